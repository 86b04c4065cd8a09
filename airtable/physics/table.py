"""AirTable: the physics world of pucks, springs and walls (SI units, no pygame).

State is kept as a structure of arrays, one row per puck (and per spring), so
one step is a handful of numpy operations whatever the number of pucks. Puck
and Spring objects are handles onto those rows (see bodies.py).

`step(dt_s, pulls)` is the course's game loop; each stage is a method below,
and the numpy work of each is in a module of its own:
0. timed events (a demo's throw) that are due;
1. forces: pulls (cursor strings) and springs (forces.py); what a puck's
   springs have beyond what an explicit step can hold is marked implicit;
2. integrate, semi-implicit Euler: v += (F/m + g) dt, then x += v dt; the
   pulls' drag and the stiff springs' implicit parts are solved for
   (implicit.py), so springs hold at any stiffness;
3. hits in time order (events.py): every wall hit and pair hit of the step,
   found on the pucks' paths through it and resolved at the moment it
   happens, earliest first, a puck's later hits on its new path (in perfect
   kiss every pair hit; in two-step and off those of fast pucks, which the
   overlap test at the step's end could miss). Then what is still past a
   wall (walls.py: wall_correction off, or resting on it);
4. puck pairs still overlapping: the candidates from a neighbour list
   (broadphase.py), then the course's collision + position correction one
   pair at a time (pairs.py), then a second look at the pairs the
   corrections pushed into overlap;
5. resting contacts: pucks pressing on each other or on a wall, approaching
   slower than the rest speed, held up together by impulses (contacts.py);
   stages 3 and 4 leave those to this one. Only when something presses:
   gravity, springs, pulls or a rest speed set by hand;
6. walls again, since pushing pairs apart can push a puck into a wall;
7. sleeping (sleep.py): under gravity, a puck still for half a second, with
   all its touching neighbours, falls asleep: velocity exactly 0, not moved,
   its contacts with walls and other sleepers left out, immovable to the
   awake pucks resting on it. At the start of a step (0b) a sleeper wakes if
   anything touched it: a velocity, position or force written from outside,
   a pull, an awake puck coming fast within reach; everything wakes when
   gravity, the table's size, the pucks or springs or the correction mode
   change. A pile at rest then costs almost nothing and shows no jitter.
"""

from __future__ import annotations

import heapq
import itertools
import math
from collections.abc import Callable, Sequence

import numpy as np

from airtable.physics import broadphase, collision, contacts, events, forces, pairs, sleep, substeps, vectors, walls
from airtable.physics import implicit as implicit_solve
from airtable.physics.bodies import Puck, Spring, as_vector
from airtable.physics.colors import rgb
from airtable.physics.forces import GRAVITY_MPS2, Pull

# The table's size unless told otherwise: 10 m across, 8:7 like the window.
TABLE_WIDTH_M = 10.0
TABLE_HEIGHT_M = 8.7556
# After the first pass over the overlapping pairs, up to this many more passes
# over the pairs the corrections pushed into overlap: collisions again, then a
# last pass that only pushes apart.
EXTRA_PASSES = 2
# A pressed contact (one whose pucks this step's forces push: gravity, springs, pulls)
# approaching slower than this (m/s) rests instead of bouncing: the speed of a 2 mm fall.
# Without it a pile's pucks, shaken at a few cm/s by their neighbours, bounce off each
# other at restitution cr_puck and keep each other shaking; Box2D's threshold is 1 m/s.
PRESSED_REST_MPS = 0.2
# Overlaps smaller than this (m) are left to the next step: round-off only.
OVERLAP_SLOP_M = 1e-9
# Said once (in `notices`) when springs are first solved implicitly (beyond what substeps.py takes).
IMPLICIT_NOTICE = (
    f"Some springs vibrate faster than even {substeps.MAX_SUBSTEPS} substeps of a step can follow: the step"
    " solves them implicitly, so they hold and sag as their k says, but their vibrations are damped away,"
    " the fastest at once and the slow ones too, a little each period."
)
# Passes that add walls to the implicit solve (see _brace_walls).
BRACE_PASSES = 4
# A last guard against runaway values: nothing real on a table moves this fast.
MAX_SPEED_MPS = 1e8


def kinetic_energy_J(mass_kg: np.ndarray, vel_mps: np.ndarray) -> float:
    """Sum of m v^2 / 2 over the rows (einsum's row dot is five times slower here)."""
    return float(0.5 * np.dot(mass_kg, vectors.squared_lengths(vel_mps)))


def _positive(value, what: str) -> float:
    v = float(value)
    if not (math.isfinite(v) and v > 0.0):
        raise ValueError(f"{what} must be a positive number, not {value!r}")
    return v


def _non_negative(value, what: str) -> float:
    v = float(value)
    if not (math.isfinite(v) and v >= 0.0):
        raise ValueError(f"{what} must be zero or a positive number, not {value!r}")
    return v


