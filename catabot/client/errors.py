"""What a stack sees go wrong, as errors that say what and where (never a hang).

Every one derives from `catabot.errors.CataBotError` (and the built-in error it stands
for), so a stack's `main` can catch one type and print the message.
"""

from __future__ import annotations

from catabot.bus.messages import End
from catabot.errors import CataBotError


class ClientError(CataBotError):
    """The root of the client's errors."""


class SimulatorNotFound(ClientError, LookupError):
    """No running world answered `world/info` within the timeout."""


class SeveralWorlds(ClientError, LookupError):
    """More than one world answered and none was named (`world=`, `--world`)."""


class UnknownVessel(ClientError, LookupError):
    """The world has no scenario vessel with that id (the message lists the ids)."""


class UnknownSensor(ClientError, LookupError):
    """The vessel has no sensor with that name (the message lists its sensors)."""


class NotAParticipant(ClientError, ValueError):
    """A join with a name the run does not expect (not in `clock.external_participants`
    nor any vessel's `controller.participant`)."""


class SeveralVessels(ClientError, ValueError):
    """The participant controls more vessels than a `Joined` commands (one)."""


class NotItsVessel(ClientError, ValueError):
    """A join naming a vessel other than the one the participant controls: nothing would
    command its own, and the run would stop at the deadline blaming physics."""


class WrongRate(ClientError, ValueError):
    """A join's `rate_hz` the clock cannot step, or not the controller's own rate (the
    participant steps at that one whatever it asks: it was taken silently)."""


class TooLate(ClientError, RuntimeError):
    """The run started without this participant, or another session holds its name."""


class CommandError(ClientError, ValueError):
    """A command the vessel cannot take: not finite, the wrong number of thrusters, a
    kind its controller does not drive. Raised in the stack, before anything is sent."""


class NoData(ClientError, TimeoutError):
    """Nothing arrived on a stream within the timeout (the run not started, the sensor off)."""


class RunEnded(ClientError, RuntimeError):
    """The run ended (or its conductor vanished) while the stack waited; `end` is the
    conductor's `End` when one came, `reason` its reason (or what happened)."""

    def __init__(self, message: str, end: End | None = None) -> None:
        super().__init__(message)
        self.end = end
        self.reason = end.reason if end is not None else "conductor gone"
