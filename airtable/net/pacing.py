"""Fair sending when the link is too slow for every snapshot to reach everyone.

Left alone, a server on a tight link hands each socket as much as the kernel
takes; the TCP connections then fight over the link, and the ones that lose a
few packets back off for hundreds of milliseconds at a time: some students get
everything and some nothing. The remedy is per-student pacing:

- a student gets a new snapshot only once its previous one has left the
  server *and* been acknowledged, apart from `SLACK_SNAPSHOTS` snapshots' worth
  of bytes (so a high round-trip time does not cut the rate on a fast link);
- when a snapshot is ready, the students are served in round-robin order,
  so nobody is always first;
- a student that was skipped simply gets the next snapshot, coded against
  what it last received (see codec.py).

Each student then has about the same number of bytes in flight, and since they
all wait in the same queue at the bottleneck, they all get the same rate: when
the link is full, every rate drops evenly. Where the kernel cannot say how
much is unacknowledged (not Linux), `queued_bytes` is None and pacing falls
back to "previous snapshot written".
"""

from __future__ import annotations

import struct
import sys
from collections.abc import Sequence
from typing import TypeVar

try:
    import fcntl
    import termios

    _OUTQ = termios.TIOCOUTQ  # Linux: bytes written but not yet acknowledged by the peer
except (ImportError, AttributeError):  # Windows, or a platform without the request
    fcntl = None
    _OUTQ = None

_THIN_LINEAR_TIMEOUTS = 16  # Linux TCP_THIN_LINEAR_TIMEOUTS (not exported by Python's socket module)
SLACK_SNAPSHOTS = 1.0  # snapshots' worth of unacknowledged bytes a student may still have in flight
RECHECK_S = 0.002  # how often a held-back student is looked at again

T = TypeVar("T")


def queued_bytes(sock) -> int | None:
    """Bytes written to `sock` that its peer has not acknowledged yet; None where unknown."""
    if _OUTQ is None:
        return None
    try:
        raw = fcntl.ioctl(sock.fileno(), _OUTQ, b"\0\0\0\0")
    except (OSError, ValueError):
        return None
    return struct.unpack("i", raw)[0]


def may_send(sock, last_snapshot_bytes: int, slack: float = SLACK_SNAPSHOTS) -> bool:
    """Whether this student may be handed a new snapshot now."""
    queued = queued_bytes(sock)
    return queued is None or queued <= slack * last_snapshot_bytes


class RoundRobin:
    """Serves a list in an order that starts one place later each time."""

    def __init__(self) -> None:
        self._start = 0

    def order(self, items: Sequence[T]) -> list[T]:
        if not items:
            return []
        k = self._start % len(items)
        self._start += 1
        return [*items[k:], *items[:k]]


def tune(sock) -> None:
    """Socket options for a student's connection: a connection with only a snapshot or
    two in flight cannot get the three duplicate acknowledgements that repair a lost
    packet quickly, so it waits for a retransmission timeout; linear timeouts (Linux)
    stop those waits from doubling each time, which otherwise starves such a student."""
    import socket

    if sys.platform.startswith("linux"):
        try:
            sock.setsockopt(socket.IPPROTO_TCP, _THIN_LINEAR_TIMEOUTS, 1)
        except OSError:
            pass
