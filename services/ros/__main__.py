import sys

from services.ros.service import main

sys.exit(main())
