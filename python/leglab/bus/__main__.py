"""`python3 -m leglab.bus VERB ...`: see leglab.bus.cli."""

import sys

from .cli import main

sys.exit(main())
