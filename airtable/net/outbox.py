"""The player's outgoing frames, sent without ever waiting and without ever giving up on TCP.

A socket with a timeout applies it to sendall too: once a cut link had filled the send buffer,
the student's window froze for the timeout and the client dropped a connection that TCP would
have carried on after the cut. So frames go out with send() only when the socket says it has
room (select with no wait); the rest waits here and goes at the next call. Only the newest
cursor matters, so a newer INPUT replaces an older one that has not started going out, and
what waits is bounded.
"""

from __future__ import annotations

import select
import socket
from collections import deque

MAX_WAITING = 32  # frames kept while the link is stalled; beyond that the oldest goes


class Outbox:
    """Frames waiting for one socket; used under the caller's lock."""

    def __init__(self) -> None:
        self._current: memoryview | None = None  # the frame part-sent: it must finish first
        self._waiting: deque[tuple[bool, bytes]] = deque()  # (replaceable, frame)

    @property
    def empty(self) -> bool:
        return self._current is None and not self._waiting

    def put(self, frame: bytes, replaceable: bool = False) -> None:
        """Queue `frame`; a `replaceable` one (an INPUT) drops the replaceable ones still waiting."""
        if replaceable:
            self._waiting = deque(item for item in self._waiting if not item[0])
        self._waiting.append((replaceable, frame))
        while len(self._waiting) > MAX_WAITING:
            self._waiting.popleft()

    def flush(self, sock: socket.socket) -> None:
        """Send what the socket takes now, never waiting; raises OSError when the connection broke."""
        for _ in range(MAX_WAITING + 2):  # bounded: each pass finishes a frame or stops
            if self._current is None:
                if not self._waiting:
                    return
                self._current = memoryview(self._waiting.popleft()[1])
            if not select.select([], [sock], [], 0)[1]:
                return  # full: the rest goes at the next call
            try:
                sent = sock.send(self._current)
            except (BlockingIOError, InterruptedError, TimeoutError):
                return
            self._current = self._current[sent:] if sent < len(self._current) else None
            if self._current is not None:
                return
