"""Storage: what a table holds between steps, and the setters that say what changed.

`AirTable` (table.py) is this storage plus the API (handles, adding and
removing, queries); the step (step.py) reads and writes it stage by stage.
Kept here:
- the columns, one row per puck and per spring (columns.py);
- the settings (gravity, restitutions, corrections, size) and the counters;
- the parts that carry something from one step to the next: the neighbour
  list (broadphase.py), the contacts' warm start (contacts.py), the timed
  events (Schedule) and the notices already given (Notices).

Setters mark what they change, as Box2D's b2Body_SetLinearVelocity wakes the
body: a change of gravity, size, correction, the pucks or the springs sets
`changed`, and the step's first stage wakes every sleeper (sleep.py). A
puck's own setters (bodies.py) mark its row in the `touched` column.

Each stateful part saves and restores its own state (`save(like)`,
`restore(saved)`); state.py asks each of them (PARTS) and keeps the plain
settings, counters and marks (`save_settings`).
"""

from __future__ import annotations

import heapq
import itertools
import math
import operator
from collections.abc import Callable

import numpy as np

from airtable.physics import broadphase, contacts, forces, vectors
from airtable.physics.collision import CORRECTION_MODES
from airtable.physics.columns import Columns

# The table's size unless told otherwise: 10 m across, 8:7 like the window.
TABLE_WIDTH_M = 10.0
TABLE_HEIGHT_M = 8.7556
PLAIN_TYPES = (bool, int, float, str, type(None))


def positive(value, what: str) -> float:
    v = float(value)
    if not (math.isfinite(v) and v > 0.0):
        raise ValueError(f"{what} must be a positive number, not {value!r}")
    return v


def non_negative(value, what: str) -> float:
    v = float(value)
    if not (math.isfinite(v) and v >= 0.0):
        raise ValueError(f"{what} must be zero or a positive number, not {value!r}")
    return v


def restitution(value, what: str) -> float:
    v = float(value)
    if not 0.0 <= v <= 1.0:  # (False for NaN: it failed deep in the first hit, a user test)
        raise ValueError(f"{what} must be a number from 0 (no bounce) to 1 (elastic), not {value!r}")
    return v


def finite(value, what: str) -> float:
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{what} must be a finite number, not {value!r}")
    return v


def _correction_mode(mode: str) -> str:
    if mode not in CORRECTION_MODES:
        raise ValueError(f"puck_correction must be one of {', '.join(CORRECTION_MODES)}, not {mode!r}")
    return mode


def _marking(name: str, check: Callable | None = None, marks: bool = True) -> property:
    """A setting whose setter checks it and marks the table `changed` (sleepers depend on it: sleep.py;
    `marks` False: nothing sleeping does); kept in `_name`."""
    private = "_" + name

    def set_(self, value) -> None:
        setattr(self, private, value if check is None else check(value))
        if marks:
            self.changed = True

    return property(operator.attrgetter(private), set_)  # (attrgetter: the step reads these often)


def _puck_view(name: str, doc: str) -> property:
    """A property: the live rows of one puck column (a view: writes go to the table)."""
    return property(lambda self: self.puck_columns.view(name), doc=doc)


def _spring_view(name: str, doc: str) -> property:
    """A property: the live rows of one spring column (a view: writes go to the table)."""
    return property(lambda self: self.spring_columns.view(name), doc=doc)


class Notices(list):
    """Sentences for the user (a list of str), each said once (`say`, by key) until cleared."""

    def __init__(self) -> None:
        super().__init__()
        self._said: set = set()

    def say(self, key, sentence: str) -> None:
        if key not in self._said:
            self._said.add(key)
            self.append(sentence)

    def clear(self) -> None:
        super().clear()
        self._said = set()

    def save(self, like: tuple | None = None) -> tuple[tuple[str, ...], frozenset]:
        saved = (tuple(self), frozenset(self._said))
        return like if like == saved else saved

    def restore(self, saved: tuple[tuple[str, ...], frozenset]) -> None:
        self[:] = saved[0]
        self._said = set(saved[1])


