"""Print a vessel's state as the simulation publishes it (an observer never blocks the clock),
until the run ends (or its conductor dies) or --count states are shown.

catabot run --realtime 1 --listen tcp/127.0.0.1:7447 &
python examples/watch_state.py --connect tcp/127.0.0.1:7447 --vessel ego --count 20
"""

import itertools
import queue
import time

import zenoh
from common import clear_errors, keys, parser, session

from catabot.bus import codec
from catabot.bus.clock import CONDUCTOR
from catabot.bus.messages import End, VesselState

GRACE_S = 2.0  # the conductor's End may come after its token has gone: wait for it this long


def show(state: VesselState) -> None:
    x, y, z = state.position
    u = state.linear_velocity[0]
    print(f"t={state.stamp_ns / 1e9:8.2f} s  x={x:8.2f} y={y:8.2f} z={z:6.3f}  u={u:5.2f} m/s")


def main() -> None:
    p = parser(__doc__)
    p.add_argument("--count", type=int, default=0, help="stop after this many states (0: never)")
    p.add_argument("--every", type=int, default=10, help="print one state in this many")
    args = p.parse_args()
    with clear_errors("watch_state.py"), session(args) as s:
        k = keys(s, args)
        got: queue.Queue[zenoh.Sample] = queue.Queue()  # the states and the run's end, in order
        s.declare_subscriber(k.vessel_state(args.vessel), got.put)
        s.declare_subscriber(k.end(), got.put)
        gone = k.live(CONDUCTOR, "*")  # its token goes when it dies without an end
        s.liveliness().declare_subscriber(gone, got.put)
        shown, gone_at = 0, None
        for n in itertools.count():
            try:
                wait = None if gone_at is None else max(gone_at + GRACE_S - time.monotonic(), 0)
                sample = got.get(timeout=wait)
            except queue.Empty:
                raise SystemExit("the conductor left without ending the run") from None
            if sample.kind == zenoh.SampleKind.DELETE:
                gone_at = time.monotonic()
                continue
            if str(sample.key_expr) == k.end():
                end = codec.decode(sample.payload.to_bytes(), End)
                print(f"the run ended at tick {end.tick} ({end.reason})")
                raise SystemExit(f"the run's fault: {end.error}" if end.error else 0)
            if n % args.every == 0:
                show(codec.decode(sample.payload.to_bytes(), VesselState))
                shown += 1
            if args.count and shown >= args.count:
                return


if __name__ == "__main__":
    main()
