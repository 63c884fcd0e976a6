import sys

from services.datasets.cli import main

sys.exit(main())