class Schedule:
    """Timed events (a demo's throw): fn(table) at a simulation time, earliest first; ties in the
    order they were scheduled."""

    def __init__(self) -> None:
        self._heap: list[tuple[float, int, Callable]] = []
        self._seq = itertools.count()

    def add(self, t_s: float, fn: Callable) -> None:
        heapq.heappush(self._heap, (t_s, next(self._seq), fn))

    def pop_due(self, time_s: float) -> Callable | None:
        """The earliest event due at time_s (taken off the schedule), or None."""
        if self._heap and self._heap[0][0] <= time_s + 1e-9:
            return heapq.heappop(self._heap)[2]
        return None

    def next_s(self) -> float:
        """When the earliest event is due (inf: none is)."""
        return self._heap[0][0] if self._heap else math.inf

    def clear(self) -> None:
        self._heap = []

    def save(self, like: tuple | None = None) -> tuple[tuple, int]:
        """The events (the demo's own functions, by reference) and the number the next one gets."""
        n = next(self._seq)  # reading a count uses it: start it again there
        self._seq = itertools.count(n)
        saved = (tuple(self._heap), n)
        return like if like == saved else saved

    def restore(self, saved: tuple[tuple, int]) -> None:
        self._heap = list(saved[0])
        self._seq = itertools.count(saved[1])


