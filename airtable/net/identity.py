"""Seat tokens: a student who reconnects gets their old number, name and colour back.

WELCOME hands each player a token; a reconnecting client sends it in HELLO.
The token names the seat and is signed, `"<number>-<32 hex digits>"`, where
the digits are an HMAC-SHA256 (cut to 16 bytes) of the number and the name
under a key that only the teacher's app knows. So the server needs no memory
of its own: a server restarted with the same key (kept in a file in the
user's config folder, see `load_key`) still recognises its students, and a
student cannot make up a token for someone else's seat. The colour follows
the number, so it comes back too. A token whose seat is taken, or that does
not verify, is simply not honoured: the player gets the lowest free seat.
"""

from __future__ import annotations

import hashlib
import hmac
import os
import re
import secrets
from pathlib import Path

KEY_BYTES = 32
_TOKEN = re.compile(r"^([1-9][0-9]{0,5})-([0-9a-f]{32})$")


class SeatTokens:
    """Makes and checks seat tokens under one key (random when none is given)."""

    def __init__(self, key: bytes | None = None) -> None:
        self.key = key if key else secrets.token_bytes(KEY_BYTES)

    def _mac(self, number: int, name: str) -> str:
        message = f"{number}\n{name}".encode()
        return hmac.new(self.key, message, hashlib.sha256).hexdigest()[:32]

    def make(self, number: int, name: str) -> str:
        """The token of seat `number` held by `name` ("" for a player without a name)."""
        return f"{number}-{self._mac(number, name)}"

    def seat(self, token: str | None, name: str) -> int | None:
        """The seat number `token` proves for `name`, or None."""
        match = _TOKEN.match(token or "")
        if match is None:
            return None
        number = int(match.group(1))
        return number if hmac.compare_digest(match.group(2), self._mac(number, name)) else None


def config_dir() -> Path:
    """Where the teacher's app keeps its files: $XDG_CONFIG_HOME/airtable (or the platform's)."""
    if os.name == "nt":
        base = Path(os.environ.get("APPDATA") or Path.home() / "AppData" / "Roaming")
    else:
        base = Path(os.environ.get("XDG_CONFIG_HOME") or Path.home() / ".config")
    return base / "airtable"


def load_key(path: Path | None = None) -> bytes | None:
    """The seat-token key kept in `path` (default: config_dir()/seat-key), made on first use.

    None if the file can neither be read nor written: tokens then last as long as the server."""
    path = path or config_dir() / "seat-key"
    try:
        key = path.read_bytes()
        if len(key) >= 16:
            return key
    except OSError:
        pass
    key = secrets.token_bytes(KEY_BYTES)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        with os.fdopen(fd, "wb") as f:
            f.write(key)
    except OSError:
        return None
    return key
