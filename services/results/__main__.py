import sys

from services.results.cli import main

sys.exit(main())
