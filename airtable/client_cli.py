"""`airtable-client`: the student's command.

pygame prints a banner of its own when imported; a student's terminal should
start with the client's line ("connected to ...; you are C1 Zoe"), so the
banner is turned off here, at the entry point, before the player (and with it
pygame) is imported; the window's name for the taskbar is set here too.
"""

from __future__ import annotations

from collections.abc import Sequence

from airtable.desktop import prepare_for_pygame


def main(argv: Sequence[str] | None = None) -> int:
    prepare_for_pygame()
    from airtable.student.command import main as play

    return play(argv)


if __name__ == "__main__":  # python -m airtable.client_cli, as the installed command
    raise SystemExit(main())
