import sys

from services.viewer.cli import main

sys.exit(main())
