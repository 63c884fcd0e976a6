"""The `ros` section: defaults, namespaces, names that become ROS topics, the gateway as an
observer or a lockstep participant, each refusal naming its field."""

from __future__ import annotations

from typing import Any

import pytest

from catabot.config.base import ScenarioError
from catabot.config.load import parse_scenario
from catabot.config.ros import RosConfig, namespace
from catabot.config.scenario import participants, services


def _scenario(ros: dict[str, Any] | None = None, **vessel: Any) -> dict[str, Any]:
    data: dict[str, Any] = {"vessels": [{"id": "ego", **vessel}], "traffic": {"count": 2}}
    if ros is not None:
        data["ros"] = ros
    return data


def test_defaults_observe_in_both_conventions() -> None:
    ros = RosConfig()
    assert (ros.mode, ros.lockstep, ros.domain_id, ros.bridge_namespace) == ("both", False, 0, "/")
    assert ros.namespace_of("ego") == "/ego"
    scenario = parse_scenario(_scenario({}))
    assert services(scenario)[-1] == "ros" and "ros" not in participants(scenario)
    assert "ros" not in services(parse_scenario(_scenario()))


def test_lockstep_gateway_steps_and_may_control_a_vessel() -> None:
    controller = {"participant": "ros", "rate_hz": 10, "command": "twist"}
    scenario = parse_scenario(_scenario({"lockstep": True}, controller=controller))
    assert participants(scenario).count("ros") == 1


@pytest.mark.parametrize(
    "text, canonical", [("", "/"), ("/", "/"), ("ego", "/ego"), ("/a/b_2/", "/a/b_2")]
)
def test_namespaces_are_canonical(text: str, canonical: str) -> None:
    assert namespace(text) == canonical


@pytest.mark.parametrize(
    "data, message",
    [
        (_scenario(controller={"participant": "ros"}), "vessels.0.controller.participant: 'ros'"),
        (_scenario({"lockstep": False}, controller={"participant": "ros"}), "lockstep"),
        ({**_scenario({}), "vessels": [{"id": "wam-v"}]}, "vessels.0.id: 'wam-v' names ROS"),
        (_scenario({}, sensors=[{"name": "9cam", "type": "imu", "rate_hz": 10}]),
         "vessels.0.sensors.0.name"),
        (_scenario({"namespaces": {"nobody": "/x"}}), "ros.namespaces.nobody: names no vessel"),
        (_scenario({"namespaces": {"ego": "/boat_001"}}), "share the namespace '/boat_001'"),
        (_scenario({"namespaces": {"ego": "a b"}}), "'a b' is not a ROS namespace"),
        (_scenario({"mode": "dds"}), "ros.mode: must be one of"),
        (_scenario({"node": "1node"}), "not a ROS node name"),
        (_scenario({"domain_id": 300}), "ros.domain_id: must be <= 232"),
        (_scenario({"clock_hz": 30}), "ros.clock_hz"),
        (_scenario({"topics": {}}), "ros.topics: unknown field"),
        (_scenario({"lockstep": True, "reply_timeout_s": 10}), "below clock.deadline_s"),
    ],
)  # fmt: skip
def test_refusals_name_the_field(data: dict[str, Any], message: str) -> None:
    with pytest.raises(ScenarioError, match=message):
        parse_scenario(data)


def test_a_vessel_at_the_root_namespace() -> None:
    scenario = parse_scenario(_scenario({"namespaces": {"ego": "/", "boat_000": "/traffic/b0"}}))
    assert scenario.ros is not None
    assert scenario.ros.namespace_of("ego") == "/"
    assert scenario.ros.namespace_of("boat_000") == "/traffic/b0"
    assert scenario.ros.namespace_of("boat_001") == "/boat_001"
