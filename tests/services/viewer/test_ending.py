"""How a live view says its run ended (services/viewer/cli.py `_ending`, live.py `_gone`):
by its End, else by its run folder once the link is lost, else exit 2 saying why."""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace

from catabot.bus.clock import CONDUCTOR
from catabot.bus.messages import End
from catabot.bus.session import Connection, free_port, open_session
from catabot.config.load import parse_scenario
from catabot.world.world import World
from services.viewer.cli import _ending
from services.viewer.live import LINK_S, LOST_S, LiveView


def _args(source: Path | None) -> argparse.Namespace:
    return argparse.Namespace(source=str(source) if source else None, connect=["tcp/h:1"])


def _folder(tmp: Path, *, ended: bool) -> Path:
    (tmp / "log").mkdir(parents=True)
    if ended:
        (tmp / "log" / "run.json").write_text(json.dumps({"reason": "completed", "ticks": 9}))
    return tmp


def _view(*, lost: bool, ever_linked: bool) -> LiveView:
    return SimpleNamespace(lost=lost, ever_linked=ever_linked)  # type: ignore[return-value]


def test_each_way_a_view_can_end_is_said(tmp_path: Path) -> None:
    done = _folder(tmp_path / "done", ended=True)
    end = End("r", 9, "completed")
    assert _ending(_args(done), end, _view(lost=False, ever_linked=True)) == (
        "run ended: completed", 0)  # fmt: skip
    assert _ending(_args(None), None, _view(lost=False, ever_linked=True))[1] == 0  # Ctrl-C
    text, code = _ending(_args(done), None, _view(lost=True, ever_linked=True))
    assert code == 0 and text.startswith("run ended: completed (its run folder says")
    text, code = _ending(_args(done), None, _view(lost=True, ever_linked=False))
    assert code == 2 and f"`catabot view {done}` replays it" in text
    going = _folder(tmp_path / "going", ended=False)
    for source in (going, None):
        text, code = _ending(_args(source), None, _view(lost=True, ever_linked=True))
        assert code == 2 and "went away (or never answered)" in text


def test_a_lost_link_ends_the_view_at_once_only_when_the_run_folder_says_it_is_over(
    tmp_path: Path,
) -> None:
    """A flap mid-run, or a slow first link, must not end a live view: it waits LINK_S."""
    nobody = SimpleNamespace(info=SimpleNamespace(peers_zid=list, routers_zid=list))
    view = object.__new__(LiveView)
    view.session, view.ever_linked = nobody, False  # type: ignore[assignment]
    view.conductor = SimpleNamespace(gone=lambda _: False, left_at=None)  # type: ignore[assignment]
    view._linked_at = time.monotonic() - LOST_S - 1.0
    assert not view._gone(_folder(tmp_path / "going", ended=False))
    assert not view._gone(None)
    assert view._gone(_folder(tmp_path / "done", ended=True))
    view._linked_at = time.monotonic() - LINK_S - 1.0
    assert view._gone(None)


def _until(check: Callable[[], bool], limit_s: float) -> bool:
    end = time.monotonic() + limit_s
    while not check() and time.monotonic() < end:
        time.sleep(0.05)
    return check()


def test_a_view_through_a_router_sees_its_run_go_when_its_conductor_leaves() -> None:
    """Through a standalone router the view's link stays up after a run killed outright
    (no End): it waited for an End forever. A stranger's token coming and going is not it."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    router = open_session(Connection(listen=(endpoint,), mode="router"))
    world = World.resolve(parse_scenario({"name": "routed", "vessels": [{"id": "ego"}]}))
    sessions = [open_session(Connection(connect=(endpoint,), mode="client")) for _ in range(3)]
    viewer, conductor, stranger = sessions
    try:
        view = LiveView(viewer, world)
        token = conductor.liveliness().declare_token(world.keys.live(CONDUCTOR, "a1"))
        assert _until(lambda: view.conductor.members.present.get(CONDUCTOR) == "a1", 5.0)
        fake = stranger.liveliness().declare_token(world.keys.live(CONDUCTOR, "b2"))
        time.sleep(0.5)
        fake.undeclare()
        time.sleep(LOST_S + 0.5)
        assert not view._gone(None) and view.conductor.members.present.get(CONDUCTOR) == "a1"
        token.undeclare()
        assert _until(lambda: view._gone(None), LOST_S + 5.0)
        assert view.ever_linked  # the link itself never dropped
    finally:
        for session in (*sessions, router):
            session.close()
