"""Refusals are logged in a form `catabot run` reads back to echo the first of each kind."""

from __future__ import annotations

import logging

import pytest

from catabot.bus import codec
from catabot.bus.messages import TwistCmd
from catabot.bus.rejections import Rejected, Rejections, report_of


def test_a_logged_refusal_reads_back_as_key_reason_and_detail(
    caplog: pytest.LogCaptureFixture,
) -> None:
    refusals = Rejections(logging.getLogger("t"), "physics", every_s=0.0)
    with caplog.at_level(logging.WARNING):
        refusals.add("catabot/w/vessel/ego/cmd/twist", Rejected("malformed", "a: b (c)"))
        refusals.add("catabot/w/vessel/ego/cmd/twist", Rejected("malformed", "a: b (c)"))
    lines = [r.getMessage() for r in caplog.records]
    expected = ("catabot/w/vessel/ego/cmd/twist", "malformed", "a: b (c)")
    assert [report_of(f"2026 t WARNING {line}\n") for line in lines] == [expected, expected]
    assert report_of("2026 physics INFO stepping\n") is None


def test_a_twist_with_the_scenario_names_is_refused_naming_the_fields() -> None:
    payload = codec.pack({"v": 1, "type": "twist_cmd", "surge_mps": 1.0, "yaw_rate_radps": 0.1})
    with pytest.raises(codec.CodecError) as info:
        codec.decode(payload, TwistCmd)
    assert str(info.value) == (
        "twist_cmd: unknown field(s) 'surge_mps', 'yaw_rate_radps' "
        "(fields: surge, yaw_rate; optional: tick, stamp_ns)"
    )
    with pytest.raises(codec.CodecError, match=r"missing field 'yaw_rate' \(fields: surge, yaw"):
        codec.decode(codec.pack({"v": 1, "type": "twist_cmd", "surge": 1.0}), TwistCmd)


def test_each_new_detail_is_logged_once_then_a_line_a_second(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """A surge and a yaw rate out of range are one key and reason: the second's words were
    lost for a second; a client varying its values gets only the first FIRST_DETAILS."""
    refusals = Rejections(logging.getLogger("t"), "physics", every_s=60.0)
    key = "catabot/w/vessel/ego/cmd/twist"
    with caplog.at_level(logging.WARNING):
        for detail in ["surge 1e6", "yaw rate 1e6", "surge 1e6", *(f"v{i}" for i in range(20))]:
            refusals.add(key, Rejected("invalid content", detail))
    details = [report_of(f"x {r.getMessage()}\n")[2] for r in caplog.records]  # type: ignore[index]
    assert details == ["surge 1e6", "yaw rate 1e6", *(f"v{i}" for i in range(6))]
    assert refusals.totals == {"invalid content": 23}
