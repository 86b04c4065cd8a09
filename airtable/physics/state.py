"""The whole state of a table at one moment, captured and restored exactly (no pygame).

`capture(table)` asks each stateful part of the table for its own state
(`part.save(like)`), and the table for its plain settings, counters and marks
(`save_settings`); `restore(table, state)` hands each part its state back
(`part.restore(saved)`). Stepping a restored table with the same pulls then
gives bit-for-bit the same positions and velocities as the first time: this
is what rewinding stands on. The parts (AirTable.PARTS), and why each is needed:
- the columns of the pucks and springs (columns.py): positions, velocities,
  force accumulators, radii, masses, colours, sleep; spring ends and parameters;
- the Puck and Spring handles themselves, in row order (bodies.py): a demo's
  code keeps handles (the cradle's timed throw says `cue.vel_mps = ...`), so a
  restored table must give the same handle objects their rows back, and mark
  the handles made later as removed;
- the timed events, with the demo's own functions (its code, kept by
  reference) and the counter that orders events due at one time (storage.py);
- the neighbour list's last build (broadphase.py): which pairs the step looks
  at depends on where the pucks were when the list was built;
- the contact solver's warm start and the rounds it solves in (contacts.py);
- the notices already given, so each is still said once (storage.py).

Not kept: what the last step's collisions were (`last_collisions`, for the
diagrams); a restored table reports none until it steps.

Arrays in a state are read-only. `capture(table, like=older)` lets each part
share what has the same bits as in the older state (masses, radii, springs and
colours rarely change; a still table's positions do not either), so a history
of states costs little more than the positions and velocities that changed.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from airtable.physics.columns import same_bits

if TYPE_CHECKING:
    from airtable.physics.table import AirTable

__all__ = ["TableState", "capture", "restore", "own_nbytes", "unchanged", "same_bits"]

# The Python objects of one state beside its arrays' data (the state, its dicts and tuples,
# the arrays' headers): tracemalloc measures 1.0 to 1.2 kB, with or without springs.
STATE_OVERHEAD_BYTES = 1600
# A numpy array's own object beside its data (sys.getsizeof of an empty array).
ARRAY_HEADER_BYTES = 112
# The parts whose save is a tuple of handle objects (bodies.Handles.save): counted as that one
# tuple, not looked into (the handles are the table's own, shared by every state; a 10000-puck
# table would cost 10000 looks per state, and the history sizes a state at every capture).
HANDLE_PARTS = frozenset({"puck_handles", "spring_handles"})


@dataclass(frozen=True, eq=False)
class TableState:
    """One moment of a table: see the module docstring. Build with `capture`, use with `restore`."""

    saved: dict[str, object]  # each part's own save(), by its name in AirTable.PARTS
    names: tuple[str, ...]  # the table's plain settings, counters and marks ...
    values: tuple  # ... and their values

    @property
    def pucks(self) -> dict[str, np.ndarray]:
        return self.saved["puck_columns"]

    @property
    def neighbours(self) -> tuple[np.ndarray, np.ndarray] | None:
        return self.saved["neighbour_list"]

    @property
    def contacts(self) -> tuple:
        return self.saved["contact_solver"]

    @property
    def time_s(self) -> float:
        return self.values[self.names.index("time_s")]

    @property
    def steps(self) -> int:
        return self.values[self.names.index("steps")]

    def parts(self) -> Iterator[tuple[object, int]]:
        """(object, bytes) of every sizeable part: the arrays, and the tuples holding arrays or
        handles (some may be shared)."""
        for name, saved in self.saved.items():
            if name in HANDLE_PARTS:
                yield saved, sys.getsizeof(saved)
            else:
                yield from _sized(saved)

    @property
    def nbytes(self) -> int:
        """Bytes this state holds: its distinct parts and its small Python objects."""
        return own_nbytes(self)


def _sized(obj) -> Iterator[tuple[object, int]]:
    """The arrays and tuples in a part's save, with their sizes, looking inside tuples and dicts."""
    if isinstance(obj, np.ndarray):
        yield obj, obj.nbytes + ARRAY_HEADER_BYTES
    elif isinstance(obj, dict):
        for value in obj.values():
            yield from _sized(value)
    elif isinstance(obj, tuple):
        yield obj, sys.getsizeof(obj)
        for value in obj:
            yield from _sized(value)


def own_nbytes(state: TableState, previous: TableState | None = None) -> int:
    """Bytes `state` adds beside `previous` (the parts it shares with it are not counted again)."""
    seen = {id(obj) for obj, _ in previous.parts()} if previous is not None else set()
    total = STATE_OVERHEAD_BYTES
    for obj, size in state.parts():
        if id(obj) not in seen:
            seen.add(id(obj))
            total += size
    return total


def unchanged(new: TableState, old: TableState) -> bool:
    """True if `new` (captured with like=old) is the same moment as `old`: nothing to keep twice."""
    return new.values == old.values and all(new.saved[k] is old.saved[k] for k in new.saved)


def capture(table: AirTable, like: TableState | None = None) -> TableState:
    """Everything the next step of `table` depends on, copied out; parts equal to `like`'s are shared with it."""
    old = like.saved if like is not None else {}
    saved = {}
    for name in table.PARTS:
        part = getattr(table, name)
        if name == "neighbour_list":  # built from the pucks' radii: shares their saved column
            saved[name] = part.save(old.get(name), radius=saved["puck_columns"]["radius"])
        else:
            saved[name] = part.save(old.get(name))
    names, values = table.save_settings()
    if like is not None and names == like.names:
        names = like.names
    return TableState(saved, names, values)


def restore(table: AirTable, state: TableState) -> None:
    """Put `table` back to `state` exactly (the same handles, settings, events and caches)."""
    for name in table.PARTS:
        getattr(table, name).restore(state.saved[name])
    table.restore_settings(state.names, state.values)
