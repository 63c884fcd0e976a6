"""`catabot deploy compose`: the compose file a scenario needs, read back as compose reads it
(YAML). A traffic scenario, a ROS scenario (observer and lockstep, with an external stack),
the secure variant, and the refusals; deploy/docker-compose.yml is the command's output."""

from __future__ import annotations

import json
import os
import re
import shutil
from pathlib import Path
from typing import Any

import pytest
import yaml

from catabot.run import compose, secure
from catabot.run.compose_text import HEADER
from tests.paths import REPO

LOCKSTEP = ["physics", "sensors", "traffic", "recorder"]


def generate(scenario: str | Path, out: Path, secure_dir: Path | None = None) -> dict[str, Any]:
    text = compose.text(str(scenario), out, secure_dir)
    out.write_text(text)
    doc = yaml.safe_load(text)
    assert isinstance(doc, dict)
    return doc


def scenario_file(folder: Path, **extra: Any) -> Path:
    gps = {"name": "gps", "type": "gps", "rate_hz": 10.0}
    data = {"name": "rosy", "seed": 3, "duration_s": 2.0,
            "vessels": [{"id": "ego", "sensors": [gps]}], **extra}  # fmt: skip
    path = folder / "rosy.json"
    path.write_text(json.dumps(data))
    return path


def test_a_traffic_scenario_gets_exactly_its_services(tmp_path: Path) -> None:
    doc = generate(REPO / "deploy" / "traffic.json", tmp_path / "compose.yml")
    svcs = doc["services"]
    assert set(svcs) == {"router", "conductor", *LOCKSTEP, "viewer"}
    assert doc["x-catabot"] == {
        "scenario": "traffic",
        "services": LOCKSTEP,
        "participants": LOCKSTEP,
        "external": [],
        "secure": False,
    }
    for name in LOCKSTEP:
        svc = svcs[name]
        assert svc["command"][:4] == ["service", name, "--scenario", "/scenario/traffic.json"]
        assert svc["command"][-4:] == ["--connect", "${CATABOT_ROUTER:-tcp/router:7447}",
                                       "--mode", "client"]  # fmt: skip
        assert "/runs/${CATABOT_RUN:-traffic}" in svc["command"]
        scenario_dir = rel(REPO / "deploy", tmp_path)
        assert svc["volumes"] == [
            f"${{CATABOT_SCENARIO_DIR:-{scenario_dir}}}:/scenario:ro",
            "${CATABOT_RUNS:-./runs}:/runs",
        ]
        assert svc["healthcheck"]["test"][-2:] == ["--name", name]
        assert svc["depends_on"] == {"router": {"condition": "service_healthy"}}
    conductor = svcs["conductor"]
    assert conductor["depends_on"] == {
        n: {"condition": "service_healthy"} for n in ["router", *LOCKSTEP]
    }
    command = conductor["command"]
    assert command[command.index("--start-timeout") + 1] == "${CATABOT_START_TIMEOUT:-60}"
    assert int(command[command.index("--linger") + 1]) > 0
    router = svcs["router"]
    assert router["command"] == ["router", "--listen", "${CATABOT_LISTEN:-tcp/0.0.0.0:7447}"]
    assert router["ports"] == ["${CATABOT_PORT:-7447}:7447"]
    assert router["healthcheck"]["test"][:4] == ["CMD", "python", "-m", "catabot.run.probe"]
    assert svcs["viewer"]["profiles"] == ["viewer"] and "--web" in svcs["viewer"]["command"]
    assert svcs["viewer"]["healthcheck"]["test"][-2:] == ["tcp/127.0.0.1:9090", "--http"]
    assert {s["build"]["context"] for s in svcs.values() if "build" in s} == {
        os.path.relpath(REPO, tmp_path)
    }


def rel(path: Path, start: Path) -> str:
    """What the compose file at `start` says for `path`."""
    text = os.path.relpath(path, start)
    return text if text.startswith(".") else f"./{text}"


def test_every_variable_is_documented_in_the_header(tmp_path: Path) -> None:
    text = compose.text(str(REPO / "deploy" / "traffic.json"), tmp_path / "c.yml")
    used = set(re.findall(r"\$\{(\w+)", text))
    assert used and all(name in HEADER for name in used), used - set(re.findall(r"\w+", HEADER))


