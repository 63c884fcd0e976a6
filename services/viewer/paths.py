"""Entity paths of the viewer, one place: the logger, the blueprint and the tests agree.

world                          annotation context (label classes), Z-up
world/terrain                  the terrain mesh, coloured by height (static)
world/water                    the wave surface near the first vessel (animated)
world/bodies/<role>-<model>    each model's shape (hull box without one), an instance a body
world/trails                   vessel positions; the 3D view shows the last 30 s
world/vessels/<id>             each scenario vessel's pose (its sensors hang below)
world/vessels/<id>/<sensor>    LiDAR points, radar sector and echoes, camera + images
minimap/<id>.<radar>           the radar PPI, north up (the paper's minimap)
series/<quantity>/<id>         time series: speed, heading, thrust, IMU, LiDAR returns
metrics                        the navigation metrics (metrics.json) as a table
"""

from __future__ import annotations

WORLD = "world"
TERRAIN = "world/terrain"
WATER = "world/water"
BODIES = "world/bodies"
TRAILS = "world/trails"
METRICS = "metrics"
RTF = "series/rtf"
CLOSEST = "series/closest_approach"


def bodies(group: str) -> str:
    """`world/bodies/<role>-<model>`: the bodies of one model drawn in one colour."""
    return f"{BODIES}/{group}"


def vessel(vid: str) -> str:
    return f"world/vessels/{vid}"


def sensor(vid: str, name: str) -> str:
    return f"world/vessels/{vid}/{name}"


def minimap(vid: str, radar: str) -> str:
    return f"minimap/{vid}.{radar}"


def series(quantity: str, owner: str) -> str:
    """`series/<quantity>/<owner>`: one view per quantity, one line group per owner."""
    return f"series/{quantity}/{owner}"
