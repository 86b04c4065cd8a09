"""The whole state of a table at one moment, captured and restored exactly (no pygame).

`capture(table)` copies out everything the next step depends on, as compact
numpy arrays and plain values; `restore(table, state)` puts it back. Stepping
a restored table with the same pulls then gives bit-for-bit the same
positions and velocities as the first time: this is what rewinding stands on.

What a state holds, and why each part is needed:
- every column of the pucks and springs (positions, velocities, force
  accumulators, radii, masses, colours; spring ends and parameters);
- the Puck and Spring handles themselves, in row order: a demo's code keeps
  handles (the cradle's timed throw says `cue.vel_mps = ...`), so a restored
  table must give the same handle objects their rows back, and mark the
  handles made later as removed;
- every plain setting and counter of the table (gravity, restitutions,
  correction mode, time, step and collision counts, the dt the springs were
  last worked out for, any threshold), taken from the table's attributes by
  type, so a setting added later is captured without a change here;
- the scheduled events, with the demo's own functions (they are its code,
  kept by reference) and the counter that orders events due at one time;
- the neighbour list's last build: which pairs the step looks at depends on
  where the pucks were when the list was built, and a stale list can miss a
  pair a correction pushed into overlap where a fresh one would see it;
  rebuilding from the same positions gives the same list again;
- the notices already given (so each is still said once).

Not kept: what the last step's collisions were (`last_collisions`, for the
diagrams); a restored table reports none until it steps.

Arrays in a state are read-only. `capture(table, like=older)` shares every
array whose bits equal the older state's (masses, radii, springs and colours
rarely change; a still table's positions do not either), so a history of
states costs little more than the positions and velocities that changed.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from airtable.physics.table import AirTable

# The table's attributes a state handles one by one (the rest are plain values, see _plain_values).
HANDLED = frozenset(
    {
        "_pucks",
        "_springs",
        "_puck_handles",
        "_spring_handles",
        "_events",
        "_event_seq",
        "_neighbours",
        "notices",
        "_noticed",
        "_collision_records",
        "_last_collisions",
    }
)
PLAIN_TYPES = (bool, int, float, str, type(None))
# The Python objects of one state beside its arrays' data (the state, its dicts and tuples,
# the arrays' headers), as tracemalloc measures them for a table of pucks and springs.
STATE_OVERHEAD_BYTES = 3000


@dataclass(frozen=True, eq=False)
class TableState:
    """One moment of a table: see the module docstring. Build with `capture`, use with `restore`."""

    pucks: dict[str, np.ndarray]  # column name -> (N, ...) array
    springs: dict[str, np.ndarray]  # column name -> (S, ...) array
    puck_handles: tuple
    spring_handles: tuple
    values: tuple[tuple[str, object], ...]  # (attribute, value) of every plain setting and counter
    events: tuple  # the scheduled (t_s, seq, fn), in heap order
    next_event_seq: int
    neighbours: tuple[np.ndarray, np.ndarray] | None  # positions and radii of the neighbour list's build
    notices: tuple[str, ...]
    noticed: frozenset

    @property
    def time_s(self) -> float:
        return dict(self.values)["time_s"]

    @property
    def steps(self) -> int:
        return dict(self.values)["steps"]

    def arrays(self) -> Iterator[np.ndarray]:
        """Every array the state holds (one shared with another state included)."""
        yield from self.pucks.values()
        yield from self.springs.values()
        if self.neighbours is not None:
            yield from self.neighbours

    @property
    def nbytes(self) -> int:
        """Bytes this state holds on its own: its distinct arrays' data and its Python objects."""
        return distinct_nbytes(self.arrays()) + STATE_OVERHEAD_BYTES


def distinct_nbytes(arrays, skip: set[int] | None = None) -> int:
    """Sum of nbytes over the distinct arrays (by identity), leaving out those whose id is in `skip`."""
    seen = set(skip or ())
    total = 0
    for a in arrays:
        if id(a) not in seen:
            seen.add(id(a))
            total += a.nbytes
    return total


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    """True if a and b hold the very same bits (so -0.0 differs from 0.0, and a NaN equals itself)."""
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    if a.dtype.kind in "fc":
        return bool(np.array_equal(a.view(f"u{a.dtype.itemsize}"), b.view(f"u{b.dtype.itemsize}")))
    return bool(np.array_equal(a, b))


