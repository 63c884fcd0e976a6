import sys

from services.plots.cli import main

sys.exit(main())
