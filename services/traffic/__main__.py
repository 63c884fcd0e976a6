import sys

from services.traffic.service import main

sys.exit(main())
