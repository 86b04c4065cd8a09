"""The command lines' parser: a bad argument is one line and exit status 2; usage only on --help.

argparse's own `error()` prints the whole usage block before the message, which buries the one
line a teacher or a student needs to read. Both commands (`python -m airtable` and
`airtable-client`) use this parser. No pygame here.
"""

from __future__ import annotations

import argparse
from typing import NoReturn


class OneLineParser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line on stderr: `airtable: <problem> (--help lists the options)`."""

    def error(self, message: str) -> NoReturn:
        name = self.prog.split()[-1]  # "python -m airtable" -> "airtable"
        self.exit(2, f"{name}: {message} (--help lists the options)\n")
