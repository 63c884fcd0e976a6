"""`catabot deploy compose SCENARIO -o compose.yml`: the compose file a scenario needs.

The services come from the rule `catabot run` uses (catabot.config.scenario.services), so a
compose file made for a scenario never lacks a participant the conductor waits for: the
router, the conductor, exactly the services that scenario runs (traffic only with traffic,
the ROS gateway only with a `ros` section), and as optional profiles the rerun web viewer
(`viewer`) and, for a ROS scenario, zenoh-bridge-ros2dds (`ros2dds`). External participants
(a vessel's controller, `clock.external_participants`) are not started: they connect to the
router's published port. The image, the scenario's folder, the run folder and the endpoints
come from environment variables with defaults; every process has a healthcheck
(catabot/run/probe.py) and the conductor starts once every stepping service is on the bus.
`--secure DIR` makes the variant for a `catabot secure init` profile (compose_secure.py).
deploy/docker-compose.yml is this command's output for deploy/scenario.json.
"""

from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from catabot.bus.clock import CONDUCTOR
from catabot.config.load import BUNDLED, load_scenario
from catabot.config.ros import RosConfig
from catabot.config.scenario import Scenario, participants, services
from catabot.config.sensors import service_of
from catabot.errors import CataBotError
from catabot.run import probe
from catabot.run.answer import OneLineParser
from catabot.run.compose_secure import Profile, profile
from catabot.run.compose_text import HEADER, NOTES, inside_folder
from catabot.run.compose_yaml import dump
from catabot.run.launcher import SERVICE_MODULES

REPO = Path(__file__).resolve().parents[2]  # in a checkout, deploy/Dockerfile is beside catabot/
PORT = 7447
START_S = 120  # a service's start period: at least the scenario's start timeout
LINGER_S = 30  # the conductor's container ends once every participant has left (or after this)
# Zenoh 1.10, as our eclipse-zenoh; from 1.5.1 on it reads TRANSIENT_LOCAL history through
# Zenoh's advanced subscriber, which the gateway's `/tf_static` and `/buoys` publishers serve
# (1.1.0 asked a publication cache that is not there: a late tf2 node got no static frames).
BRIDGE_IMAGE = "eclipse/zenoh-bridge-ros2dds:1.10.0"
VIEWER_PORTS = (9090, 9876)  # the rerun web viewer and its data (gRPC) port
Service = dict[str, Any]


class ComposeError(CataBotError, ValueError):
    """No compose file can be made for this scenario."""


@dataclass(frozen=True)
class Plan:
    """What the compose file is made from: the scenario, how the containers name it, the
    image's build section (in a checkout) and the secure profile (None: plain TCP)."""

    scenario: Scenario
    source: str  # /scenario/<file> (its folder mounted there) or a bundled scenario's name
    mounts: list[str]
    build: dict[str, str] | None
    secure: Profile | None

    @property
    def port(self) -> int:
        return self.secure.port if self.secure else PORT

    @property
    def router(self) -> str:
        default = self.secure.endpoint if self.secure else f"tcp/router:{PORT}"
        return f"${{CATABOT_ROUTER:-{default}}}"

    @property
    def listen(self) -> str:
        return f"${{CATABOT_LISTEN:-{'tls' if self.secure else 'tcp'}/0.0.0.0:{self.port}}}"

    def login(self, name: str) -> list[str]:
        return ["--zenoh-config", self.secure.login(name)] if self.secure else []


