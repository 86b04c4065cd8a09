"""A seat at the table as the teacher's roster shows it (the server fills it, the app draws it)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Seat:
    """One player in the roster: who, and how their connection is doing."""

    number: int  # n of "Cn"
    name: str  # as shown on the table, e.g. "C3 Ann"
    color: tuple[int, int, int]
    address: str
    snapshots_per_s: float  # snapshots that went out whole, over the last 2 s
    lag_s: float  # how long a snapshot waits at the server before it is out (smoothed)
    idle_s: float  # since the player's input last changed
    far_off: bool  # the cursor is more than a table size beyond the table's edge