def _frozen(a: np.ndarray, like: np.ndarray | None) -> np.ndarray:
    """A read-only copy of `a`, or `like` itself if it holds the same bits."""
    if like is not None and same_bits(a, like):
        return like
    out = np.array(a, copy=True)
    out.flags.writeable = False
    return out


def _columns(columns, like: dict[str, np.ndarray] | None) -> dict[str, np.ndarray]:
    like = like or {}
    return {name: _frozen(columns.view(name), like.get(name)) for name in columns._data}


def _plain_values(table: AirTable) -> tuple[tuple[str, object], ...]:
    """Every attribute of the table that is a plain value: its settings, counters and thresholds."""
    out = []
    for name, value in vars(table).items():
        if name in HANDLED:
            continue
        if not isinstance(value, PLAIN_TYPES):
            raise TypeError(
                f"AirTable.{name} is a {type(value).__name__}: airtable/physics/state.py must learn to capture it"
            )
        out.append((name, value))
    return tuple(out)


def _next_event_seq(table: AirTable) -> int:
    """The number the next scheduled event will get (reading an itertools.count uses it, so it is replaced)."""
    n = next(table._event_seq)
    table._event_seq = itertools.count(n)
    return n


def _neighbour_build(table: AirTable, pucks: dict[str, np.ndarray], like: TableState | None):
    built = getattr(table._neighbours, "_built_pos", None)
    if built is None:
        return None
    old = like.neighbours if like is not None else None
    pos = old[0] if old is not None and (old[0] is built or same_bits(built, old[0])) else _frozen(built, None)
    radius = table._neighbours._built_radius
    radius = pucks["radius"] if same_bits(radius, pucks["radius"]) else _frozen(radius, None)
    return pos, radius


def capture(table: AirTable, like: TableState | None = None) -> TableState:
    """Everything the next step of `table` depends on, copied out; arrays equal to `like`'s are shared with it."""
    pucks = _columns(table._pucks, like.pucks if like is not None else None)
    return TableState(
        pucks=pucks,
        springs=_columns(table._springs, like.springs if like is not None else None),
        puck_handles=tuple(table._puck_handles),
        spring_handles=tuple(table._spring_handles),
        values=_plain_values(table),
        events=tuple(table._events),
        next_event_seq=_next_event_seq(table),
        neighbours=_neighbour_build(table, pucks, like),
        notices=tuple(table.notices),
        noticed=frozenset(table._noticed),
    )


def _load_columns(columns, arrays: dict[str, np.ndarray]) -> None:
    """Set a table's growable columns to `arrays` (every column has one row per entry)."""
    n = len(next(iter(arrays.values())))
    if n > columns._cap:
        columns._cap = max(16, n)
        for name, (shape, dtype) in columns._specs.items():
            columns._data[name] = np.zeros((columns._cap, *shape), dtype)
    for name, a in arrays.items():
        columns._data[name][:n] = a
    if n != columns.n:
        columns.n = n
        columns._views = {}


def _give_rows(current: list, kept: tuple) -> list:
    """The handles of `kept` get their rows back (their place in it); the others are marked removed."""
    for h in current:
        h._index = None
    for row, h in enumerate(kept):
        h._index = row
    return list(kept)


def restore(table: AirTable, state: TableState) -> None:
    """Put `table` back to `state` exactly (the same handles, settings, events and caches)."""
    _load_columns(table._pucks, state.pucks)
    _load_columns(table._springs, state.springs)
    table._puck_handles = _give_rows(table._puck_handles, state.puck_handles)
    table._spring_handles = _give_rows(table._spring_handles, state.spring_handles)
    for name, value in state.values:
        setattr(table, name, value)
    table._events = list(state.events)
    table._event_seq = itertools.count(state.next_event_seq)
    table.notices = list(state.notices)
    table._noticed = set(state.noticed)
    table._collision_records, table._last_collisions = [], None
    _restore_neighbours(table, state.neighbours)


def _restore_neighbours(table: AirTable, build) -> None:
    nl = table._neighbours
    builds = nl.builds
    if build is None:
        nl._built_pos = None
    else:
        nl._build(*build)  # the same positions and radii give the same list
    nl.builds = builds
