"""Where tests find things: the checkout, its bundled data, and `../shared` beside it.

`../shared` holds real input data the project may not commit (the New York river elevation
image); tests that need it skip cleanly where it is absent (`SHARED_DATA` does not exist).
"""

from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
BAY = REPO / "catabot" / "data" / "terrain" / "bay.png"
SHARED_DATA = REPO.parent / "shared" / "data"
NEW_YORK_RIVER = SHARED_DATA / "elevation" / "new-york-river.png"
