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

The token crosses the network once, in the WELCOME. To ask for the seat
again a client sends only the seat's number in HELLO; the server answers
with a CHALLENGE (a fresh random nonce) and the client with a PROOF,
`seat_proof(token, nonce)`. A program that takes the port after the teacher
quits therefore learns a proof for its own nonce, which no real server will
ever ask for again: nothing it can reuse (docs/classroom.md says what the
token does and does not protect against).
"""

from __future__ import annotations

import hashlib
import hmac
import os
import re
import secrets
from pathlib import Path

KEY_BYTES = 32
PROOF_LABEL = b"airtable seat proof\n"  # so a proof is never some other HMAC under the same token
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

    def proves(self, number: int, name: str, nonce: str, proof: str) -> bool:
        """Whether `proof` answers CHALLENGE `nonce` with the token of seat `number` held by `name`."""
        return hmac.compare_digest(proof, seat_proof(self.make(number, name), nonce))

    def seat(self, token: str | None, name: str) -> int | None:
        """The seat number `token` proves for `name`, or None."""
        match = _TOKEN.match(token or "")
        if match is None:
            return None
        number = int(match.group(1))
        return number if hmac.compare_digest(match.group(2), self._mac(number, name)) else None


def new_nonce() -> str:
    """A CHALLENGE's nonce: 16 random bytes as 32 hex digits, never the same twice."""
    return secrets.token_hex(16)


def seat_proof(token: str, nonce: str) -> str:
    """The PROOF that answers CHALLENGE `nonce`: HMAC-SHA256 under the token, 64 hex digits."""
    return hmac.new(token.encode(), PROOF_LABEL + nonce.encode(), hashlib.sha256).hexdigest()


def token_seat(token: str | None) -> int | None:
    """The seat number a token names ("3-..." -> 3), or None for no token or a malformed one."""
    match = _TOKEN.match(token or "")
    return int(match.group(1)) if match else None


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
