"""A benchmark peer process: an empty CataBot participant, or a raw Zenoh tick echo."""

from __future__ import annotations

import argparse

import zenoh

from catabot.bus.keys import Keys
from catabot.bus.messages import Tick
from catabot.bus.participant import Participant
from catabot.bus.session import Connection, open_session


def catabot_peer(session: zenoh.Session, world: str, name: str, peers: list[str]) -> None:
    def step(tick: Tick, inputs: object) -> None:
        pass

    Participant(session, Keys(world), name, peers=peers).run(step)  # type: ignore[arg-type]


def raw_peer(session: zenoh.Session, world: str, name: str) -> None:
    """Receive on our own thread from a FIFO channel, answer each tick with an ack."""
    sub = session.declare_subscriber(f"raw/{world}/tick", zenoh.handlers.FifoChannel(1024))
    pub = session.declare_publisher(
        f"raw/{world}/ack/{name}", congestion_control=zenoh.CongestionControl.BLOCK
    )
    session.liveliness().declare_token(f"raw/{world}/live/{name}")
    for sample in sub:
        payload = sample.payload.to_bytes()
        if payload == b"end":
            return
        pub.put(payload)


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("mode", choices=["catabot", "raw"])
    p.add_argument("--connect", required=True)
    p.add_argument("--world", required=True)
    p.add_argument("--name", required=True)
    p.add_argument("--peers", default="")
    a = p.parse_args()
    session = open_session(Connection(connect=(a.connect,)))
    try:
        if a.mode == "catabot":
            catabot_peer(session, a.world, a.name, [x for x in a.peers.split(",") if x])
        else:
            raw_peer(session, a.world, a.name)
    finally:
        session.close()


if __name__ == "__main__":
    main()