class _Columns:
    """Growable numpy arrays sharing one row count (amortised O(1) append)."""

    def __init__(self, **specs: tuple[tuple[int, ...], type]) -> None:
        self._specs = specs
        self.n = 0
        self._cap = 0
        self._data = {name: np.zeros((0, *shape), dtype) for name, (shape, dtype) in specs.items()}
        self._views: dict[str, np.ndarray] = {}  # the live rows of each column, until the row count changes

    def view(self, name: str) -> np.ndarray:
        v = self._views.get(name)
        if v is None:
            v = self._views[name] = self._data[name][: self.n]
        return v

    def append(self, **values) -> int:
        if self.n == self._cap:
            self._cap = max(16, 2 * self._cap)
            for name, (shape, dtype) in self._specs.items():
                grown = np.zeros((self._cap, *shape), dtype)
                grown[: self.n] = self._data[name][: self.n]
                self._data[name] = grown
        row = self.n
        for name, value in values.items():
            self._data[name][row] = value
        self.n += 1
        self._views = {}
        return row

    def delete(self, rows: np.ndarray) -> np.ndarray:
        """Remove `rows`; return the old-row -> new-row map (-1 for removed)."""
        keep = np.ones(self.n, dtype=bool)
        keep[rows] = False
        remap = np.full(self.n, -1, dtype=np.intp)
        remap[keep] = np.arange(int(keep.sum()))
        for name in self._data:
            kept = self._data[name][: self.n][keep]
            self._data[name][: len(kept)] = kept
        self.n = int(keep.sum())
        self._views = {}
        return remap

    def clear(self) -> None:
        self.n = 0
        self._views = {}


