"""Gymnasium environments over the simulator (`import catabot.gym` registers them).

`CataBot/Navigate-v0`: reach a goal drawn 20-60 m from a random start in the bundled
`navigate` scenario (a bay with an island and a shore, five buoys, a light current and a
steady wind); `CataBot/StationKeep-v0`: hold a random start position and heading in the
`harbour` scenario, against its current, gusty wind and chop. Every
keyword of `catabot.gym.options.EnvOptions` may be given to `gymnasium.make`.
"""

from __future__ import annotations

import gymnasium

from catabot.gym.env import ActionError, CataBotEnv
from catabot.gym.link import LinkError
from catabot.gym.options import EnvOptions, EnvOptionsError

__all__ = ["ActionError", "CataBotEnv", "EnvOptions", "EnvOptionsError", "LinkError"]

ENTRY_POINT = "catabot.gym.env:CataBotEnv"
MAX_STEPS = 600  # 60 s at 10 Hz; the env truncates itself at `max_steps` (no TimeLimit:
# registered with max_episode_steps, `gym.make(..., max_steps=700)` still ended at 600).
# No passive checker: Gymnasium's (1.x) broke the env for good after a first reset that
# raised (a refused option, a run that failed): every later step raised "cannot unpack
# non-iterable NoneType". The env checks its own actions; the full env_checker passes.

if "CataBot/Navigate-v0" not in gymnasium.registry:
    gymnasium.register(
        "CataBot/Navigate-v0",
        entry_point=ENTRY_POINT,
        kwargs={"task": "navigate", "scenario": "navigate", "max_steps": MAX_STEPS},
        disable_env_checker=True,
    )
if "CataBot/StationKeep-v0" not in gymnasium.registry:
    gymnasium.register(
        "CataBot/StationKeep-v0",
        entry_point=ENTRY_POINT,
        kwargs={
            "task": "station_keep",
            "scenario": "harbour",
            "max_steps": MAX_STEPS,
            "rewards": {"progress": 1.0, "distance": 0.1, "heading": 0.5, "goal": 0.0},
        },
        disable_env_checker=True,
    )
