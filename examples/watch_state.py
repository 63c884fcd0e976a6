"""Print a vessel's state as the simulation publishes it (an observer never blocks the clock).

catabot run --realtime 1 --listen tcp/127.0.0.1:7447 &
python examples/watch_state.py --connect tcp/127.0.0.1:7447 --vessel ego --count 20
"""

import zenoh
from common import keys, parser, session

from catabot.bus import codec
from catabot.bus.messages import VesselState


def show(state: VesselState) -> None:
    x, y, z = state.position
    u = state.linear_velocity[0]
    print(f"t={state.stamp_ns / 1e9:8.2f} s  x={x:8.2f} y={y:8.2f} z={z:6.3f}  u={u:5.2f} m/s")


def main() -> None:
    p = parser(__doc__)
    p.add_argument("--count", type=int, default=0, help="stop after this many states (0: never)")
    p.add_argument("--every", type=int, default=10, help="print one state in this many")
    args = p.parse_args()
    with session(args) as s:
        sub = s.declare_subscriber(
            keys(s, args).vessel_state(args.vessel), zenoh.handlers.RingChannel(256)
        )
        shown = 0
        for n, sample in enumerate(sub):
            if n % args.every == 0:
                show(codec.decode(sample.payload.to_bytes(), VesselState))
                shown += 1
            if args.count and shown >= args.count:
                break


if __name__ == "__main__":
    main()