class Storage:
    """The columns, settings, counters and kept parts of a table with walls at x = 0..width_m, y = 0..height_m."""

    # Pucks at rest under gravity fall asleep (sleep.py); set False on a table to compare.
    sleeping = True

    def __init__(self, width_m: float = TABLE_WIDTH_M, height_m: float = TABLE_HEIGHT_M) -> None:
        self.puck_columns = Columns(
            pos=((2,), float),
            vel=((2,), float),
            force=((2,), float),
            radius=((), float),
            mass=((), float),
            color=((3,), np.uint8),
            still=((), float),  # seconds the puck has been slower than sleep.SLEEP_MPS
            asleep=((), bool),
            rest_pos=((2,), float),  # where the puck sleeps, or where its still time began (sleep.py)
            touched=((), bool),  # set by the puck's setters since the last step (bodies.py): it wakes
        )
        self.spring_columns = Columns(
            i=((), np.intp),
            j=((), np.intp),
            length=((), float),
            k=((), float),
            damper=((), float),
            width=((), float),
            color=((3,), np.uint8),
        )
        self.neighbour_list = broadphase.NeighbourList()
        self.contact_solver = contacts.ContactSolver()
        self.timed = Schedule()
        self.notices = Notices()
        self.width_m = width_m
        self.height_m = height_m
        self.reset_settings()

    def reset_settings(self) -> None:
        """Back to the defaults every demo starts from."""
        self.gravity_on = False
        self.gravity_mps2 = forces.GRAVITY_MPS2  # the strength of gravity while it is on (Earth's unless changed)
        self.cr_puck = 1.0
        self.cr_wall = 1.0
        self.wall_correction = True
        self.puck_correction = "perfect-kiss"  # the accurate mode; two-step is taught in demo 2p
        self.puck_collisions = True
        # Contacts approaching slower than this (m/s) are resting: held up by
        # the contact stage, with no bounce. Where forces press a puck, its
        # contacts along the press also rest below PRESSED_REST_MPS and twice
        # what the step's forces add to its speed (2 g dt under gravity; see
        # rest_speeds.py).
        self.rest_speed_mps = 0.0

    def clear_storage(self) -> None:
        """No pucks, springs, events or notices; time and the counters start again at 0."""
        self.puck_columns.clear()
        self.spring_columns.clear()
        self.timed.clear()
        self.notices.clear()
        self.contact_solver.forget()
        self.spring_dt_s = 1 / 240  # the dt the springs' effective stiffness was last worked out for
        self.time_s = 0.0
        self.steps = 0
        self.collision_count = 0  # puck-puck collisions since the start
        self.wall_collision_count = 0  # bounces off a wall since the start
        self.changed = True  # a setting, the pucks or the springs changed since the last step (sleep.wake)
        self.any_touched = False  # some puck was set through its handle since the last step (touch)
        self.quiet = None  # the table as a step that changed nothing left it (quiet.py), or None

    # ------------------------------------------------------------ settings that wake every sleeper

    gravity_on = _marking("gravity_on")
    gravity_mps2 = _marking("gravity_mps2", lambda v: finite(v, "gravity_mps2"))  # (below 0: falls upward)
    width_m = _marking("width_m", lambda v: positive(v, "width_m"))
    height_m = _marking("height_m", lambda v: positive(v, "height_m"))
    puck_correction = _marking("puck_correction", _correction_mode)
    puck_collisions = _marking("puck_collisions")
    # Checked, not marking: a bounce's restitution or the rest speed changes nothing for a sleeper.
    cr_puck = _marking("cr_puck", lambda v: restitution(v, "cr_puck"), marks=False)
    cr_wall = _marking("cr_wall", lambda v: restitution(v, "cr_wall"), marks=False)
    rest_speed_mps = _marking("rest_speed_mps", lambda v: non_negative(v, "rest_speed_mps"), marks=False)

    @property
    def size_m(self) -> np.ndarray:
        return np.array([self.width_m, self.height_m])

    # ------------------------------------------------------------ the columns

    @property
    def n_pucks(self) -> int:
        return self.puck_columns.n

    @property
    def n_springs(self) -> int:
        return self.spring_columns.n

    pos_m = _puck_view("pos", "(N, 2) positions, a live view (rows in creation order).")
    vel_mps = _puck_view("vel", "(N, 2) velocities, a live view.")
    force_N = _puck_view("force", "(N, 2) force accumulators: add to them before `step` to push pucks.")
    radius_m = _puck_view("radius", "(N,) radii, a live view (set one through its Puck to wake sleepers).")
    mass_kg = _puck_view("mass", "(N,) masses, a live view.")
    color_rgb = _puck_view("color", "(N, 3) colours, a live view.")
    spring_length_m = _spring_view("length", "(S,) relaxed lengths, a live view.")
    spring_k_Npm = _spring_view("k", "(S,) stiffnesses asked for, a live view.")
    spring_damper_Nspm = _spring_view("damper", "(S,) dampers, a live view.")
    spring_width_m = _spring_view("width", "(S,) drawn widths, a live view.")
    spring_color_rgb = _spring_view("color", "(S, 3) colours, a live view.")

    @property
    def spring_ends(self) -> tuple[np.ndarray, np.ndarray]:
        """(S,) rows of each spring's p1 and (S,) rows of its p2 (live views)."""
        return self.spring_columns.view("i"), self.spring_columns.view("j")

    def spring_stretch_m(self) -> np.ndarray:
        """(S,) how far each spring is longer than its relaxed length now (negative: compressed)."""
        a, b = self.spring_ends
        return vectors.lengths(vectors.take(self.pos_m, a) - vectors.take(self.pos_m, b)) - self.spring_length_m

    @property
    def spring_k_effective_Npm(self) -> np.ndarray:
        """(S,) the stiffness each spring acts with at the last step's dt (or 1/240 s before any step).

        It is the k asked for, unless that is beyond what a step can compute
        (forces.SOFTENING_LIMIT); then the spring is softened to this, and
        `notices` says so.
        """
        return self._effective_springs()[0]

    @property
    def spring_damper_effective_Nspm(self) -> np.ndarray:
        """(S,) the damper each spring acts with (as spring_k_effective_Npm)."""
        return self._effective_springs()[1]

    def _effective_springs(self) -> tuple[np.ndarray, np.ndarray]:
        mu = forces.reduced_masses(self.mass_kg, *self.spring_ends)
        return forces.effective_spring(self.spring_k_Npm, self.spring_damper_Nspm, mu, self.spring_dt_s)

    # ------------------------------------------------------------ marks and timed events

    def run_due_events(self) -> None:
        """Run the scheduled events whose time has come, in time order (the step's first stage)."""
        while (fn := self.timed.pop_due(self.time_s)) is not None:
            fn(self)

    def touch(self, row: int) -> None:
        """Mark a puck set through its handle: if it sleeps, it wakes at the next step."""
        self.puck_columns.view("touched")[row] = True
        self.any_touched = True  # some row is: the wake stage looks at the column only then

    # ------------------------------------------------------------ saving (state.py)

    # The parts that save and restore their own state (`save(like)`, `restore(saved)`; state.py).
    PARTS = ("puck_columns", "spring_columns", "neighbour_list", "contact_solver", "timed", "notices")
    # Attributes that are neither parts nor settings (AirTable's: what the last step did, not kept; `quiet`, a
    # memo the step checks against the table before it trusts it).
    NOT_SAVED: tuple[str, ...] = ("quiet",)

    def save_settings(self) -> tuple[tuple[str, ...], tuple]:
        """The names and values of the plain attributes: settings, counters and marks (taken by type, so a
        setting added later is saved without a change here)."""
        names, values = [], []
        for name, value in vars(self).items():
            if name in self.PARTS or name in self.NOT_SAVED:
                continue
            if not isinstance(value, PLAIN_TYPES):
                raise TypeError(f"AirTable.{name} is a {type(value).__name__}: save it as a part (storage.py)")
            names.append(name)
            values.append(value)
        return tuple(names), tuple(values)

    def restore_settings(self, names: tuple[str, ...], values: tuple) -> None:
        """Set the attributes save_settings gave (their stored values: no setter marks anything)."""
        for name, value in zip(names, values, strict=True):
            setattr(self, name, value)