def test_a_ros_scenario_gets_the_gateway_and_the_bridge_profile(tmp_path: Path) -> None:
    ros = {"ros": {"domain_id": 7}}
    doc = generate(scenario_file(tmp_path, **ros), tmp_path / "compose.yml")
    svcs = doc["services"]
    assert set(svcs) == {"router", "conductor", "physics", "sensors", "recorder", "ros",
                         "viewer", "zenoh-bridge-ros2dds"}  # fmt: skip
    assert "traffic" not in svcs
    assert svcs["ros"]["command"][:2] == ["service", "ros"]
    assert "--name" not in svcs["ros"]["healthcheck"]["test"]  # an observer holds no token
    assert svcs["conductor"]["depends_on"]["ros"] == {"condition": "service_started"}
    bridge = svcs["zenoh-bridge-ros2dds"]
    assert bridge["profiles"] == ["ros2dds"] and bridge["network_mode"] == "host"
    assert bridge["environment"] == {  # the bridge takes an unset distro for iron
        "ROS_DOMAIN_ID": "${ROS_DOMAIN_ID:-7}",
        "ROS_DISTRO": "${ROS_DISTRO:-jazzy}",
    }
    assert bridge["image"].startswith("eclipse/zenoh-bridge-ros2dds:1.")
    assert "-n" not in bridge["command"]


def test_the_bridge_takes_the_scenarios_namespace_and_rmw_zenoh_needs_none(
    tmp_path: Path,
) -> None:
    """The gateway puts on `bot1/...`: a bridge without `-n /bot1` matched no topic."""
    doc = generate(scenario_file(tmp_path, ros={"bridge_namespace": "/bot1"}), tmp_path / "a.yml")
    assert doc["services"]["zenoh-bridge-ros2dds"]["command"][-2:] == ["-n", "/bot1"]
    version = doc["services"]["zenoh-bridge-ros2dds"]["image"].rsplit(":", 1)[1]
    assert tuple(map(int, version.split("."))) >= (1, 5, 1)  # reads advanced publishers' history
    doc = generate(scenario_file(tmp_path, ros={"mode": "rmw_zenoh"}), tmp_path / "b.yml")
    assert "zenoh-bridge-ros2dds" not in doc["services"] and "ros" in doc["services"]


def test_a_lockstep_gateway_and_an_external_stack(tmp_path: Path) -> None:
    clock = {"external_participants": ["stack"], "start_timeout_s": 200}
    path = scenario_file(tmp_path, ros={"lockstep": True}, clock=clock)
    text = compose.text(str(path), tmp_path / "c.yml")
    doc = yaml.safe_load(text)
    svcs = doc["services"]
    assert svcs["ros"]["healthcheck"]["test"][-2:] == ["--name", "ros"]
    assert svcs["conductor"]["depends_on"]["ros"] == {"condition": "service_healthy"}
    assert doc["x-catabot"]["external"] == ["stack"] and "stack" not in svcs
    assert "External participants: stack: start them yourself" in text
    command = svcs["conductor"]["command"]
    assert command[command.index("--start-timeout") + 1] == "${CATABOT_START_TIMEOUT:-200}"
    assert svcs["physics"]["healthcheck"]["start_period"] == "200s"  # loading may take as long


@pytest.mark.skipif(shutil.which("openssl") is None, reason="needs openssl")
def test_the_secure_variant_mounts_each_process_only_its_own_login(tmp_path: Path) -> None:
    folder = tmp_path / "prof"
    secure.init(folder, clients=["stack"], observers=[], host="sim.example.org", port=7450)
    doc = generate(REPO / "deploy" / "traffic.json", tmp_path / "compose.yml", folder)
    svcs, var = doc["services"], f"${{CATABOT_SECURE:-{folder.resolve()}}}"
    assert doc["x-catabot"]["secure"] is True
    router = svcs["router"]
    assert router["command"] == ["router", "--listen", "${CATABOT_LISTEN:-tls/0.0.0.0:7450}",
                                 "--zenoh-config", f"{var}/router.json5"]  # fmt: skip
    assert router["networks"] == {"default": {"aliases": ["sim.example.org"]}}
    assert {s["source"] for s in router["secrets"]} == {
        "router-config",
        "router-users",
        "router-key",
        "viewer-login",  # its health check logs in as the observer
    }
    assert f"{var}/ca.pem:{var}/ca.pem:ro" in router["volumes"]
    assert router["healthcheck"]["test"][-3:] == [  # its name, not 0.0.0.0: the certificate's
        "${CATABOT_ROUTER:-tls/sim.example.org:7450}",
        "--zenoh-config",
        f"{var}/viewer.json5",
    ]
    for name in ["conductor", *LOCKSTEP, "viewer"]:
        svc = svcs[name]
        assert svc["command"][-2:] == ["--zenoh-config", f"{var}/{name}.json5"], name
        assert "${CATABOT_ROUTER:-tls/sim.example.org:7450}" in svc["command"]
        assert svc["secrets"] == [{"source": f"{name}-login", "target": f"{var}/{name}.json5"}]
        assert f"{var}/ca.pem:{var}/ca.pem:ro" in svc["volumes"]
        assert not any("key" in v or "users" in v for v in svc["volumes"])
    health = svcs["physics"]["healthcheck"]["test"]
    assert health[-2:] == ["--zenoh-config", f"{var}/physics.json5"]
    for source in doc["secrets"].values():  # every file named is one the profile has
        assert (folder / Path(source["file"]).name).is_file()
    logins = {f"{n}-login" for n in ["conductor", *LOCKSTEP, "viewer"]}
    assert set(doc["secrets"]) == {"router-config", "router-users", "router-key", *logins}


