"""Drive a vessel from outside the lockstep: one thrust command per thruster, -1..1.

The last command holds after the program ends, until a release or the scenario's
`command_timeout_s` hands the vessel back (README, Commanding); physics refuses a command of
the wrong length on its own console, as it refuses any other sender's.

catabot run --realtime 1 --listen tcp/127.0.0.1:7447 &
python examples/send_thrust.py --connect tcp/127.0.0.1:7447 --thrust 0.5 0.9
"""

import time

import zenoh
from common import clear_errors, keys, parser, session

from catabot.bus import codec
from catabot.bus.messages import ThrustCmd


def ticking(states: zenoh.Subscriber, *, timeout_s: float) -> bool:
    """Whether the vessel's state comes within `timeout_s`: the run has started."""
    limit = time.monotonic() + timeout_s
    while states.try_recv() is None:
        if time.monotonic() > limit:
            return False
        time.sleep(0.05)
    return True


def main() -> None:
    p = parser(__doc__)
    p.add_argument("--thrust", type=float, nargs="+", required=True)
    p.add_argument("--repeat", type=int, default=10, help="send this many times, 0.1 s apart")
    args = p.parse_args()
    if not all(-1.0 <= v <= 1.0 for v in args.thrust):  # physics refuses it, on its console
        p.error(f"--thrust {args.thrust}: each value in [-1, 1]")
    with clear_errors("send_thrust.py"), session(args) as s:
        at = keys(s, args)
        pub = s.declare_publisher(at.cmd_thrust(args.vessel))
        states = s.declare_subscriber(at.vessel_state(args.vessel), zenoh.handlers.RingChannel(1))
        if not ticking(states, timeout_s=args.timeout):  # then every service of the run listens
            raise SystemExit(f"no simulation subscribes to {pub.key_expr}: is it running?")
        states.undeclare()
        for _ in range(args.repeat):
            pub.put(codec.encode(ThrustCmd(thrust=tuple(args.thrust))))
            time.sleep(0.1)


if __name__ == "__main__":
    main()
