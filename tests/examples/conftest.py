"""The examples import each other as scripts do (`from common import ...`): put examples/ on
the path so their pure functions can be tested in process."""

import sys

from tests.paths import REPO

if str(REPO / "examples") not in sys.path:
    sys.path.insert(0, str(REPO / "examples"))
