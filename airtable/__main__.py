"""`python -m airtable`: the teacher's table (and the server students join)."""

import sys

from airtable.cli import main

if __name__ == "__main__":
    sys.exit(main())
