"""A ROS 2 stand-in for the gateway benchmark: subscribes to every topic the gateway publishes
for a scenario (in one convention) and keeps only the latest of each, with no Python per
sample, so what it costs the machine is what receiving them costs (a ROS node in C++ that
drops what it has no time for costs about that).

python -m benchmarks.ros_listener --connect ENDPOINT --scenario FILE --mode bridge|rmw_zenoh
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading

import zenoh

from catabot.bus.session import Connection, open_session
from catabot.config.load import load_scenario
from catabot.config.ros import RosConfig
from catabot.ros2 import types
from catabot.ros2.convert import Converter
from catabot.ros2.names import CLOCK, TF
from catabot.ros2.wire import Convention, bridge_key, rmw_key
from catabot.world.world import World


def topics(world: World, ros: RosConfig) -> list[tuple[str, str]]:
    """(topic, type) of every data topic of the gateway (latched ones left out)."""
    convert = Converter(world, ros, boats=ros.traffic)
    out = [(t, types.ODOMETRY) for t in convert.odom_topics] + [(TF, types.TF)]
    out.append((CLOCK, types.CLOCK))
    out += [pair for s in world.sensors for pair in convert.names.sensor_topics(s)]
    return out


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--connect", required=True)
    p.add_argument("--scenario", required=True)
    p.add_argument("--mode", choices=[c.value for c in Convention], default="bridge")
    a = p.parse_args()
    world = World.resolve(load_scenario(a.scenario))
    ros = world.scenario.ros or RosConfig()
    keys = [
        bridge_key(t, ros.bridge_namespace) if a.mode == "bridge" else rmw_key(0, t, kind)
        for t, kind in topics(world, ros)
    ]
    done = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: done.set())
    with open_session(Connection(connect=(a.connect,))) as session:
        # a ring of one per key, emptied by nobody: Zenoh receives every sample and no Python
        # runs per sample, as in a C++ node that only keeps the latest
        subs = [session.declare_subscriber(k, zenoh.handlers.RingChannel(1)) for k in keys]
        print(f"listening to {len(subs)} topics", flush=True)
        done.wait()
        received = sum(1 for sub in subs if sub.try_recv() is not None)
    print(f"topics with a sample at the end: {received} of {len(subs)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
