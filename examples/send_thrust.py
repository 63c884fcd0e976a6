"""Drive a vessel from outside the lockstep: one thrust command per thruster, -1..1.

catabot run --listen tcp/127.0.0.1:7447 &
python examples/send_thrust.py --connect tcp/127.0.0.1:7447 --thrust 0.5 0.9
"""

import time

from common import parser, session

from catabot.bus import codec
from catabot.bus.keys import Keys
from catabot.bus.messages import ThrustCmd

p = parser(__doc__)
p.add_argument("--thrust", type=float, nargs="+", required=True)
p.add_argument("--repeat", type=int, default=10, help="send this many times, 0.1 s apart")
args = p.parse_args()

with session(args) as s:
    pub = s.declare_publisher(Keys(args.world).cmd_thrust(args.vessel))
    for _ in range(50):  # wait (up to 5 s) until the simulation's subscriber is reachable
        if pub.matching_status.matching:
            break
        time.sleep(0.1)
    for _ in range(args.repeat):
        pub.put(codec.encode(ThrustCmd(thrust=tuple(args.thrust))))
        time.sleep(0.1)
