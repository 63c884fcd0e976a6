"""Samples forged in a run's session's name, on the open mesh (a sample's sender is the source
info it states: identity.py). A trial's forged Tick changed the physics and the run ended
"completed"; its forged End was blamed on the network; its forged states were recorded in
place of physics's. Each now ends the run with an error that says what happened."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import zenoh

from catabot.bus import codec
from catabot.bus.clock import Stream
from catabot.bus.inbox import Inputs
from catabot.bus.messages import End, Tick, VesselState
from catabot.bus.participant import Participant
from tests.catabot.bus.lockstep_world import World, _state

Forge = Callable[[zenoh.Sample], bytes]


def _forger(world: World, heard_on: str, put_on: str, forge: Forge) -> None:
    """A stranger that answers the first sample on `heard_on` with one of its own on `put_on`,
    in that sample's sender's name (its source info copied), as `forge` makes it."""
    session, done = world.open(), []

    def on_sample(sample: zenoh.Sample) -> None:
        info = sample.source_info
        if done or info is None:
            return
        done.append(True)
        forged = zenoh.SourceInfo(info.source_id, info.source_sn + 1000)
        session.put(put_on, forge(sample), source_info=forged)

    session.declare_subscriber(heard_on, on_sample)


def _run_two(world: World, ticks: int = 200) -> str:
    names, holder = ["prod", "cons"], dict[str, Participant]()
    state = world.keys.vessel_state("prod")

    def produce(tick: Tick, _inputs: Inputs) -> None:
        holder["prod"].publish(state, _state(tick.tick))

    holder["prod"] = world.member("prod", produce, peers=names).participant
    world.member("cons", inputs=[Stream(state, VesselState, "prod", 1)], peers=names)
    return world.run(names, ticks, deadline_s=5.0, start_timeout_s=5.0, realtime_factor=1.0).error


def test_a_forged_tick_ends_the_run_saying_so(world: World) -> None:
    def the_next(sample: zenoh.Sample) -> bytes:
        tick = codec.decode(sample.payload.to_bytes(), Tick)
        return codec.encode(dataclasses.replace(tick, tick=tick.tick + 1))

    _forger(world, world.keys.tick(), world.keys.tick(), the_next)
    error = _run_two(world)
    said = "a Tick the conductor did not send reached clock/tick, in its session's name: "
    assert error.startswith(said + "a process on this mesh poses as the conductor"), error


def test_a_forged_end_is_named_not_blamed_on_the_network(world: World) -> None:
    def end_now(sample: zenoh.Sample) -> bytes:
        tick = codec.decode(sample.payload.to_bytes(), Tick)
        return codec.encode(End(tick.run, tick.tick, "completed", ""))

    _forger(world, world.keys.tick(), world.keys.end(), end_now)
    error = _run_two(world)
    assert error.startswith("an End the conductor did not send reached clock/end"), error


def test_forged_states_for_a_tick_end_the_run_whichever_came_first(world: World) -> None:
    def moved(sample: zenoh.Sample) -> bytes:
        state = codec.decode(sample.payload.to_bytes(), VesselState)
        return codec.encode(dataclasses.replace(state, position=(600.0, 0.0, 0.0)))

    key = world.keys.vessel_state("prod")
    _forger(world, key, key, moved)
    error = _run_two(world)
    assert error.startswith("participant 'cons' stopped at tick "), error
    assert "two different samples for one tick: tick 0 of " in error
    assert "both in prod's session's name: one is forged, or prod sent two" in error