def plan(scenario_arg: str, output: Path, secure_dir: Path | None = None) -> Plan:
    """Read the scenario (a bad one is refused, its field named) and place its files."""
    scenario = load_scenario(scenario_arg)
    names = services(scenario)
    unknown = [n for n in names if service_of(n, names)[0] not in SERVICE_MODULES]
    if unknown:
        raise ComposeError(f"scenario needs service(s) {', '.join(unknown)}, which this lacks")
    out_dir = output.resolve().parent
    file = Path(scenario_arg)
    if file.is_file():
        folder = file.resolve().parent
        inside_folder(file, folder)
        rel = os.path.relpath(folder, out_dir)
        rel = rel if rel.startswith(".") else f"./{rel}"
        source, mounts = (
            f"/scenario/{file.name}",
            [f"${{CATABOT_SCENARIO_DIR:-{rel}}}:/scenario:ro"],
        )
    elif (BUNDLED / f"{scenario_arg}.json").is_file():
        source, mounts = scenario_arg, []  # the image has it
    else:
        raise ComposeError(f"scenario {scenario_arg!r}: no such file or bundled scenario")
    build = None
    if (REPO / "deploy" / "Dockerfile").is_file():
        build = {"context": os.path.relpath(REPO, out_dir), "dockerfile": "deploy/Dockerfile"}
    secure = None
    if secure_dir is not None:
        needed = [CONDUCTOR, *services(scenario), "viewer"]
        secure = profile(secure_dir, needed, ros=scenario.ros is not None)
    return Plan(scenario, source, mounts, build, secure)


def _image(p: Plan) -> Service:
    return {"image": "${CATABOT_IMAGE:-catabot:latest}", **({"build": p.build} if p.build else {})}


def _health(probe: list[str], start_s: int) -> Service:
    """Probe every 5 s; failures count only after `start_s` (loading the world)."""
    return {"test": ["CMD", "python", "-m", "catabot.run.probe", *probe], "interval": "5s",
            "timeout": "10s", "retries": 3, "start_period": f"{start_s}s"}  # fmt: skip


def _process(p: Plan, name: str, command: list[str], probe: list[str], runs: bool) -> Service:
    """A CataBot process, a client of the router; `probe`: what tells it is healthy."""
    volumes = [*p.mounts, *(["${CATABOT_RUNS:-./runs}:/runs"] if runs else [])]
    svc = _image(p) | {
        "command": [*command, "--connect", p.router, "--mode", "client", *p.login(name)],
        "depends_on": {"router": {"condition": "service_healthy"}},
        "restart": "no",
        "healthcheck": _health(probe, max(START_S, math.ceil(p.scenario.clock.start_timeout_s))),
    }
    if p.secure:
        extra = p.secure.mounts(name)
        volumes += extra["volumes"]
        svc["secrets"] = extra["secrets"]
    return svc | ({"volumes": volumes} if volumes else {})


def _router(p: Plan) -> Service:
    config = ["--zenoh-config", p.secure.router_config] if p.secure else []
    svc = _image(p) | {
        "command": ["router", "--listen", p.listen, *config],
        "ports": [f"${{CATABOT_PORT:-{p.port}}}:{p.port}"],
        "restart": "no",
        "healthcheck": _health(_router_probe(p), 30),
    }
    return svc | (p.secure.router_mounts() if p.secure else {})


def _router_probe(p: Plan) -> list[str]:
    """Plain: a Zenoh session at its listening port. Secure: a login at the name in its
    certificate, as the observer 'viewer' (a check of 0.0.0.0 without the CA's certificate
    and a login never passed, and every other container waited on it)."""
    return [p.router, *p.login("viewer")] if p.secure else [p.listen]


def _viewer(p: Plan) -> Service:
    web, grpc = VIEWER_PORTS
    command = ["view", p.source, "--web", "--web-port", str(web), "--grpc-port", str(grpc)]
    svc = _process(p, "viewer", command, [f"tcp/127.0.0.1:{web}", "--http"], runs=False)
    svc["ports"] = [f"${{CATABOT_WEB_PORT:-{web}}}:{web}", f"{grpc}:{grpc}"]
    return {"profiles": ["viewer"], **svc}


def _bridge(p: Plan, ros: RosConfig) -> Service:
    """The bridge with the scenario's domain and namespace (the gateway's keys carry it)."""
    namespace = ["-n", ros.bridge_namespace] if ros.bridge_namespace != "/" else []
    return {
        "image": BRIDGE_IMAGE,
        "profiles": ["ros2dds"],
        "network_mode": "host",  # DDS discovery is multicast on the host's network
        "environment": {  # the bridge takes an unset ROS_DISTRO for iron (type hashes)
            "ROS_DOMAIN_ID": f"${{ROS_DOMAIN_ID:-{ros.domain_id}}}",
            "ROS_DISTRO": "${ROS_DISTRO:-jazzy}",
        },
        "command": [
            "-m",
            "client",
            "-e",
            f"tcp/127.0.0.1:${{CATABOT_PORT:-{p.port}}}",
            *namespace,
        ],
        "depends_on": {"router": {"condition": "service_healthy"}},
    }


