"""Print a vessel's state as the simulation publishes it (an observer never blocks the clock).

python examples/watch_state.py --connect tcp/127.0.0.1:7447 --vessel ego
"""

import time

from common import parser, session

from catabot.bus import codec
from catabot.bus.keys import Keys
from catabot.bus.messages import VesselState

args = parser(__doc__).parse_args()


def show(sample) -> None:
    s = codec.decode(sample.payload.to_bytes(), VesselState)
    x, y, z = s.position
    u = s.linear_velocity[0]
    print(f"t={s.stamp_ns / 1e9:8.2f} s  x={x:8.2f} y={y:8.2f} z={z:6.3f}  u={u:5.2f} m/s")


with session(args) as s:
    s.declare_subscriber(Keys(args.world).vessel_state(args.vessel), show)
    time.sleep(3600)
