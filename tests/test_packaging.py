"""What a wheel and the image carry: every bundled data file, and a compose service for every
process `catabot run` can start (a scenario needing one compose lacks would wait forever)."""

from __future__ import annotations

import tomllib

import yaml

from catabot.run.launcher import SERVICE_MODULES
from tests.paths import REPO


def test_package_data_covers_every_bundled_file() -> None:
    config = tomllib.loads((REPO / "pyproject.toml").read_text())
    patterns = config["tool"]["setuptools"]["package-data"]["catabot"]
    package = REPO / "catabot"
    covered = {p for pattern in patterns for p in package.glob(pattern)}
    bundled = {p for p in (package / "data").rglob("*") if p.is_file()}
    assert bundled and bundled <= covered, sorted(str(p) for p in bundled - covered)


def test_compose_has_every_process() -> None:
    compose = yaml.safe_load((REPO / "deploy" / "docker-compose.yml").read_text())
    services = compose["services"]
    assert {"router", "conductor", *SERVICE_MODULES} <= set(services)
    for name in SERVICE_MODULES:
        command = services[name]["command"]
        assert command[:2] == ["service", name] and "--connect" in command, name


def test_the_image_context_leaves_out_environments_and_runs() -> None:
    ignored = (REPO / ".dockerignore").read_text().split()
    assert {".venv", "runs", ".git"} <= set(ignored)
    dockerfile = (REPO / "deploy" / "Dockerfile").read_text()
    for library in ("libusb-1.0-0", "libgl1", "libegl1", "libx11-6"):
        assert library in dockerfile, library
