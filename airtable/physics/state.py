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
- the contact stage's warm start (last step's impulses, by contact) and the
  rounds it solves in, when the table has that stage (CONTACT_KEPT);
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
import sys
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
        "_contacts",
        "notices",
        "_noticed",
        "_collision_records",
        "_last_collisions",
    }
)
PLAIN_TYPES = (bool, int, float, str, type(None))
# What the contact stage keeps from step to step: its impulses by contact (the warm start), and
# the rounds it solves in, kept while the contacts stay the same (their order depends on where
# the pucks were when they were formed, so they change results). The stage replaces these
# arrays each step and never changes them in place, so a state keeps references.
CONTACT_KEPT = (
    "_keys", "_impulses", "_rows", "_round_keys", "_round_sleepers", "_key_order", "_rounds", "_free_rounds",
    "count", "iterations",
)  # fmt: skip
# Worked out afresh at the start of every contact stage: nothing to keep.
ROUND_LISTS = (CONTACT_KEPT.index("_rounds"), CONTACT_KEPT.index("_free_rounds"))  # lists of arrays, kept as tuples
CONTACT_SCRATCH = frozenset({"_y", "_r_mean", "_warm"})  # worked out afresh in each solve
# Worked out from kept values and used only while those are the very same objects (restored
# ones are other objects): they change no result, so a state need not keep them.
CONTACT_CACHE = frozenset({"_layouts", "_wall_rest"})
# The Python objects of one state beside its arrays' data (the state, its dicts and tuples,
# the arrays' headers): tracemalloc measures 1.0 to 1.2 kB, with or without springs.
STATE_OVERHEAD_BYTES = 1600
# A numpy array's own object beside its data (sys.getsizeof of an empty array).
ARRAY_HEADER_BYTES = 112


@dataclass(frozen=True, eq=False)
class TableState:
    """One moment of a table: see the module docstring. Build with `capture`, use with `restore`."""

    pucks: dict[str, np.ndarray]  # column name -> (N, ...) array
    springs: dict[str, np.ndarray]  # column name -> (S, ...) array
    puck_handles: tuple
    spring_handles: tuple
    names: tuple[str, ...]  # the table's plain settings and counters ...
    values: tuple  # ... and their values
    events: tuple  # the scheduled (t_s, seq, fn), in heap order
    next_event_seq: int
    neighbours: tuple[np.ndarray, np.ndarray] | None  # positions and radii of the neighbour list's build
    contacts: tuple | None  # the contact stage's CONTACT_KEPT values
    notices: tuple[str, ...]
    noticed: frozenset

    @property
    def time_s(self) -> float:
        return self.values[self.names.index("time_s")]

    @property
    def steps(self) -> int:
        return self.values[self.names.index("steps")]

    def parts(self) -> Iterator[tuple[object, int]]:
        """(object, bytes) of every sizeable part: the arrays and the handle tuples (some may be shared)."""
        for a in (*self.pucks.values(), *self.springs.values(), *(self.neighbours or ()), *_contact_arrays(self)):
            yield a, a.nbytes + ARRAY_HEADER_BYTES
        tuples = (self.puck_handles, self.spring_handles)
        if self.contacts is not None:
            tuples += (self.contacts, self.contacts[CONTACT_KEPT.index("_rounds")])
        for t in tuples:
            yield t, sys.getsizeof(t)

    @property
    def nbytes(self) -> int:
        """Bytes this state holds: its distinct parts and its small Python objects."""
        return own_nbytes(self)


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
    return (
        new.pucks is old.pucks
        and new.springs is old.springs
        and new.puck_handles is old.puck_handles
        and new.spring_handles is old.spring_handles
        and new.values == old.values
        and new.events == old.events
        and new.next_event_seq == old.next_event_seq
        and new.neighbours is old.neighbours
        and new.contacts is old.contacts
        and new.notices == old.notices
    )


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
    """Every column's live rows, frozen; `like` itself if every one of them is shared with it."""
    out = {name: _frozen(columns.view(name), (like or {}).get(name)) for name in columns._data}
    if like is not None and out.keys() == like.keys() and all(out[k] is like[k] for k in out):
        return like
    return out


def _shared(new: tuple, old: tuple | None) -> tuple:
    """`old` if it holds the same items as `new` (a tuple kept once for many states)."""
    return old if old is not None and old == new else new


