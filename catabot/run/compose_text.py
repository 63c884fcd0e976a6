"""The words of a generated compose file (its header and comments), and the check that a
scenario's own files are where the containers can read them."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from catabot.config.load import absolute_paths
from catabot.errors import CataBotError

HEADER = """\
Made by `catabot deploy compose`; do not edit, make it again (the services follow the scenario):
  {command}
  docker compose -f FILE run --rm conductor   # the router and the services, then the clock;
  docker compose -f FILE down                 # its exit code is the run's; then stop the rest
(or `docker compose -f FILE up` to see every log; Ctrl-C once the conductor has exited).
Exit codes: 0 done; 1 a fault: a participant that never joined within the start timeout or
left (named in the conductor's log), a missed deadline; 2 a bad scenario. Profiles: viewer
(the rerun web viewer), ros2dds (zenoh-bridge-ros2dds, with a ROS scenario).
Environment (default): CATABOT_IMAGE (catabot:latest); CATABOT_SCENARIO_DIR (the scenario's
folder, mounted read-only as /scenario); CATABOT_RUNS (./runs, the run folders) and
CATABOT_RUN (the scenario's name: this run's folder in it, one a run); CATABOT_PORT (the router's
published port); CATABOT_LISTEN and CATABOT_ROUTER (where the router listens, where the
processes reach it); CATABOT_START_TIMEOUT (the scenario's clock.start_timeout_s);
CATABOT_SECURE (the secure profile's folder); CATABOT_WEB_PORT (9090).
External participants: {external}."""

NOTES = {
    "x-catabot": "what this scenario runs (catabot.config.scenario.services and participants)",
    "services.router": "every process is a client of this router; stacks outside connect to "
    "its published port",
    "services.conductor": "the clock: starts when every stepping service is on the bus, names "
    "any participant missing\nafter the start timeout and exits 1; ends once every "
    "participant has left (its files are closed)",
    "services.viewer": "docker compose -f FILE --profile viewer up -d viewer, then open\n"
    "http://localhost:9090/?url=rerun%2Bhttp://localhost:9876/proxy (served until `down`)",
    "services.zenoh-bridge-ros2dds": "ROS 2 on DDS on this host (multicast discovery): "
    "docker compose -f FILE --profile ros2dds up -d\nzenoh-bridge-ros2dds; ROS_DOMAIN_ID "
    "and ROS_DISTRO (jazzy unless set; humble for Humble's nodes) must match your nodes'",
    "secrets": "the secure profile's passwords: each process gets its own login only",
}


class ScenarioFilesError(CataBotError, ValueError):
    """A file the scenario reads lies outside the folder the containers are given."""


def inside_folder(file: Path, folder: Path) -> None:
    """Refuse a scenario that reads a file (terrain, current map, vessel model) outside its
    own folder: the containers see that folder only (mounted as /scenario)."""
    try:
        raw = json.loads(file.read_text())
    except (OSError, ValueError):
        return  # load_scenario has already said what is wrong with it, if anything
    outside = [p for p in _paths(raw, absolute_paths(raw, folder)) if not p.is_relative_to(folder)]
    if outside:
        raise ScenarioFilesError(
            f"{file}: reads {', '.join(map(str, outside))}, outside {folder}, which is all the "
            "containers see: copy it into that folder and name it relative to the scenario"
        )


def _paths(raw: Any, resolved: Any) -> list[Path]:
    """Input files: the values `absolute_paths` changed (relative paths, now resolved),
    and absolute paths of existing files."""
    if isinstance(raw, dict) and isinstance(resolved, dict):
        return [p for k in raw for p in _paths(raw[k], resolved.get(k))]
    if isinstance(raw, list) and isinstance(resolved, list):
        return [p for a, b in zip(raw, resolved, strict=False) for p in _paths(a, b)]
    if isinstance(raw, str) and isinstance(resolved, str):
        changed = raw != resolved
        if changed or (raw.startswith("/") and Path(raw).is_file()):
            return [Path(resolved).resolve()]
    return []
