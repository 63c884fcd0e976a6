"""The service shell (catabot/run/service.py): a SIGTERM named as such however it surfaces."""

from __future__ import annotations

from catabot.run.service import Terminated, _from_sigterm


def test_a_sigterm_met_inside_a_compiled_call_is_still_a_sigterm() -> None:
    """Raised as a numba-compiled call returned, the handler's Terminated came out as a
    SystemError ("CPUDispatcher(...) returned a result with an exception set") with it as
    its cause, and the run named physics as crashed (a CI rehearsal)."""
    wrapped = SystemError("CPUDispatcher(<function f>) returned a result with an exception set")
    wrapped.__cause__ = Terminated(143)
    assert _from_sigterm(wrapped) and _from_sigterm(Terminated(143))
    other = ValueError("a bug")
    other.__context__ = KeyError("while handling")
    assert not _from_sigterm(other) and not _from_sigterm(SystemError("alone"))