def _plain_values(table: AirTable) -> tuple[tuple[str, ...], tuple]:
    """The names and values of the table's plain attributes: its settings, counters and thresholds."""
    names, values = [], []
    for name, value in vars(table).items():
        if name in HANDLED:
            continue
        if not isinstance(value, PLAIN_TYPES):
            raise TypeError(
                f"AirTable.{name} is a {type(value).__name__}: airtable/physics/state.py must learn to capture it"
            )
        names.append(name)
        values.append(value)
    return tuple(names), tuple(values)


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
    radius = table._neighbours._built_radius
    radius = pucks["radius"] if same_bits(radius, pucks["radius"]) else _frozen(radius, None)
    if old is not None and old[1] is radius and same_bits(built, old[0]):
        return old
    return _frozen(built, None if old is None else old[0]), radius


def _contact_state(table: AirTable, like: TableState | None) -> tuple | None:
    """The contact stage's warm start and rounds (references: see CONTACT_KEPT); like's tuple if the same."""
    solver = getattr(table, "_contacts", None)
    if solver is None:
        return None
    unknown = set(vars(solver)) - set(CONTACT_KEPT) - CONTACT_SCRATCH - CONTACT_CACHE
    if unknown:
        raise TypeError(
            f"the contact stage keeps {sorted(unknown)}: airtable/physics/state.py must learn to capture it"
        )
    kept = [getattr(solver, name) for name in CONTACT_KEPT]
    for k in ROUND_LISTS:
        kept[k] = tuple(kept[k])  # the list of rounds, as it is now
    old = like.contacts if like is not None else None
    if old is None:
        return tuple(kept)
    same = [_same_part(a, b) for a, b in zip(kept, old, strict=True)]
    if all(same):
        return old
    for k in ROUND_LISTS:
        if same[k]:
            kept[k] = old[k]  # the same rounds: one tuple for both
    return tuple(kept)


def _same_part(a, b) -> bool:
    """Arrays and tuples of arrays are the same only if they are the same objects; plain values if equal."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return a is b
    if isinstance(a, tuple):
        return isinstance(b, tuple) and len(a) == len(b) and all(x is y for x, y in zip(a, b, strict=True))
    return a == b


def _contact_arrays(state: TableState) -> tuple:
    """The contact stage's arrays in `state` (for counting bytes)."""
    if state.contacts is None:
        return ()
    kept = dict(zip(CONTACT_KEPT, state.contacts, strict=True))
    round_keys = () if kept["_round_keys"] is None else (kept["_round_keys"], kept["_key_order"])
    if kept["_round_sleepers"] is not None:
        round_keys += (kept["_round_sleepers"],)
    return (kept["_keys"], kept["_impulses"], *round_keys, *kept["_rounds"], *kept["_free_rounds"])


def _restore_contacts(table: AirTable, kept: tuple | None) -> None:
    solver = getattr(table, "_contacts", None)
    if solver is None or kept is None:
        return
    for name, value in zip(CONTACT_KEPT, kept, strict=True):
        setattr(solver, name, list(value) if name in ("_rounds", "_free_rounds") else value)


def capture(table: AirTable, like: TableState | None = None) -> TableState:
    """Everything the next step of `table` depends on, copied out; parts equal to `like`'s are shared with it."""
    pucks = _columns(table._pucks, like.pucks if like is not None else None)
    names, values = _plain_values(table)
    return TableState(
        pucks=pucks,
        springs=_columns(table._springs, like.springs if like is not None else None),
        puck_handles=_shared(tuple(table._puck_handles), like.puck_handles if like is not None else None),
        spring_handles=_shared(tuple(table._spring_handles), like.spring_handles if like is not None else None),
        names=_shared(names, like.names if like is not None else None),
        values=values,
        events=tuple(table._events),
        next_event_seq=_next_event_seq(table),
        neighbours=_neighbour_build(table, pucks, like),
        contacts=_contact_state(table, like),
        notices=_shared(tuple(table.notices), like.notices if like is not None else None),
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
    for name, value in zip(state.names, state.values, strict=True):
        setattr(table, name, value)
    table._events = list(state.events)
    table._event_seq = itertools.count(state.next_event_seq)
    table.notices = list(state.notices)
    table._noticed = set(state.noticed)
    table._collision_records, table._last_collisions = [], None
    _restore_neighbours(table, state.neighbours)
    _restore_contacts(table, state.contacts)


def _restore_neighbours(table: AirTable, build) -> None:
    nl = table._neighbours
    builds = nl.builds
    if build is None:
        nl._built_pos = None
    else:
        nl._build(*build)  # the same positions and radii give the same list
    nl.builds = builds
