"""A stranger's flood in the real lockstep (catabot/bus/lanes.py). A trial's 2000 junk commands
a second queued the traffic's set-points behind them in physics; physics grew to 1.4 GB and
the run ended with it "hung". The run's own samples no longer wait behind a stranger's, a
client's command still arrives, and what the flooder's lane cannot hold is counted."""

from __future__ import annotations

import subprocess
import sys
import threading

import pytest

from catabot.bus import codec, lanes
from catabot.bus.clock import Stream
from catabot.bus.inbox import Inputs
from catabot.bus.messages import ThrustCmd, Tick, VesselState
from catabot.bus.participant import Participant
from tests.catabot.bus.lockstep_world import World, _state

TICKS = 300
FLOODER = """
import sys, msgpack, zenoh
conf = zenoh.Config()
conf.insert_json5("mode", '"client"')
conf.insert_json5("connect/endpoints", '["' + sys.argv[1] + '"]')
session = zenoh.open(conf)
if len(sys.argv) > 3:  # a token under a name the run does not have: not one of the run's
    token = session.liveliness().declare_token(sys.argv[3] + str(session.zid()))
pub = session.declare_publisher(sys.argv[2])
junk = msgpack.packb(list(range(16000)))  # 47 KB that reads as msgpack: decoded, then refused
print("flooding", flush=True)
n = 0
while True:  # its own session's id, as a CataBot publisher states it (identity.py)
    pub.put(junk, source_info=zenoh.SourceInfo(pub.id, n))
    n += 1
"""


@pytest.mark.parametrize("token", [False, True], ids=["no-token", "token-of-no-participant"])
def test_a_flood_of_junk_commands_neither_stops_the_run_nor_hides_a_clients_command(
    world: World, token: bool
) -> None:
    """With a token too: a client's `live/helper/<its zid>` was bound like a participant's,
    its flood skipped the lanes and stalled physics until it was killed as hung (an audit)."""
    cmd, state = world.keys.cmd_thrust("ego"), world.keys.vessel_state("prod")
    names, holder, heard = ["prod", "cons"], dict[str, Participant](), list[ThrustCmd]()

    def produce(tick: Tick, _inputs: Inputs) -> None:
        holder["prod"].publish(state, _state(tick.tick))

    def consume(tick: Tick, inputs: Inputs) -> None:
        heard.extend(m for m in inputs.get(cmd, []) if isinstance(m, ThrustCmd))

    holder["prod"] = world.member("prod", produce, peers=names).participant
    streams = [Stream(state, VesselState, "prod", 1), Stream(cmd, ThrustCmd, "external", None)]
    cons = world.member("cons", consume, inputs=streams, peers=names).participant
    client = world.open().declare_publisher(cmd)
    stop, longest = threading.Event(), [0]
    posing = [world.keys.live("helper", "")] if token else []
    flooder = subprocess.Popen([sys.executable, "-c", FLOODER, world.endpoint, cmd, *posing],
                               stdout=subprocess.PIPE, text=True)  # fmt: skip
    assert flooder.stdout is not None and flooder.stdout.readline() == "flooding\n"

    def watch() -> None:  # the longest lane a stranger had
        while not stop.wait(0.001):
            longest[0] = max([longest[0], *map(len, list(cons.events._lanes.values()))])

    def command() -> None:
        while not stop.wait(0.05):  # a client's 20 Hz, among the flood
            client.put(codec.encode(ThrustCmd(thrust=(0.25, 0.5))))

    threads = [threading.Thread(target=watch), threading.Thread(target=command)]
    for thread in threads:
        thread.start()
    try:
        result = world.run(names, TICKS, deadline_s=2.0, start_timeout_s=5.0, realtime_factor=1.0)
    finally:
        stop.set()
        flooder.kill()
        flooder.wait()
        for thread in threads:
            thread.join()
    assert result.error == "" and result.ticks_done == TICKS
    world.members["cons"].join()
    assert world.members["cons"].ticks == list(range(TICKS))
    assert heard and heard[-1].thrust == (0.25, 0.5)
    assert cons.rejections.totals["malformed"] > 0  # the junk that was read: refused
    assert longest[0] <= lanes.LANE_EVENTS
    refused = cons.rejections.totals["token of no participant of this run"]
    assert refused >= 1 if token else refused == 0  # its join, and its leave if seen
