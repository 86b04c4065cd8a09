"""`python -m bench [--quick] [--only SECTION] [--no-pymunk] [--seed N]`."""

import sys

from bench.main import main

sys.exit(main())
