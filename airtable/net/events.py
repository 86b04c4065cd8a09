"""What the network thread tells the game loop: typed, immutable event records.

The server's network thread never touches the table or the loop's list of
clients. It turns what players do into these records and queues them in an
`EventQueue`; the game loop takes them every frame (even while paused) in
`GameServer.update_clients` and applies them to its own list of Clients.

The queue stays bounded whatever the players do and however long the loop
does not look: a join that leaves again before the loop saw it cancels out,
and each player keeps only a few input records (see `EventQueue.input`).
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

from airtable.net.protocol import InputRecord

# Input records kept per player between two frames: the newest, plus the first
# record after each button change, so a quick click between frames is not lost.
MAX_QUEUED_INPUTS = 6


@dataclass(frozen=True)
class PlayerJoined:
    """Player `cid` was welcomed as `name` with `color`: add a Client for it."""

    cid: int
    name: str
    color: tuple[int, int, int]
    number: int = 0  # n of "Cn" (the teacher's floor and hands-off rules go by it)


@dataclass(frozen=True)
class PlayerLeft:
    """Player `cid` is gone (BYE, hung up, dropped or removed): let go of its puck."""

    cid: int


@dataclass(frozen=True)
class PlayerInput:
    """Player `cid`'s cursor, button and keys, already validated."""

    cid: int
    record: InputRecord


Event = PlayerJoined | PlayerLeft | PlayerInput


class EventQueue:
    """Events from the network thread to the game loop; safe to use from both.

    `take()` returns joins and leaves in the order they happened, then each
    player's queued inputs. Its size is bounded by the number of players.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._members: list[PlayerJoined | PlayerLeft] = []
        self._inputs: dict[int, list[InputRecord]] = {}

    def __len__(self) -> int:
        """Records waiting for the game loop."""
        with self._lock:
            return len(self._members) + sum(len(q) for q in self._inputs.values())

    def join(self, cid: int, name: str, color: tuple[int, int, int], number: int = 0) -> None:
        with self._lock:
            self._members.append(PlayerJoined(cid, name, color, number))

    def leave(self, cid: int) -> None:
        """Queue a leave; a join the loop has not seen yet is simply withdrawn."""
        with self._lock:
            self._inputs.pop(cid, None)
            for i, event in enumerate(self._members):
                if isinstance(event, PlayerJoined) and event.cid == cid:
                    del self._members[i]
                    return
            self._members.append(PlayerLeft(cid))

    def input(self, cid: int, record: InputRecord) -> None:
        """Keep the newest record, plus the first record after each button change.

        Motion between two frames collapses into the newest position, but a
        press (and where it happened) survives even when the press and the
        next move arrive within one frame, so a quick grab is not lost.
        """
        with self._lock:
            queue = self._inputs.setdefault(cid, [])
            if len(queue) >= 2 and queue[-1].button == queue[-2].button == record.button:
                queue[-1] = record  # same run of one button: only its first and newest matter
                return
            queue.append(record)
            if len(queue) > MAX_QUEUED_INPUTS:
                del queue[0]

    def take(self) -> list[Event]:
        """Everything queued, oldest first; the queue is empty afterwards."""
        with self._lock:
            members, self._members = self._members, []
            inputs, self._inputs = self._inputs, {}
        events: list[Event] = list(members)
        for cid, records in inputs.items():
            events.extend(PlayerInput(cid, record) for record in records)
        return events
