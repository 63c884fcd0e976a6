"""The secure profile for a sharded sensor farm: a login and the sensor keys for each shard."""

from __future__ import annotations

import pytest

from catabot.run.secure import SecureError, _acl, own_keys


def test_each_shard_may_put_sensor_samples() -> None:
    own = own_keys(3)
    assert {"sensors.0", "sensors.1", "sensors.2", "sensors"} <= set(own)
    assert own["sensors.2"] == ["sensor/**"]
    acl = _acl(own, clients=[], observers=[])
    rules = {r["id"]: r["key_exprs"] for r in acl["rules"]}
    assert rules["sensors.1-puts"] == ["catabot/*/sensor/**", "catabot/*/clock/ack/sensors.1"]
    assert rules["sensors.1-token"] == ["catabot/*/live/sensors.1/*"]


@pytest.mark.parametrize("shards", [0, 65])
def test_a_shard_count_out_of_range_is_refused(shards: int) -> None:
    with pytest.raises(SecureError, match="use 1 to 64"):
        own_keys(shards)
