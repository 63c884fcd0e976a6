"""What a wheel and the image carry: every module and bundled data file, the system libraries
the services load, and a compose service for every process `catabot run` can start (a
scenario needing one that compose lacks would wait for it in vain)."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import yaml

from catabot.run import compose
from catabot.run.launcher import SERVICE_MODULES
from tests.paths import REPO


def _tracked(top: str) -> list[Path]:
    """The files of a package (what git has, so no caches or local scratch)."""
    return [p for p in (REPO / top).rglob("*") if p.is_file() and "__pycache__" not in p.parts]


def test_package_data_covers_every_bundled_file() -> None:
    """Every file that is not a module is package data (`pip wheel .` lists the same)."""
    config = tomllib.loads((REPO / "pyproject.toml").read_text())
    data = config["tool"]["setuptools"]["package-data"]
    bundled: set[Path] = set()
    for top in ("catabot", "services"):
        package = REPO / top
        covered = {p for pattern in data.get(top, []) for p in package.glob(pattern)}
        files = {p for p in _tracked(top) if p.suffix != ".py"}
        assert files <= covered, sorted(str(p) for p in files - covered)
        bundled |= files
    assert REPO / "catabot" / "data" / "terrain" / "bay.png" in bundled
    assert REPO / "catabot" / "py.typed" in bundled  # a stack's mypy reads catabot's hints


def test_every_module_is_in_a_package() -> None:
    """setuptools' package finder takes folders with an __init__.py only: a module in a
    folder without one would be missing from the wheel and the image."""
    for top in ("catabot", "services"):
        folders = {p.parent for p in _tracked(top) if p.suffix == ".py"}
        lacking = [f for f in folders if not (f / "__init__.py").is_file()]
        assert not lacking, lacking


def test_compose_has_every_process(tmp_path: Path) -> None:
    """A scenario that uses every service gets a compose service for each."""
    gps = {"name": "g", "type": "gps", "rate_hz": 10}
    data = {"name": "all", "seed": 1, "duration_s": 1.0, "traffic": {"count": 2}, "ros": {},
            "vessels": [{"id": "ego", "sensors": [gps]}]}  # fmt: skip
    scenario = tmp_path / "all.json"
    scenario.write_text(json.dumps(data))
    services = yaml.safe_load(compose.text(str(scenario), tmp_path / "c.yml"))["services"]
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
