import sys

from services.physics.service import main

sys.exit(main())