def document(p: Plan) -> dict[str, Any]:
    """The compose document: x-catabot (what the scenario runs), services, secrets."""
    s = p.scenario
    names, stepping = services(s), participants(s)
    timeout = f"${{CATABOT_START_TIMEOUT:-{s.clock.start_timeout_s:g}}}"
    command = ["service", CONDUCTOR, "--scenario", p.source, "--start-timeout", timeout,
               "--linger", str(LINGER_S)]  # fmt: skip
    probe_args = [p.router, "--name", CONDUCTOR, *p.login(CONDUCTOR)]
    conductor = _process(p, CONDUCTOR, command, probe_args, runs=False)
    conductor["depends_on"] |= {
        n: {"condition": "service_healthy" if n in stepping else "service_started"} for n in names
    }
    svcs: dict[str, Service] = {"router": _router(p), CONDUCTOR: conductor}
    run_dir = f"/runs/${{CATABOT_RUN:-{s.name}}}"
    for name in names:
        token = ["--name", name, *p.login(name)] if name in stepping else []  # observers: none
        program, shard = service_of(name, names)  # a shard: its service with --shard I/N
        command = ["service", program, *shard, "--scenario", p.source, "--run-dir", run_dir]
        svcs[name] = _process(p, name, command, [p.router, *token], runs=True)
    svcs["viewer"] = _viewer(p)
    if s.ros is not None and s.ros.mode != "rmw_zenoh":  # rmw_zenoh nodes read the keys as they are
        svcs["zenoh-bridge-ros2dds"] = _bridge(p, s.ros)
    external = [n for n in stepping if n not in names]
    doc: dict[str, Any] = {
        "x-catabot": {
            "scenario": s.name,
            "services": names,
            "participants": stepping,
            "external": external,
            "secure": p.secure is not None,
        },
        "services": svcs,
    }
    if p.secure:
        doc["secrets"] = p.secure.secrets([CONDUCTOR, *names, "viewer"])
    return doc


def render(doc: dict[str, Any], command: str) -> str:
    """The compose file's text: a header saying how to use it, the document, comments."""
    external = doc["x-catabot"]["external"]
    where = "start them yourself, connected to the router's published port (tcp/HOST:PORT)"
    names = f"{', '.join(external)}: {where}" if external else "none"
    return dump(doc, NOTES, HEADER.format(command=command, external=names))


def text(scenario_arg: str, output: Path, secure_dir: Path | None = None) -> str:
    """The compose file for `scenario_arg`, to be written at `output`."""
    command = f"catabot deploy compose {scenario_arg} -o {output}"
    command += f" --secure {secure_dir}" if secure_dir else ""
    return render(document(plan(scenario_arg, output, secure_dir)), command)


def parser() -> OneLineParser:
    p = OneLineParser(prog="catabot deploy", description="containers for a scenario")
    sub = p.add_subparsers(dest="action", required=True)
    c = sub.add_parser("compose", help="write the compose file a scenario needs")
    c.add_argument("scenario", help="scenario file or bundled name")
    c.add_argument("-o", "--output", default="compose.yml", help="default: compose.yml")
    c.add_argument("--secure", metavar="DIR", help="for the profile of catabot secure init DIR")
    sub.add_parser("probe", help="a container's health check (catabot deploy probe --help)",
                   add_help=False)  # fmt: skip
    return p


def main(argv: list[str]) -> int:
    """`catabot deploy compose ...` and `catabot deploy probe ...`; 2 on a refusal."""
    args, rest = parser().parse_known_args(argv)
    if args.action == "probe":
        return probe.main(rest)
    parser().refuse_extra(args, rest)
    output = Path(args.output)
    try:
        body = text(args.scenario, output, Path(args.secure) if args.secure else None)
        output.write_text(body)
    except CataBotError as exc:
        print(f"catabot deploy compose: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"catabot deploy compose: cannot write {output}: {exc.strerror}", file=sys.stderr)
        return 2
    print(f"{output}: written; run it with docker compose -f {output} run --rm conductor")
    return 0
