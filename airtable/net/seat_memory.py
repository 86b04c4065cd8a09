"""A student's seat tokens, kept on their computer: a client started again gets its seat back.

The token of a WELCOME lives in the client's memory, so a client that lost
its connection asks for its seat again (identity.py). A client that was
closed, crashed or killed, or a laptop that restarted, had lost it: the
student came back as a newcomer, "Ann 2" in another seat and colour, while
the roster held "Ann"'s seat for someone who never came (a user test, 2 of 2).
So the student command keeps each table's token in a small JSON file in the
user's config folder, by the table's address and the name it was given for,
and a new client with the same name asks for that seat as a reconnecting one
does: by its number, proven in answer to the server's CHALLENGE. A token the
table does not know (its teacher's key changed, the seat was given away) just
asks for nothing, as before.

The file is the student's own, like a browser's cookies; it is read and written
as JSON only, and anything in it that does not look like a token is ignored.
Reading or writing it may fail (a read-only home): the client then simply
remembers nothing.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from airtable.net.identity import config_dir, token_seat

# The most tables kept (the newest): a student meets a handful of tables a term.
MAX_TABLES = 32


def default_path() -> Path:
    """Where the student command keeps the tokens: config_dir()/seats.json."""
    return config_dir() / "seats.json"


class SeatMemory:
    """The tokens last given to this computer, by table address and name, in a JSON file at `path`."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)

    def recall(self, address: str, name: str | None) -> str | None:
        """The token the table at `address` gave `name` last, or None."""
        token = self._read().get(_key(address, name))
        return token if isinstance(token, str) and token_seat(token) is not None else None

    def keep(self, address: str, name: str | None, token: str) -> None:
        """Remember `token` as the one the table at `address` gave `name` (the newest, at the end)."""
        if token_seat(token) is None:
            return
        tokens = self._read()
        tokens.pop(_key(address, name), None)
        tokens[_key(address, name)] = token
        kept = dict(list(tokens.items())[-MAX_TABLES:])
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            spare = self.path.with_name(self.path.name + ".new")
            fd = os.open(spare, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                json.dump({"tokens": kept}, f, ensure_ascii=False, indent=1)
            os.replace(spare, self.path)  # whole or not at all: two clients never leave half a file
        except OSError:
            pass

    def _read(self) -> dict[str, str]:
        try:
            data = json.loads(self.path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return {}
        tokens = data.get("tokens") if isinstance(data, dict) else None
        if not isinstance(tokens, dict):
            return {}
        return {k: v for k, v in tokens.items() if isinstance(k, str) and isinstance(v, str)}


def _key(address: str, name: str | None) -> str:
    """One entry per table and name: two students rehearsing on one laptop keep a seat each."""
    return f"{address} {name or ''}"