@pytest.mark.skipif(shutil.which("openssl") is None, reason="needs openssl")
def test_secure_refusals(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    local = tmp_path / "local"
    secure.init(local, clients=[], observers=[])  # host localhost: a container's own loopback
    out = str(tmp_path / "c.yml")
    assert compose.main(["compose", str(REPO / "deploy" / "scenario.json"), "-o", out,
                         "--secure", str(local)]) == 2  # fmt: skip
    assert "--host NAME" in capsys.readouterr().err
    named = tmp_path / "named"
    secure.init(named, clients=[], observers=[], host="router")
    ros = scenario_file(tmp_path, ros={})
    assert compose.main(["compose", str(ros), "-o", out, "--secure", str(named)]) == 2
    assert "ROS gateway is not in the secure profile" in capsys.readouterr().err
    (named / "traffic.json5").unlink()
    traffic = str(REPO / "deploy" / "traffic.json")
    assert compose.main(["compose", traffic, "-o", out, "--secure", str(named)]) == 2
    assert "no login for traffic" in capsys.readouterr().err
    assert compose.main(["compose", traffic, "-o", out, "--secure", str(tmp_path)]) == 2
    assert "no secure profile here" in capsys.readouterr().err
    moved = tmp_path / "moved"
    named.rename(moved)
    assert compose.main(["compose", "default", "-o", out, "--secure", str(moved)]) == 2
    assert "make it again where it is" in capsys.readouterr().err


def test_bad_scenarios_are_refused_with_the_reason(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = str(tmp_path / "c.yml")
    assert compose.main(["compose", str(tmp_path / "nope.json"), "-o", out]) == 2
    assert "does not exist" in capsys.readouterr().err
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"name": "x", "seed": -1}))
    assert compose.main(["compose", str(bad), "-o", out]) == 2
    assert "seed" in capsys.readouterr().err
    inner = tmp_path / "inner"
    inner.mkdir()
    shutil.copy(REPO / "catabot" / "data" / "terrain" / "bay.png", tmp_path / "bay.png")
    outside = scenario_file(inner, terrain={"elevation_image": "../bay.png"})
    assert compose.main(["compose", str(outside), "-o", out]) == 2
    assert "outside" in capsys.readouterr().err and not Path(out).exists()


def test_a_bundled_scenario_is_read_from_the_image(tmp_path: Path) -> None:
    doc = generate("harbour", tmp_path / "c.yml")
    physics = doc["services"]["physics"]
    assert physics["command"][2:4] == ["--scenario", "harbour"]
    assert physics["volumes"] == ["${CATABOT_RUNS:-./runs}:/runs"]


def test_deploy_compose_is_the_output_for_deploy_scenario(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(REPO)
    made = compose.text("deploy/scenario.json", Path("deploy/docker-compose.yml"))
    assert (REPO / "deploy" / "docker-compose.yml").read_text() == made, (
        "deploy/docker-compose.yml is stale: catabot deploy compose deploy/scenario.json "
        "-o deploy/docker-compose.yml"
    )


def test_shards_are_services_of_their_own_with_their_place(tmp_path: Path) -> None:
    gps = {"name": "gps", "type": "gps", "rate_hz": 10.0}
    path = scenario_file(tmp_path, sensors={"shards": 2}, traffic={"count": 3, "shards": 3})
    data = json.loads(path.read_text())
    data["vessels"][0]["sensors"].append(gps | {"name": "gps2"})
    path.write_text(json.dumps(data))
    doc = generate(path, tmp_path / "compose.yml")
    names = ["physics", "sensors.0", "sensors.1", "traffic.0", "traffic.1", "traffic.2", "recorder"]
    assert doc["x-catabot"]["services"] == names
    assert doc["services"]["sensors.1"]["command"][:4] == ["service", "sensors", "--shard", "1/2"]
    assert doc["services"]["traffic.2"]["command"][:4] == ["service", "traffic", "--shard", "2/3"]
    assert set(names) <= set(doc["services"]["conductor"]["depends_on"])
