"""What `catabot run` says before the clock starts: where clients connect, once they can,
and which participants started outside the run it waits for."""

from __future__ import annotations

import time
from subprocess import Popen

from catabot.bus.session import port_open
from catabot.config.notes import scenario_notes
from catabot.run import programs
from catabot.world.traffic_notes import traffic_notes
from catabot.world.world import World

LISTEN_WAIT_S = 10.0  # the conductor's endpoint opens ≈1-2 s after start on a busy machine


def announce(
    world: World, *, scenario_file: str | None, endpoint: str, listener: Popen[str] | None
) -> None:
    """The `zenoh:` line, then the scenario's notes and who the run waits for. On the
    embedded mesh (`listener`: the conductor, which listens there) the line waits until the
    endpoint takes connections: printed at once, it came 1.7 s early, and a script that
    connected on reading it was refused; a conductor that died says nothing to connect to."""
    if listener is not None and not _listening(endpoint, listener):
        return  # the supervisor reports why the conductor ended
    name = world.scenario.name
    print(f"zenoh: clients connect to {endpoint} (world {name!r}, keys catabot/{name}/...)",
          flush=True)  # fmt: skip
    for note in [*scenario_notes(world.scenario), *traffic_notes(world)]:
        print(note, flush=True)
    _waits_for(world, scenario_file, endpoint)


def _listening(endpoint: str, listener: Popen[str]) -> bool:
    """Whether the endpoint's port takes a connection (LISTEN_WAIT_S at most) while its
    listener lives; UDP ones are not probed."""
    if endpoint.startswith(("udp/", "quic/")):
        return listener.poll() is None
    limit = time.monotonic() + LISTEN_WAIT_S
    while port_open(endpoint, timeout_s=0.5) and time.monotonic() < limit:
        if listener.poll() is not None:
            return False
        time.sleep(0.05)
    return listener.poll() is None


def _waits_for(world: World, scenario_file: str | None, endpoint: str) -> None:
    """The clock starts only once the participants started outside the run have joined:
    say so, or the console shows a progress bar standing at zero until the start timeout."""
    launched = {p.participant for p in programs.programs(world.scenario, scenario_file)}
    outside = [p for p in world.participants if p not in {*world.services, *launched}]
    if outside:
        print(
            f"waiting for {', '.join(outside)} to join (started by you, connecting to "
            f"{endpoint}); the run gives up after {world.scenario.clock.start_timeout_s:g} s",
            flush=True,
        )
    for vessel in world.scenario.vessels:  # the flags of the README's stack (add_stack_args)
        c = vessel.controller
        if c is not None and c.participant in outside:
            print(f"  {c.participant}: e.g. python my_stack.py --connect {endpoint} "
                  f"--participant {c.participant} --vessel {vessel.id}", flush=True)  # fmt: skip
