import sys

from services.sensors.service import main

sys.exit(main())
