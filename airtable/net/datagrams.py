"""Inputs over UDP beside the TCP session, so the newest cursor never waits behind a lost older one.

Over TCP every INPUT waits its turn: one lost packet holds up all the inputs after it for a
retransmission (input-to-effect 195 ms median at 100 ms one-way with 10 % loss). Only the
newest cursor matters, so the player also sends each INPUT as a UDP datagram to the server's
port; the server applies a datagram only when its sequence number is newer than any before,
and answers with a small acknowledgement so the player knows UDP gets through. While it does,
the player's TCP INPUTs are only a heartbeat and the server takes the cursor from UDP; where
UDP is blocked (no acknowledgement), inputs go over TCP as before.

A datagram is authenticated by a key that only the TCP session knows: WELCOME carries
`"udp_key"` (32 hex digits, new for every connection), and each datagram carries the first
16 bytes of an HMAC-SHA256 under that key. Layout (big-endian), see docs/protocol.md:

    INPUT_DATAGRAM (11, player -> server): u8 type, u32 seat number, u32 sequence,
        16 bytes MAC of the 9 bytes before it and the payload, then the INPUT JSON payload
    INPUT_ACK (12, server -> player): u8 type, u32 seat number, u32 sequence,
        16 bytes MAC of the 9 bytes before it

No sockets here: bytes in, bytes out.
"""

from __future__ import annotations

import hashlib
import hmac
import secrets
import struct
from dataclasses import dataclass

INPUT_DATAGRAM = 11
INPUT_ACK = 12
KEY_HEX = 32  # a session's key: 16 random bytes as hex
MAC_BYTES = 16
_HEAD = struct.Struct("!BII")
MAX_DATAGRAM = _HEAD.size + MAC_BYTES + 1024  # a datagram near an INPUT's real size
MAX_SEQUENCE = 2**32 - 1


def new_key() -> str:
    return secrets.token_hex(KEY_HEX // 2)


def _mac(key: str, data: bytes) -> bytes:
    return hmac.new(bytes.fromhex(key), data, hashlib.sha256).digest()[:MAC_BYTES]


def encode_input(key: str, number: int, sequence: int, payload: bytes) -> bytes:
    """An INPUT_DATAGRAM carrying `payload` (an INPUT frame's JSON) for seat `number`."""
    head = _HEAD.pack(INPUT_DATAGRAM, number, sequence)
    return head + _mac(key, head + payload) + payload


def encode_ack(key: str, number: int, sequence: int) -> bytes:
    head = _HEAD.pack(INPUT_ACK, number, sequence)
    return head + _mac(key, head)


@dataclass(frozen=True)
class Datagram:
    """A datagram's type, seat and sequence, with what follows the MAC (checked only by `verify`)."""

    kind: int
    number: int
    sequence: int
    mac: bytes
    payload: bytes

    def verify(self, key: str | None) -> bool:
        """Whether the MAC is right under the session's `key` (False without one)."""
        if not key:
            return False
        head = _HEAD.pack(self.kind, self.number, self.sequence)
        return hmac.compare_digest(self.mac, _mac(key, head + self.payload))


def parse(data: bytes) -> Datagram | None:
    """The fields of a datagram of ours, or None for anything else (never an exception)."""
    if not _HEAD.size + MAC_BYTES <= len(data) <= MAX_DATAGRAM:
        return None
    kind, number, sequence = _HEAD.unpack_from(data)
    if kind not in (INPUT_DATAGRAM, INPUT_ACK):
        return None
    mac_end = _HEAD.size + MAC_BYTES
    return Datagram(kind, number, sequence, data[_HEAD.size : mac_end], data[mac_end:])
