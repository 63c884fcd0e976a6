"""Run a generated compose file's services with `podman run`, as `docker compose run --rm
conductor` would: no compose is needed (Debian's podman has none that knows profiles and
health conditions), and the file is read as compose reads it.

    python scripts/compose_podman.py COMPOSE.yml [--prefix NAME] -- podman --runtime runc

- `${VAR:-default}` and `${VAR}` are taken from the environment, as compose does;
- every service outside a profile starts in dependency order; one that depends on another
  `service_healthy` starts once that one's own healthcheck (its `test`) has passed, run
  by `podman healthcheck run` every half second within its start period and retries;
- host network (the compose network's names are not used: point CATABOT_LISTEN and
  CATABOT_ROUTER at a free port on 127.0.0.1), volumes and secrets as bind mounts,
  relative paths from the compose file's folder;
- the exit status is the conductor's; then every other container must end by itself (the
  conductor lingers until they have left) with 0; the router is stopped; all are removed.
Part of scripts/container-check.sh; needs pyyaml.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import yaml

VAR = re.compile(r"\$\{([A-Za-z_][A-Za-z0-9_]*)(?::-([^}]*))?\}")
FLAGS = ["--network", "host", "--ulimit", "nofile=1024:1024", "--ulimit", "nproc=1024:1024"]


def interpolate(value: Any) -> Any:
    """Compose's `${VAR:-default}` (set and non-empty, else the default) and `${VAR}`."""
    if isinstance(value, str):
        return VAR.sub(lambda m: os.environ.get(m.group(1)) or (m.group(2) or ""), value)
    if isinstance(value, list):
        return [interpolate(v) for v in value]
    if isinstance(value, dict):
        return {k: interpolate(v) for k, v in value.items()}
    return value


def order(services: dict[str, Any]) -> list[str]:
    """Services outside profiles, each after what it depends on."""
    active = [n for n, s in services.items() if not s.get("profiles")]
    done: list[str] = []
    while len(done) < len(active):
        ready = [
            n
            for n in active
            if n not in done and set(services[n].get("depends_on", {})) <= set(done)
        ]
        if not ready:
            sys.exit(f"compose_podman: a dependency cycle among {sorted(set(active) - set(done))}")
        done += ready
    return done


def _seconds(text: str) -> float:
    return float(text.rstrip("s"))


def mounts(svc: dict[str, Any], secrets: dict[str, Any], base: Path) -> list[str]:
    args = []
    for volume in svc.get("volumes", []):
        source, target, *mode = volume.split(":")
        path = base / source  # an absolute source stays as it is
        if not mode and not path.exists():
            path.mkdir(parents=True)  # as compose makes a missing bind-mount folder
        args += ["-v", ":".join([str(path.resolve()), target, *mode])]
    for secret in svc.get("secrets", []):
        source = secrets[secret["source"]]["file"]
        args += ["-v", f"{(base / source).resolve()}:{secret['target']}:ro"]
    return args


def start(
    podman: list[str], name: str, svc: dict[str, Any], secrets: dict[str, Any], base: Path
) -> None:
    health = svc.get("healthcheck", {})
    test = health.get("test", [])
    args = [*podman, "run", "-d", "--name", name, *FLAGS, *mounts(svc, secrets, base)]
    if test:
        args += ["--health-cmd", json.dumps(test[1:]), "--health-interval", "disable"]
    args += [svc["image"], *svc.get("command", [])]  # the image's entrypoint: catabot
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)


def healthy(podman: list[str], name: str, svc: dict[str, Any]) -> bool:
    """Its healthcheck passes, within its start period and retries (as an engine runs it)."""
    health = svc.get("healthcheck", {})
    limit = time.monotonic() + _seconds(health.get("start_period", "0s")) + _seconds(
        health.get("interval", "5s")) * int(health.get("retries", 3))  # fmt: skip
    while time.monotonic() < limit:
        if (
            subprocess.run([*podman, "healthcheck", "run", name], capture_output=True).returncode
            == 0
        ):
            return True
        state = subprocess.run([*podman, "inspect", name, "--format", "{{.State.Status}}"],
                               capture_output=True, text=True).stdout.strip()  # fmt: skip
        if state not in ("running", "created"):
            return False
        time.sleep(0.5)
    return False


def exit_code(podman: list[str], name: str, timeout_s: float) -> int | None:
    """The container's exit status once it has ended; None if it does not within timeout_s."""
    try:
        done = subprocess.run([*podman, "wait", name], capture_output=True, text=True,
                              timeout=timeout_s)  # fmt: skip
    except subprocess.TimeoutExpired:
        return None
    return int(done.stdout.strip()) if done.returncode == 0 else None


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("compose", type=Path)
    p.add_argument("--prefix", default="catabot")
    p.add_argument("--logs", type=Path, help="write each container's log here")
    argv = sys.argv[1:]
    cut = argv.index("--") if "--" in argv else len(argv)
    args = p.parse_args(argv[:cut])
    podman = argv[cut + 1 :] or ["podman"]
    doc = interpolate(yaml.safe_load(args.compose.read_text()))
    services, secrets, base = doc["services"], doc.get("secrets", {}), args.compose.resolve().parent
    names = order(services)
    ctr = {n: f"{args.prefix}-{n}" for n in names}
    code = 1
    try:
        for name in names:
            for dep, cond in services[name].get("depends_on", {}).items():
                if cond.get("condition") == "service_healthy" and not healthy(
                    podman, ctr[dep], services[dep]
                ):
                    print(f"{dep}: unhealthy, so {name} does not start", file=sys.stderr)
                    return 1
            start(podman, ctr[name], services[name], secrets, base)
            print(f"started {name}", flush=True)
        rc = exit_code(podman, ctr["conductor"], 900)
        code = 1 if rc is None else rc
        print(f"conductor: exit {rc}", flush=True)
        for name in names:
            if name in ("router", "conductor"):
                continue
            rc = exit_code(podman, ctr[name], 60)
            print(f"{name}: exit {rc}", flush=True)
            code = code or (rc if rc is not None else 1)
    finally:
        for name in names:
            if args.logs:
                log = subprocess.run([*podman, "logs", ctr[name]], capture_output=True, text=True)
                (args.logs / f"{name}.log").write_text(log.stdout + log.stderr)
            subprocess.run([*podman, "rm", "-f", "-t", "5", ctr[name]], capture_output=True)
    return code


if __name__ == "__main__":
    sys.exit(main())
