"""Environment fields: water current and wind evaluated at many points at once.

Their settings (`CurrentConfig`, `WindConfig`) are scenario models in catabot.config; the
physics turns the fields into forces; sensors and viewers may read the same fields.
"""

from catabot.world.environment.current import CurrentField, load_current_map
from catabot.world.environment.wind import WindField

__all__ = ["CurrentField", "WindField", "load_current_map"]