class AirTable:
    """A rectangular air table with walls at x = 0..width_m and y = 0..height_m."""

    # Pucks at rest under gravity fall asleep (sleep.py); set False on a table to compare.
    sleeping = True

    def __init__(self, width_m: float = TABLE_WIDTH_M, height_m: float = TABLE_HEIGHT_M) -> None:
        self.width_m = _positive(width_m, "width_m")
        self.height_m = _positive(height_m, "height_m")
        self._pucks = _Columns(
            pos=((2,), float),
            vel=((2,), float),
            force=((2,), float),
            radius=((), float),
            mass=((), float),
            color=((3,), np.uint8),
            still=((), float),  # seconds the puck has been slower than sleep.SLEEP_MPS
            asleep=((), bool),
            rest_pos=((2,), float),  # where the puck sleeps, or where its still time began (sleep.py)
        )
        self._springs = _Columns(
            i=((), np.intp),
            j=((), np.intp),
            length=((), float),
            k=((), float),
            damper=((), float),
            width=((), float),
            color=((3,), np.uint8),
        )
        self._puck_handles: list[Puck] = []
        self._neighbours = broadphase.NeighbourList()
        self._contacts = contacts.ContactSolver()
        self._spring_handles: list[Spring] = []
        self._events: list[tuple[float, int, Callable[[AirTable], None]]] = []
        self._event_seq = itertools.count()
        self.reset_settings()
        self.clear()

    # ------------------------------------------------------------ settings

    def reset_settings(self) -> None:
        """Back to the defaults every demo starts from."""
        self.gravity_on = False
        self.gravity_mps2 = GRAVITY_MPS2  # the strength of gravity while it is on (Earth's unless changed)
        self.cr_puck = 1.0
        self.cr_wall = 1.0
        self.wall_correction = True
        self.puck_correction = "perfect-kiss"  # the accurate mode; two-step is taught in demo 2p
        self.puck_collisions = True
        # Contacts approaching slower than this (m/s) are resting: held up by
        # the contact stage, with no bounce. Where forces press a puck, its
        # contacts also rest below PRESSED_REST_MPS and twice what the step's
        # forces add to its speed (2 g dt under gravity).
        self.rest_speed_mps = 0.0

    @property
    def puck_correction(self) -> str:
        return self._puck_correction

    @puck_correction.setter
    def puck_correction(self, mode: str) -> None:
        if mode not in pairs.CORRECTION_MODES:
            raise ValueError(f"puck_correction must be one of {', '.join(pairs.CORRECTION_MODES)}, not {mode!r}")
        self._puck_correction = mode

    @property
    def size_m(self) -> np.ndarray:
        return np.array([self.width_m, self.height_m])

    # ------------------------------------------------------------ state arrays

    @property
    def pos_m(self) -> np.ndarray:
        """(N, 2) positions, a live view (rows in creation order)."""
        return self._pucks.view("pos")

    @property
    def vel_mps(self) -> np.ndarray:
        return self._pucks.view("vel")

    @property
    def force_N(self) -> np.ndarray:
        """(N, 2) force accumulators: add to them before `step` to push pucks."""
        return self._pucks.view("force")

    @property
    def radius_m(self) -> np.ndarray:
        return self._pucks.view("radius")

    @property
    def mass_kg(self) -> np.ndarray:
        return self._pucks.view("mass")

    @property
    def color_rgb(self) -> np.ndarray:
        return self._pucks.view("color")

    @property
    def spring_pairs(self) -> np.ndarray:
        """(S, 2) puck rows joined by each spring."""
        return np.stack([self._springs.view("i"), self._springs.view("j")], axis=1)

    @property
    def spring_length_m(self) -> np.ndarray:
        return self._springs.view("length")

    @property
    def spring_k_Npm(self) -> np.ndarray:
        return self._springs.view("k")

    @property
    def spring_damper_Nspm(self) -> np.ndarray:
        return self._springs.view("damper")

    @property
    def spring_width_m(self) -> np.ndarray:
        return self._springs.view("width")

    @property
    def spring_color_rgb(self) -> np.ndarray:
        return self._springs.view("color")

    @property
    def pucks(self) -> tuple[Puck, ...]:
        return tuple(self._puck_handles)

    @property
    def springs(self) -> tuple[Spring, ...]:
        return tuple(self._spring_handles)

    # ------------------------------------------------------------ building

    def add_puck(
        self,
        pos_m: Sequence[float] = (5.0, 4.0),
        radius_m: float = 0.25,
        density_kgpm2: float = 0.3,
        vel_mps: Sequence[float] = (0.0, 0.0),
        color="white",
    ) -> Puck:
        """Add a puck; its mass is density * pi * r^2 (kg).

        A puck asked for outside the walls (or partly through one) is placed
        at the nearest point inside: its edge on the wall it was beyond (at
        the centre of the table along an axis the puck is too big for).
        """
        pos = self._nearest_inside(as_vector(pos_m, "pos_m"), _positive(radius_m, "radius_m"))
        vel = as_vector(vel_mps, "vel_mps")
        r = _positive(radius_m, "radius_m")
        rho = _positive(density_kgpm2, "density_kgpm2")
        row = self._pucks.append(pos=pos, vel=vel, radius=r, mass=rho * math.pi * r * r, color=rgb(color))
        handle = Puck(self, row)
        self._puck_handles.append(handle)
        return handle

    def _nearest_inside(self, pos: np.ndarray, r: float) -> np.ndarray:
        """The point nearest pos where a puck of radius r is inside the walls."""
        half = 0.5 * self.size_m
        lo, hi = np.minimum(r, half), np.maximum(self.size_m - r, half)
        return np.minimum(np.maximum(pos, lo), hi)

    def add_spring(
        self,
        p1: Puck,
        p2: Puck,
        length_m: float = 1.5,
        k_Npm: float = 20.0,
        damper_Nspm: float = 0.5,
        width_m: float = 0.2,
        color="gold",
    ) -> Spring:
        """Join two pucks with a spring (relaxed length length_m) and a damper."""
        for p in (p1, p2):
            if not isinstance(p, Puck) or p._table is not self or not p.alive:
                raise ValueError("a spring must join two pucks of this table")
        if p1 is p2:
            raise ValueError("a spring needs two different pucks")
        row = self._springs.append(
            i=p1.index,
            j=p2.index,
            length=_non_negative(length_m, "length_m"),
            k=_non_negative(k_Npm, "k_Npm"),
            damper=_non_negative(damper_Nspm, "damper_Nspm"),
            width=_positive(width_m, "width_m"),
            color=rgb(color),
        )
        handle = Spring(self, row, p1, p2)
        self._spring_handles.append(handle)
        return handle

    def remove_puck(self, puck: Puck) -> None:
        """Remove a puck and every spring attached to it."""
        if not isinstance(puck, Puck) or puck._table is not self or not puck.alive:
            raise ValueError("that puck is not on this table")
        row = puck.index
        si, sj = self._springs.view("i"), self._springs.view("j")
        dead_springs = np.flatnonzero((si == row) | (sj == row))
        if len(dead_springs):
            remap = self._springs.delete(dead_springs)
            survivors = []
            for s in self._spring_handles:
                new = int(remap[s._index])
                if new < 0:
                    s._index = None
                else:
                    s._index = new
                    survivors.append(s)
            self._spring_handles = survivors
        remap = self._pucks.delete(np.array([row]))
        puck._index = None
        self._puck_handles.pop(row)
        for h in self._puck_handles[row:]:
            h._index = int(remap[h._index])
        si, sj = self._springs.view("i"), self._springs.view("j")
        si[:] = remap[si]
        sj[:] = remap[sj]

    def clear(self) -> None:
        """Remove every puck, spring and scheduled event; time starts again at 0."""
        for h in self._puck_handles:
            h._index = None
        for s in self._spring_handles:
            s._index = None
        self._puck_handles = []
        self._spring_handles = []
        self._pucks.clear()
        self._springs.clear()
        self._events = []
        self.notices: list[str] = []  # sentences for the user, appended once each (see _notice)
        self._noticed: set = set()
        self._spring_dt_s = 1 / 240  # the dt the springs' effective stiffness was last worked out for
        self._speed_bound_mps = math.inf  # no speed is over this in the step (scratch, see _integrate)
        self._contacts.forget()
        self.time_s = 0.0
        self.steps = 0
        self.collision_count = 0  # puck-puck collisions since the start
        self.wall_collision_count = 0  # bounces off a wall since the start
        self._collision_records: list[pairs.Recorded] = []
        self._last_collisions: collision.Collisions | None = None
        self._world_key = ""  # what the sleepers fell asleep in (see _world): any change wakes them
        self._sleepers: np.ndarray | None = None  # this step's sleeping rows (scratch)

    def schedule(self, t_s: float, fn: Callable[[AirTable], None]) -> None:
        """Run fn(table) at the start of the first step at or after simulation time t_s."""
        t = float(t_s)
        if not math.isfinite(t):
            raise ValueError(f"schedule time must be a finite number of seconds, not {t_s!r}")
        heapq.heappush(self._events, (t, next(self._event_seq), fn))

    # ------------------------------------------------------------ queries

    def puck_at(self, point_m: Sequence[float]) -> Puck | None:
        """The puck under `point_m` (the last created, i.e. drawn on top), or None."""
        p = as_vector(point_m, "point_m")
        if self._pucks.n == 0:
            return None
        d = self.pos_m - p
        inside = np.flatnonzero(vectors.squared_lengths(d) <= self.radius_m**2)
        return self._puck_handles[int(inside[-1])] if len(inside) else None

    def springs_on(self, puck: Puck) -> tuple[Spring, ...]:
        """The springs attached to `puck`, in creation order."""
        return tuple(s for s in self._spring_handles if s.p1 is puck or s.p2 is puck)

    def kinetic_energy_J(self) -> float:
        return kinetic_energy_J(self.mass_kg, self.vel_mps)

    def spring_energy_J(self) -> float:
        """Elastic energy stored in the springs, sum of k (d - L)^2 / 2, with the k the step uses."""
        if self._springs.n == 0:
            return 0.0
        d = vectors.take(self.pos_m, self._springs.view("i")) - vectors.take(self.pos_m, self._springs.view("j"))
        stretch = vectors.lengths(d) - self.spring_length_m
        return float(0.5 * np.dot(self.spring_k_effective_Npm, stretch * stretch))

    def gravity_energy_J(self) -> float:
        """m g y summed over pucks (floor at y = 0); 0 while gravity is off."""
        if not self.gravity_on:
            return 0.0
        return float(self.gravity_mps2 * np.dot(self.mass_kg, self.pos_m[:, 1]))

    def momentum_Ns(self) -> np.ndarray:
        return self.mass_kg @ self.vel_mps if self._pucks.n else np.zeros(2)

    def center_of_mass_m(self) -> np.ndarray:
        """Mass-weighted mean position (the table centre when there are no pucks)."""
        if self._pucks.n == 0:
            return 0.5 * self.size_m
        return self.mass_kg @ self.pos_m / self.mass_kg.sum()

    def center_of_mass_vel_mps(self) -> np.ndarray:
        if self._pucks.n == 0:
            return np.zeros(2)
        return self.momentum_Ns() / self.mass_kg.sum()

    @property
    def last_collisions(self) -> collision.Collisions:
        """What the puck-puck collisions of the last step did (collision.Collisions)."""
        if self._last_collisions is None:  # joined on first read: most steps nobody asks
            self._last_collisions = collision.Collisions.concatenate(self._collision_records)
        return self._last_collisions

    # ------------------------------------------------------------ the step

    def step(self, dt_s: float, pulls: Sequence[Pull] = ()) -> None:
        """Advance the simulation by dt_s seconds, stage by stage (see the module docstring).

        `pulls` are the cursor strings acting during this step (forces.Pull).
        Sleeping pucks (`asleep`) are not moved: the step first wakes those
        something disturbed; when every puck sleeps, it only advances time.
        """
        dt = float(dt_s)
        if not (math.isfinite(dt) and dt >= 0.0):
            raise ValueError(f"dt_s must be zero or a positive number of seconds, not {dt_s!r}")
        self._run_due_events()
        self._collision_records, self._last_collisions = [], None
        if self._pucks.n and not self._wake(pulls, dt):  # 0b. sleepers: wake those disturbed
            kick, began = None, self.pos_m.copy()  # where the step began (the contacts start there)
            if dt > 0.0:
                kick = self._forces_and_integrate(pulls, dt)  # 1-2. forces, semi-implicit Euler (substeps)
            self.force_N[:] = 0.0  # the accumulators hold one step's forces
            rest = self._rest_speeds(kick, dt)  # below these speeds contacts rest, not bounce: (pairs, walls)
            wall_rest = None if rest is None else self._contacts.wall_rest(rest[1])
            maybe_past = None
            if dt > 0.0:  # 3. hits, walls and pairs, in time order
                maybe_past = self._hits_in_order(dt, None if rest is None else rest[0], wall_rest)
                self._wake_hit()
            self._resolve_walls(maybe_past, wall_rest)  # 3b. still past a wall
            moved = np.empty(0, dtype=np.intp)
            if self.puck_collisions:  # 4. overlapping pairs (told what the walls moved if the list was just checked)
                moved = self._resolve_pairs(dt, None if rest is None else rest[0])
            self._wake_hit()
            if rest is not None and self._resolve_contacts(rest, dt, began):  # 5. resting contacts
                self._resolve_walls(rest=self._contacts.wall_rest(rest[1]), hold=True)  # 6. walls again
            elif len(moved):
                self._resolve_walls(only=moved)  # 6. walls again, for the pucks the pairs moved
            self._fall_asleep(pulls, dt)  # 7. pucks still for long enough fall asleep
        self.time_s += dt
        self.steps += 1

    # ------------------------------------------------------------ sleeping (sleep.py)

    @property
    def asleep(self) -> np.ndarray:
        """(N,) which pucks sleep (read-only): at rest, not moved by the step until disturbed."""
        out = self._pucks.view("asleep").view()
        out.flags.writeable = False
        return out

    def _world(self) -> str:
        """What sleepers depend on, as one value: a change in any of it wakes every puck."""
        g = self.gravity_mps2 if self.gravity_on else 0.0
        sizes = f"{self.width_m!r} {self.height_m!r} {self._pucks.n} {self._springs.n} {self.radius_m.sum()!r}"
        return f"{g!r} {sizes} {self.puck_correction} {self.puck_collisions}"

    def _wake(self, pulls: Sequence[Pull], dt: float) -> bool:
        """Wake the sleepers that must wake (sleep.py); return True if every puck still sleeps.

        Sets `_sleepers` to the rows that sleep through this step (None: none).
        """
        asleep = self._pucks.view("asleep")
        self._sleepers = None
        if not np.count_nonzero(asleep):
            self._world_key = ""  # worked out when someone falls asleep (_fall_asleep)
            return False
        world, self._world_key = self._world_key, self._world()
        if world != self._world_key or not (self.sleeping and self.gravity_on):
            self._set_awake(np.flatnonzero(asleep), island=False)
            return False
        pos, vel = self.pos_m, self.vel_mps
        sleepers = np.flatnonzero(asleep)
        woken = sleep.written_from_outside(pos, vel, self.force_N, self._pucks.view("rest_pos"), sleepers)
        pulled = np.array([p.row for p in pulls], dtype=np.intp)
        self._set_awake(np.concatenate([woken, pulled]))
        if np.count_nonzero(asleep) < self._pucks.n:  # someone is awake: is it coming near a sleeper?
            candidates = self._neighbours.pairs(pos, self.radius_m)
            self._set_awake(sleep.near_movers(pos, vel, asleep, candidates, dt, pulled))
        sleepers = np.flatnonzero(asleep)
        if len(sleepers) == self._pucks.n:
            return True
        self._sleepers = sleepers if len(sleepers) else None
        return False

    def _set_awake(self, rows: np.ndarray, island: bool = True) -> None:
        """Wake the pucks in `rows` (their still time starts again) and, with `island`, every
        sleeper touching them, and every one touching those, and so on (sleep.island)."""
        if len(rows) == 0:
            return
        asleep = self._pucks.view("asleep")
        if island and len(rows) < self._pucks.n:
            rows = sleep.island(self.pos_m, rows, asleep, self._neighbours.pairs(self.pos_m, self.radius_m))
        asleep[rows] = False
        self._pucks.view("still")[rows] = 0.0

    def _wake_hit(self) -> None:
        """Wake the sleepers a collision gave a velocity (this step's stages then move them)."""
        if self._sleepers is None:
            return
        v = vectors.take(self.vel_mps, self._sleepers)
        hit = self._sleepers.take(np.flatnonzero((v[:, 0] != 0.0) | (v[:, 1] != 0.0)))
        if len(hit):
            self._set_awake(hit)
            keep = np.flatnonzero(self._pucks.view("asleep").take(self._sleepers))
            self._sleepers = self._sleepers.take(keep) if len(keep) else None

    def _fall_asleep(self, pulls: Sequence[Pull], dt: float) -> None:
        """Put to sleep the pucks that have been still for long enough (sleep.ready_to_sleep)."""
        self._sleepers = None
        if not (self.sleeping and self.gravity_on):
            return
        asleep, pos, vel = self._pucks.view("asleep"), self.pos_m, self.vel_mps
        free = np.ones(self._pucks.n, dtype=bool)
        free[self._springs.view("i")] = False
        free[self._springs.view("j")] = False
        free[[p.row for p in pulls]] = False
        still, anchor = self._pucks.view("still"), self._pucks.view("rest_pos")
        ready = sleep.still_for_long(pos, vel, still, anchor, asleep, free, dt)
        if ready is not None:
            candidates = self._neighbours.pairs(pos, self.radius_m)
            asleep[sleep.with_still_neighbours(pos, ready, asleep, candidates)] = True
        sleepers = np.flatnonzero(asleep)
        if len(sleepers):
            self._world_key = self._world_key or self._world()
            vel[sleepers] = 0.0
            self._pucks.view("rest_pos")[sleepers] = pos[sleepers]

    def _run_due_events(self) -> None:
        """Run the scheduled events whose time has come, in time order."""
        while self._events and self._events[0][0] <= self.time_s + 1e-9:
            _, _, fn = heapq.heappop(self._events)
            fn(self)

    def _forces_and_integrate(self, pulls: Sequence[Pull], dt: float) -> np.ndarray | float | None:
        """Stages 1 and 2, in as many substeps as the springs need (substeps.py); return the kick
        (see _integrate) of the whole step. Forces written from outside act through every substep."""
        n = 1
        if self._springs.n:
            a, b = self._springs.view("i"), self._springs.view("j")
            n = substeps.count(self.mass_kg, a, b, self.spring_k_Npm, dt)
        if n == 1:
            return self._integrate(self._add_forces(pulls, dt), dt)
        h, outside, kick = dt / n, self.force_N.copy(), None
        for s in range(n):
            if s:
                self.force_N[:] = outside
            add = self._integrate(self._add_forces(pulls, h), h)
            kick = add if kick is None else kick if add is None else kick + add
        return kick

    def _add_forces(self, pulls: Sequence[Pull], dt: float) -> forces.Implicit | None:
        """Add the pulls' and springs' forces to force_N; return what the step takes implicitly (None: nothing)."""
        if not pulls and self._springs.n == 0:
            return None  # a gas: nothing to add, and no (N, 2) arrays to make and check
        force = self.force_N
        implicit = forces.Implicit.empty(self._pucks.n)
        if pulls:
            forces.add_pull_forces(force, implicit, pulls, self.pos_m, self.vel_mps, self.mass_kg, dt)
        if self._springs.n:
            a, b, f1 = self._spring_forces(dt, implicit)
            forces.add_spring_forces(force, a, b, f1)
        return implicit

    def _integrate(self, implicit: forces.Implicit | None, dt: float) -> np.ndarray | float | None:
        """Semi-implicit Euler: v += (F/m + g) dt (the implicit parts solved for), then x += v dt.

        Returns the speed the forces and gravity added to each puck (a number
        if the same for all), or None if nothing pushed: the contact stage's
        rest speeds come from it.
        """
        pos, vel, force, mass = self.pos_m, self.vel_mps, self.force_N, self.mass_kg
        kick = None
        if implicit is not None and implicit.any:
            rhs = dt * (force + implicit.lag)
            if self.gravity_on:
                rhs[:, 1] -= self.gravity_mps2 * dt * mass
            dv = self._implicit_velocity_change(implicit, rhs, dt)
            vel += dv
            kick = vectors.lengths(dv)
        elif force.any():  # usually nothing pushes: skip the (N, 2) update (any() beats count_nonzero on floats)
            dv = force * (dt / mass)[:, None]
            if self.gravity_on:
                dv[:, 1] -= self.gravity_mps2 * dt
            vel += dv
            kick = vectors.lengths(dv)
        elif self.gravity_on:
            vel[:, 1] -= self.gravity_mps2 * dt
            kick = self.gravity_mps2 * dt
        if self._sleepers is not None:
            vel[self._sleepers] = 0.0  # sleepers stay where they are
        # A last guard against runaway values; a cheap bound first: a speed
        # over the limit has a component over limit / sqrt(2).
        # A bound on every speed (sqrt 2 times the largest component): the hits' stage uses it too.
        self._speed_bound_mps = math.sqrt(2.0) * float(np.abs(vel).max())
        if self._speed_bound_mps > MAX_SPEED_MPS:
            speed = np.hypot(vel[:, 0], vel[:, 1])  # not lengths(): v^2 may overflow here
            vel *= np.minimum(1.0, MAX_SPEED_MPS / np.maximum(speed, 1e-300))[:, None]
            self._speed_bound_mps = MAX_SPEED_MPS
        pos += vel * dt
        return kick

    def _implicit_velocity_change(self, implicit: forces.Implicit, rhs: np.ndarray, dt: float) -> np.ndarray:
        """dv from the implicit solve (implicit.py), with walls braced and the springs' turning taken in."""
        mass = self.mass_kg
        dv = implicit_solve.velocity_change(mass, implicit, rhs)
        released = np.zeros(dv.shape, dtype=bool)
        for _ in range(BRACE_PASSES):  # bracing one puck can push another of its body into a wall
            if not self._brace_walls(implicit, dv, released, dt):
                break
            dv = implicit_solve.velocity_change(mass, implicit, rhs)
            # A wall only pushes: let go where it had to pull the puck to keep it bouncing.
            pulled = implicit_solve.wall_impulses(mass, implicit, rhs, dv) * implicit.fixed_side < 0.0
            if pulled.any():
                implicit.fixed &= ~pulled
                released |= pulled
                dv = implicit_solve.velocity_change(mass, implicit, rhs)
        if implicit_solve.correct_for_turning(self.pos_m, self.vel_mps + dv, mass, implicit, rhs, dt):
            dv = implicit_solve.velocity_change(mass, implicit, rhs)
        return dv

    def _brace_walls(self, implicit: forces.Implicit, dv: np.ndarray, released: np.ndarray, dt: float) -> bool:
        """Put the walls that pucks on implicit springs would cross into the solve (implicit.brace_walls)."""
        walls = (self.size_m, self.cr_wall)
        return implicit_solve.brace_walls(self.pos_m, self.vel_mps, dv, self.radius_m, walls, implicit, released, dt)

    def _hits_in_order(self, dt: float, rest: np.ndarray | None, wall_rest: np.ndarray | None) -> np.ndarray | None:
        """Resolve the step's wall and pair hits in the order they happen (events.py); return the
        rows that may still be past a wall (None: any)."""
        mode = self.puck_correction
        rules = events.Rules(
            self.cr_puck,
            self.cr_wall,
            pairs=mode if self.puck_collisions else "none",
            walls=self.wall_correction,
            accel_y_mps2=-self.gravity_mps2 if self.gravity_on else 0.0,
            rest=rest,
            wall_rest=wall_rest,
            held=None if rest is None else self._contacts.held,
            speed_bound_mps=self._speed_bound_mps,
        )
        hits = events.resolve_hits(
            self.pos_m, self.vel_mps, self.radius_m, self.mass_kg, self.size_m, dt, rules, self._neighbours
        )
        self.wall_collision_count += hits.walls
        if hits.rows:
            self._collision_records.append(hits.collisions(self.radius_m))
            self.collision_count += len(hits.rows)
        if hits.capped:
            self._notice("capped", events.CAPPED_NOTICE)
        return hits.maybe_past

    def _rest_speeds(self, kick: np.ndarray | float | None, dt: float) -> tuple[np.ndarray, np.ndarray] | None:
        """Each puck's rest speeds towards other pucks and towards the walls; None: all zero.

        The rest speed is rest_speed_mps, and where this step's forces gave the puck a kick,
        PRESSED_REST_MPS and twice the kick; a contact rests when its bounce would be slower
        than that (contacts.rest_for_restitution: at restitution 0, always).
        """
        floor = _non_negative(self.rest_speed_mps, "rest_speed_mps")
        if kick is None and floor == 0.0:
            return None  # nothing presses: every contact is a collision, as in the course's model
        rest = np.full(self._pucks.n, floor)
        if kick is not None:
            kick = np.asarray(kick)
            np.maximum(rest, np.where(kick > 0.0, np.maximum(2.0 * kick, PRESSED_REST_MPS), 0.0), out=rest)
        return contacts.rest_for_restitution(rest, self.cr_puck), contacts.rest_for_restitution(rest, self.cr_wall)

    def _resolve_contacts(
        self, rest: tuple[np.ndarray, np.ndarray], dt: float, began: np.ndarray | None = None
    ) -> bool:
        """Hold resting contacts (contacts.py), `rest` being the rest speeds (pairs, walls) and `began`
        the positions when the step began; return whether there were any."""
        if self.puck_collisions:
            candidates = self._neighbours.pairs(self.pos_m, self.radius_m)
        else:
            none = np.empty(0, dtype=np.intp)
            candidates = (none, none, np.empty(0))
        asleep = None if self._sleepers is None else self._pucks.view("asleep")
        pucks = (self.pos_m, self.vel_mps, self.radius_m, self.mass_kg)
        return self._contacts.solve(
            *pucks, self.size_m, candidates, rest[0], dt, asleep, rest_walls=rest[1], began=began
        )

    def _resolve_walls(self, only: np.ndarray | None = None, rest: np.ndarray | None = None, hold=False) -> np.ndarray:
        """Push pucks back inside the walls and bounce them (only the rows `only`, if given); return
        the rows that were past a wall.

        With `rest`, slow pucks are left to the contact stage, or with `hold`
        put on the surface without a bounce (walls.resolve_walls).
        """
        bounced, past = walls.resolve_walls(
            self.pos_m,
            self.vel_mps,
            self.radius_m,
            self.size_m,
            self.cr_wall,
            self.wall_correction,
            only=only,
            rest=rest,
            hold_slow=hold,
        )
        self.wall_collision_count += bounced
        return past

    def _resolve_pairs(self, dt: float, rest: np.ndarray | None = None) -> np.ndarray:
        """Collide and part the overlapping pairs; return the rows they moved (a row may repeat).

        With `rest`, pairs approaching slower than their rest speed are left to
        the contact stage.
        """
        pos, vel, radius, mass = self.pos_m, self.vel_mps, self.radius_m, self.mass_kg
        ci, cj, _ = self._neighbours.pairs(pos, radius)
        close = broadphase.squared_distances(pos, ci, cj) < self._neighbours.reach_squared()
        i, j = self._colliding(rest, *broadphase.pairs_where(close, ci, cj, len(pos), self._neighbours.sorted_order))
        records, moved = [], []
        for attempt in range(1 + EXTRA_PASSES):
            if len(i) == 0:
                break
            look_again = self.puck_correction != "off" and attempt < EXTRA_PASSES
            if attempt < EXTRA_PASSES:
                records += pairs.resolve_pairs(
                    pos, vel, radius, mass, i, j, self.cr_puck, self.puck_correction, dt, in_time_order=True
                )
            else:
                pairs.push_apart(pos, radius, mass, i, j)
            moved += [i, j]
            if not look_again:
                break  # the last pass; or "off", where overlaps stay: that is what it shows
            # Parting a pair can push one of its pucks into a third one that
            # was already handled: look again among the same candidates (those
            # that may have come within reach: nothing else changed), collide
            # those pairs too, and at last just push apart what is left.
            near_sq = self._neighbours.reach_squared(OVERLAP_SLOP_M)
            i, j = self._colliding(rest, *broadphase.overlapping_pairs(pos, ci, cj, None, reach_sq=near_sq))
        if not moved:
            return np.empty(0, dtype=np.intp)
        self._collision_records += records
        self.collision_count += sum(len(r) for r in records)
        return np.concatenate(moved)

    def _colliding(self, rest: np.ndarray | None, i: np.ndarray, j: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The pairs (i, j) that collide: all of them if rest is None, else those that approach
        faster than their rest speed and did not press on each other in the last step."""
        if rest is None or len(i) == 0:
            return i, j
        pos, vel = self.pos_m, self.vel_mps
        n, _ = vectors.unit_vectors(vectors.take(pos, i) - vectors.take(pos, j), i + j)
        vn = vectors.dot_rows(vectors.take(vel, i) - vectors.take(vel, j), n)
        fast = (vn < -np.maximum(rest.take(i), rest.take(j))).nonzero()[0]  # few: look only these up
        fast = fast.take((~self._contacts.held(i.take(fast), j.take(fast))).nonzero()[0])
        return i.take(fast), j.take(fast)

    def _spring_forces(
        self, dt: float, implicit: forces.Implicit | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(rows of p1, rows of p2, force on p1) for every spring; p2 gets minus that.

        With `implicit`, a step is being taken: each spring's share beyond its
        pucks' explicit budget is recorded there, with its lag forces added in.
        """
        a, b = self._springs.view("i"), self._springs.view("j")
        mass, length = self.mass_kg, self.spring_length_m
        mu = forces.reduced_masses(mass, a, b)
        k, c = forces.effective_spring(self.spring_k_Npm, self.spring_damper_Nspm, mu, dt)
        n, f1 = forces.spring_forces(self.pos_m, self.vel_mps, a, b, length, k, c)
        if implicit is not None:
            self._spring_dt_s = dt
            frac_k, frac_c = forces.explicit_fractions(mass, a, b, k, c, dt)
            if frac_k.min() < 1.0 or frac_c.min() < 1.0:  # else all explicit, as soft springs usually are
                k_i, c_i = (1.0 - frac_k) * k, (1.0 - frac_c) * c
                ia, ib, lag = forces.implicit_springs(implicit, self.vel_mps, (a, b, n), k_i, c_i, dt)
                forces.add_spring_forces(implicit.lag, ia, ib, lag)
                if frac_k.min() < 1.0:
                    self._notice("implicit", IMPLICIT_NOTICE)
            if (k < self.spring_k_Npm).any():
                self._notice_softened(k)
        return a, b, f1

    @property
    def spring_k_effective_Npm(self) -> np.ndarray:
        """(S,) the stiffness each spring acts with at the last step's dt (or 1/240 s before any step).

        It is the k asked for, unless that is beyond what a step can compute
        (forces.SOFTENING_LIMIT); then the spring is softened to this, and
        `notices` says so.
        """
        a, b = self._springs.view("i"), self._springs.view("j")
        mu = forces.reduced_masses(self.mass_kg, a, b)
        return forces.effective_spring(self.spring_k_Npm, self.spring_damper_Nspm, mu, self._spring_dt_s)[0]

    @property
    def spring_damper_effective_Nspm(self) -> np.ndarray:
        """(S,) the damper each spring acts with (as spring_k_effective_Npm)."""
        a, b = self._springs.view("i"), self._springs.view("j")
        mu = forces.reduced_masses(self.mass_kg, a, b)
        return forces.effective_spring(self.spring_k_Npm, self.spring_damper_Nspm, mu, self._spring_dt_s)[1]

    def _notice(self, key, sentence: str) -> None:
        """Add `sentence` to `notices`, once for each `key` (until clear())."""
        if key not in self._noticed:
            self._noticed.add(key)
            self.notices.append(sentence)

    def _notice_softened(self, k: np.ndarray) -> None:
        for s in np.flatnonzero(k < self.spring_k_Npm):
            self._notice(
                ("softened", int(s)),
                f"Spring {s} asks for k = {self.spring_k_Npm[s]:.3g} N/m, more than a step can compute;"
                f" it acts with k = {k[s]:.3g} N/m (its k_effective_Npm).",
            )

    def forces_on(self, puck: Puck, dt_s: float = 1 / 240, pulls: Sequence[Pull] = ()) -> dict[str, np.ndarray]:
        """The forces (N) the next step will apply to `puck`, by source, if `pulls` act on it.

        Keys: "cursor strings", "springs", "gravity" (only the non-zero ones).
        `dt_s` matters only for springs stiffer than a step can compute (see
        spring_k_effective_Npm). These are the forces at the start of the step;
        a spring stiff enough to be solved implicitly acts with what it will
        have at the end.
        """
        row = puck.index
        out: dict[str, np.ndarray] = {}
        v = self.vel_mps[row]
        strings = [f - c * v for r, f, c, _ in forces.pull_forces(pulls, self.pos_m) if r == row]
        if strings:
            out["cursor strings"] = np.sum(strings, axis=0)
        if self._springs.n:
            a, b, f1 = self._spring_forces(dt_s)
            total = f1[a == row].sum(axis=0) - f1[b == row].sum(axis=0)
            if (a == row).any() or (b == row).any():
                out["springs"] = total
        if self.gravity_on:
            out["gravity"] = np.array([0.0, -self.mass_kg[row] * self.gravity_mps2])
        return out
