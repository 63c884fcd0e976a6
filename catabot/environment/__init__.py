"""Environment shared by every service: water current and wind, their settings and fields.

Settings (`CurrentConfig`, `WindConfig`, `WindZone`) are validated pydantic models that live
in a scenario; fields (`CurrentField`, `WindField`) evaluate them at many points at once.
The physics turns them into forces; sensors and viewers may read the same fields.
"""

from catabot.environment.config import (
    CurrentConfig,
    CurrentMapConfig,
    CurrentMapError,
    EnvironmentConfigError,
    WindConfig,
    WindZone,
)
from catabot.environment.current import CurrentField, load_current_map
from catabot.environment.wind import WindField

__all__ = [
    "CurrentConfig",
    "CurrentField",
    "CurrentMapConfig",
    "CurrentMapError",
    "EnvironmentConfigError",
    "WindConfig",
    "WindField",
    "WindZone",
    "load_current_map",
]
