"""`airtable-client`: the student's command.

pygame prints a banner of its own when imported; a student's terminal should
start with the client's line ("connected to ...; you are C1 Zoe"), so the
banner is turned off here, at the entry point, before the player (and with it
pygame) is imported.
"""

from __future__ import annotations

import os
from collections.abc import Sequence


def main(argv: Sequence[str] | None = None) -> int:
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
    from airtable.student.command import main as play

    return play(argv)


if __name__ == "__main__":  # python -m airtable.client_cli, as the installed command
    raise SystemExit(main())
