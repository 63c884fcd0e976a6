"""`python -m catabot ...` is the `catabot` command."""

import sys

from catabot.run.cli import main

sys.exit(main())
