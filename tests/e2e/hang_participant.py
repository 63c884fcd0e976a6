"""An external lockstep participant for fault tests: steps, then hangs or crashes.

python hang_participant.py ENDPOINT WORLD NAME TICK {hang,kill}
"""

import os
import signal
import sys
import time

from catabot.bus.keys import Keys
from catabot.bus.participant import Participant
from catabot.bus.session import Connection, open_session

endpoint, world, name, at, how = sys.argv[1:6]
session = open_session(Connection(connect=(endpoint,)))


def step(tick, inputs) -> None:
    if tick.tick == int(at):
        if how == "kill":  # the ack of the tick before is on its way out first: under load
            time.sleep(0.3)  # SIGKILL lost it, and the run ended 20 ticks earlier than tested
            os.kill(os.getpid(), signal.SIGKILL)
        time.sleep(3600)


Participant(session, Keys(world), name, peers=[]).run(step)
session.close()
