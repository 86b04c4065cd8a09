"""Fair sending when the link is too slow for every snapshot to reach everyone.

Left alone, a server on a tight link hands each socket as much as the kernel
takes; the TCP connections then fight over the link, and the ones that lose a
few packets back off for hundreds of milliseconds at a time: some students get
everything and some nothing. The remedy is per-student pacing:

- a student gets a new snapshot only while the bytes it has not yet
  acknowledged are fewer than the snapshots the rate needs in one round trip
  (the bandwidth-delay product of the snapshot stream: round trip / period
  snapshots; one on a LAN, as before), so the rate is set by the snapshot rate and the link's
  bandwidth, never by the round trip (a cap of two unacknowledged snapshots
  gave 17 a second at 50 ms one-way, 9.6 at 100 and 3.2 at 300);
- once the link queues (the smoothed round trip is well above the lowest
  seen: a full hotspot, a slow reader), only what the lowest round trip needs
  may be in flight (on a LAN: a new snapshot only once the previous one is
  acknowledged), so the queue drains and every student's rate drops evenly;
- when a snapshot is ready, the students are served in round-robin order,
  so nobody is always first;
- a student that was skipped simply gets the next snapshot, coded against
  what it last received (see codec.py).

Each student then has one snapshot in flight when the link is full, and since
they all wait in the same queue at the bottleneck, they all get the same rate:
every rate drops evenly. (Measured in a namespace held to 10 Mbit/s with
2.7 KB snapshots: every one of 30 students got 11.4-12.2 a second; without
pacing the median was 0.4, several got none and a few got 30.) Where the kernel cannot say how
much is unacknowledged (not Linux), pacing falls back to "previous snapshot
written".
"""

from __future__ import annotations

import math
import struct
from collections.abc import Sequence
from typing import TypeVar

try:
    import fcntl
    import termios

    _OUTQ = termios.TIOCOUTQ  # Linux: bytes written but not yet acknowledged by the peer
except (ImportError, AttributeError):  # Windows, or a platform without the request
    fcntl = None
    _OUTQ = None

SIZE_MARGIN = 1.25  # delta-coded snapshots vary in size: count each as this much of the typical one
MAX_IN_FLIGHT = 40  # snapshots unacknowledged at most (30 a second for 1.3 s of round trip)
# The link is queueing when the smoothed round trip exceeds the lowest seen by this much.
QUEUEING_FACTOR = 2.0
QUEUEING_EXTRA_S = 0.03
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


def round_trip_s(sock) -> tuple[float, float] | None:
    """(smoothed, lowest) round-trip time of a TCP socket in seconds (Linux), else None."""
    if _OUTQ is None:
        return None
    import socket

    try:
        info = sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_INFO, 152)
    except (OSError, AttributeError):
        return None
    if len(info) < 152:
        return None
    smoothed_us, lowest_us = struct.unpack_from("I", info, 68)[0], struct.unpack_from("I", info, 148)[0]
    return smoothed_us / 1e6, lowest_us / 1e6


SLOW_LINK_RTT_S = 0.15  # a round trip longer than this is a slow link (Wi-Fi under load, a hotspot)


def link_is_slow(sock) -> bool | None:
    """Whether a TCP connection is on a slow link: a long round trip, or bytes written and not yet
    acknowledged (lost and being sent again). None where the kernel cannot tell (not Linux)."""
    queued, rtt = queued_bytes(sock), round_trip_s(sock)
    if queued is None or rtt is None:
        return None
    return queued > 0 or rtt[0] > SLOW_LINK_RTT_S


def may_send(sock, snapshot_bytes: int, period_s: float = 1 / 30, rtt: tuple[float, float] | None = None) -> bool:
    """Whether this student may be handed a new snapshot now, when snapshots of about `snapshot_bytes`
    come every `period_s` (`rtt`: a recent round_trip_s reading, else it is read now):
    nothing is unacknowledged, or the link is not queueing and fewer bytes are in flight than the
    rate needs over one round trip (see `in_flight_budget`)."""
    queued = queued_bytes(sock)
    if not queued:  # nothing unacknowledged, or the platform cannot tell
        return True
    rtt = rtt or round_trip_s(sock)  # the caller may pass a recent reading: this is asked every few ms
    if rtt is None:
        return False
    return queued <= in_flight_budget(rtt[0], rtt[1], snapshot_bytes, period_s)


def in_flight_budget(smoothed_s: float, lowest_s: float, snapshot_bytes: int, period_s: float) -> int:
    """Unacknowledged bytes a student may have and still be handed a snapshot.

    A snapshot is acknowledged a round trip after it leaves, so to get one every `period_s`,
    round trip / period of them must be in flight besides the one about to go: that many (at most
    MAX_IN_FLIGHT) of SIZE_MARGIN x `snapshot_bytes` each. On a LAN that is one, as it always was,
    so a tight link (a hotspot) fills no faster than before. Once the link queues (the smoothed
    round trip is above QUEUEING_FACTOR times the lowest plus QUEUEING_EXTRA_S), only what the
    lowest round trip needs, less the snapshot about to go: on a LAN nothing (the next one waits
    for every byte to be acknowledged), on a long link its bandwidth-delay product, so the rate
    falls with the queue, evenly for everyone behind it, and not with the length of the link."""
    period_s, size = max(period_s, 1e-3), SIZE_MARGIN * max(0, snapshot_bytes)
    if smoothed_s > QUEUEING_FACTOR * lowest_s + QUEUEING_EXTRA_S:
        return round(max(0, min(MAX_IN_FLIGHT, math.ceil(lowest_s / period_s)) - 1) * size)
    return round(min(MAX_IN_FLIGHT, math.ceil(smoothed_s / period_s)) * size)


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
