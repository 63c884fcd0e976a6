import sys

from services.recorder.service import main

sys.exit(main())
