"""AirTable: the physics world of pucks, springs and walls (SI units, no pygame).

State is kept as a structure of arrays, one row per puck (and per spring), so
one step is a handful of numpy operations whatever the number of pucks. Puck
and Spring objects are handles onto those rows (see bodies.py).

One `step(dt_s)`, in the order of the course's game loop:
1. forces: cursor strings, springs, gravity;
2. semi-implicit Euler: v += F/m dt, then x += v dt;
3. walls;
4. puck pairs: the candidates from a neighbour list (a grid rebuilds it every
   few steps), then sequential collision + position correction, then a second
   look at the pairs the corrections pushed into overlap;
5. walls again, since pushing pairs apart can push a puck into a wall.
"""

from __future__ import annotations

import heapq
import itertools
import math
from collections.abc import Callable, Sequence

import numpy as np

from airtable.app.client import CURSOR_STRINGS
from airtable.colors import rgb
from airtable.memory import keep_freed_memory
from airtable.physics import collisions, rows
from airtable.physics.bodies import Puck, Spring, as_vector

GRAVITY_MPS2 = 9.8
# Springs and cursor strings stiffer than a step can integrate are softened to
# this fraction of the limit (k dt^2 / m, and a spring's c dt / m, at most
# this), which keeps semi-implicit Euler stable for any mass the user picks.
# The cursor strings' drag needs no limit: it is applied implicitly.
STIFFNESS_LIMIT = 0.5
# After the first pass over the overlapping pairs, up to this many more passes
# over the pairs the corrections pushed into overlap: collisions again, then a
# last pass that only pushes apart.
EXTRA_PASSES = 2
# Overlaps smaller than this (m) are left to the next step: round-off only.
OVERLAP_SLOP_M = 1e-9
# A last guard against runaway values: nothing real on a table moves this fast.
MAX_SPEED_MPS = 1e8


def kinetic_energy_J(mass_kg: np.ndarray, vel_mps: np.ndarray) -> float:
    """Sum of m v^2 / 2 over the rows (einsum's row dot is five times slower here)."""
    return float(0.5 * np.dot(mass_kg, collisions.squared_lengths(vel_mps)))


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

    def view(self, name: str) -> np.ndarray:
        return self._data[name][: self.n]

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
        return remap

    def clear(self) -> None:
        self.n = 0


class AirTable:
    """A rectangular air table with walls at x = 0..width_m and y = 0..height_m."""

    def __init__(self, width_m: float = 10.0, height_m: float = 8.7556) -> None:
        keep_freed_memory()  # the step's temporary arrays are reused, not re-faulted (memory.py)
        self.width_m = _positive(width_m, "width_m")
        self.height_m = _positive(height_m, "height_m")
        self._pucks = _Columns(
            pos=((2,), float),
            vel=((2,), float),
            force=((2,), float),
            radius=((), float),
            mass=((), float),
            color=((3,), np.uint8),
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
        self._neighbours = collisions.NeighbourList()
        self._spring_handles: list[Spring] = []
        self._events: list[tuple[float, int, Callable[[AirTable], None]]] = []
        self._event_seq = itertools.count()
        # Clients (airtable.app.client.Client) whose cursor strings pull on pucks;
        # the app and the server share this list. Index 0 is the local user.
        self.clients: list = []
        self.reset_settings()
        self.clear()

    # ------------------------------------------------------------ settings

    def reset_settings(self) -> None:
        """Back to the defaults every demo starts from."""
        self.gravity_on = False
        self.cr_puck = 1.0
        self.cr_wall = 1.0
        self.wall_correction = True
        self.puck_correction = "two-step"
        self.puck_collisions = True

    @property
    def puck_correction(self) -> str:
        return self._puck_correction

    @puck_correction.setter
    def puck_correction(self, mode: str) -> None:
        if mode not in collisions.CORRECTION_MODES:
            raise ValueError(f"puck_correction must be one of {', '.join(collisions.CORRECTION_MODES)}, not {mode!r}")
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
        """Add a puck; its mass is density * pi * r^2 (kg)."""
        pos = as_vector(pos_m, "pos_m")
        vel = as_vector(vel_mps, "vel_mps")
        r = _positive(radius_m, "radius_m")
        rho = _positive(density_kgpm2, "density_kgpm2")
        row = self._pucks.append(pos=pos, vel=vel, radius=r, mass=rho * math.pi * r * r, color=rgb(color))
        handle = Puck(self, row)
        self._puck_handles.append(handle)
        return handle

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
        self.time_s = 0.0
        self.steps = 0
        self.collision_count = 0
        self._collision_records: list[collisions.Collisions] = []
        self._last_collisions: collisions.Collisions | None = None

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
        inside = np.flatnonzero(collisions.squared_lengths(d) <= self.radius_m**2)
        return self._puck_handles[int(inside[-1])] if len(inside) else None

    def kinetic_energy_J(self) -> float:
        return kinetic_energy_J(self.mass_kg, self.vel_mps)

    def spring_energy_J(self) -> float:
        """Elastic energy stored in the springs, sum of k (d - L)^2 / 2."""
        if self._springs.n == 0:
            return 0.0
        pairs = self.spring_pairs
        d = rows.take(self.pos_m, pairs[:, 0]) - rows.take(self.pos_m, pairs[:, 1])
        stretch = collisions.lengths(d) - self.spring_length_m
        return float(0.5 * np.dot(self.spring_k_Npm, stretch * stretch))

    def gravity_energy_J(self) -> float:
        """m g y summed over pucks (floor at y = 0); 0 while gravity is off."""
        if not self.gravity_on:
            return 0.0
        return float(GRAVITY_MPS2 * np.dot(self.mass_kg, self.pos_m[:, 1]))

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
    def last_collisions(self) -> collisions.Collisions:
        """What the puck-puck collisions of the last step did (collisions.Collisions)."""
        if self._last_collisions is None:  # joined on first read: most steps nobody asks
            self._last_collisions = collisions.Collisions.concatenate(self._collision_records)
        return self._last_collisions

    # ------------------------------------------------------------ the step

    def step(self, dt_s: float) -> None:
        """Advance the simulation by dt_s seconds (see the module docstring)."""
        dt = float(dt_s)
        if not (math.isfinite(dt) and dt >= 0.0):
            raise ValueError(f"dt_s must be zero or a positive number of seconds, not {dt_s!r}")
        while self._events and self._events[0][0] <= self.time_s + 1e-9:
            _, _, fn = heapq.heappop(self._events)
            fn(self)
        self._collision_records, self._last_collisions = [], None
        if self._pucks.n:
            self._integrate(dt)
        self.time_s += dt
        self.steps += 1

    def _integrate(self, dt: float) -> None:
        pos, vel, force = self.pos_m, self.vel_mps, self.force_N
        mass, radius = self.mass_kg, self.radius_m
        if dt > 0.0:
            drag = np.zeros(len(mass)) if self.clients else None
            self._add_cursor_forces(force, drag, dt)
            self._add_spring_forces(force, dt)
            if np.count_nonzero(force):  # usually nothing pushes: skip the (N, 2) update
                vel += force * (dt / mass)[:, None]
            if self.gravity_on:
                vel[:, 1] -= GRAVITY_MPS2 * dt
            if drag is not None and drag.any():
                # The strings' drag -c v is taken at the end of the step
                # (backward Euler), which stays stable for any c and mass.
                vel /= (1.0 + drag * dt / mass)[:, None]
            # A cheap bound first: a speed over the limit has a component over limit / sqrt(2).
            if np.abs(vel).max() > MAX_SPEED_MPS / math.sqrt(2.0):
                speed = np.hypot(vel[:, 0], vel[:, 1])  # not lengths(): v^2 may overflow here
                vel *= np.minimum(1.0, MAX_SPEED_MPS / np.maximum(speed, 1e-300))[:, None]
            pos += vel * dt
        force[:] = 0.0
        collisions.resolve_walls(pos, vel, radius, self.size_m, self.cr_wall, self.wall_correction)
        if self.puck_collisions:
            self._resolve_pucks(dt)

    def _resolve_pucks(self, dt: float) -> None:
        pos, vel, radius, mass = self.pos_m, self.vel_mps, self.radius_m, self.mass_kg
        ci, cj, reach = self._neighbours.pairs(pos, radius)
        i, j = collisions.overlapping_pairs(pos, ci, cj, reach)
        records, moved = [], []
        for attempt in range(1 + EXTRA_PASSES):
            if len(i) == 0:
                break
            if attempt < EXTRA_PASSES:
                records += collisions.resolve_pairs(
                    pos, vel, radius, mass, i, j, self.cr_puck, self.puck_correction, dt
                )
            else:
                collisions.push_apart(pos, radius, mass, i, j)
            moved += [i, j]
            if self.puck_correction == "off" or attempt == EXTRA_PASSES:
                break  # with "off" overlaps stay: that is what it shows
            # Parting a pair can push one of its pucks into a third one that
            # was already handled: look again among the same candidates,
            # collide those pairs too, and at last just push apart what is left.
            i, j = collisions.overlapping_pairs(pos, ci, cj, reach - OVERLAP_SLOP_M)
        if not moved:
            return
        self._collision_records = records
        self.collision_count += sum(len(r) for r in records)
        # Only pucks that pairs moved can have been pushed into a wall (a row
        # listed twice is just checked twice).
        moved_rows = np.concatenate(moved)
        collisions.resolve_walls(pos, vel, radius, self.size_m, self.cr_wall, self.wall_correction, only=moved_rows)

    def _spring_forces(self, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(rows of p1, rows of p2, force on p1) for every spring; p2 gets minus that."""
        pairs = self.spring_pairs
        a, b = pairs[:, 0], pairs[:, 1]
        pos, vel, mass = self.pos_m, self.vel_mps, self.mass_kg
        n, dist = collisions.unit_vectors(rows.take(pos, a) - rows.take(pos, b))
        m_a, m_b = mass.take(a), mass.take(b)
        mu = m_a * m_b / (m_a + m_b)
        k = np.minimum(self.spring_k_Npm, STIFFNESS_LIMIT * mu / (dt * dt))
        c = np.minimum(self.spring_damper_Nspm, STIFFNESS_LIMIT * mu / dt)
        vn = collisions.dot_rows(rows.take(vel, a) - rows.take(vel, b), n)
        return a, b, (k * (self.spring_length_m - dist) - c * vn)[:, None] * n

    def _cursor_strings(self, dt: float) -> list[tuple[int, np.ndarray, float]]:
        """(puck row, spring force k (cursor - x), drag c) for every client holding a puck."""
        out = []
        for client in self.clients:
            puck = getattr(client, "held", None)
            if puck is None or not puck.alive or client.button not in CURSOR_STRINGS:
                continue
            row = puck.index
            k, c = CURSOR_STRINGS[client.button]
            k = min(k, STIFFNESS_LIMIT * self.mass_kg[row] / (dt * dt))
            out.append((row, k * (np.asarray(client.cursor_m) - self.pos_m[row]), c))
        return out

    def _add_spring_forces(self, force: np.ndarray, dt: float) -> None:
        if self._springs.n:
            a, b, f1 = self._spring_forces(dt)
            rows.add_at(force, a, f1)
            rows.add_at(force, b, -f1)

    def _add_cursor_forces(self, force: np.ndarray, drag: np.ndarray | None, dt: float) -> None:
        for row, f, c in self._cursor_strings(dt):
            force[row] += f
            drag[row] += c

    def forces_on(self, puck: Puck, dt_s: float = 1 / 240) -> dict[str, np.ndarray]:
        """The forces (N) the next step will apply to `puck`, by source.

        Keys: "cursor strings", "springs", "gravity" (only the non-zero ones).
        `dt_s` matters only for springs stiffer than the step can integrate.
        """
        row = puck.index
        out: dict[str, np.ndarray] = {}
        v = self.vel_mps[row]
        strings = [f - c * v for r, f, c in self._cursor_strings(dt_s) if r == row]
        if strings:
            out["cursor strings"] = np.sum(strings, axis=0)
        if self._springs.n:
            a, b, f1 = self._spring_forces(dt_s)
            total = f1[a == row].sum(axis=0) - f1[b == row].sum(axis=0)
            if (a == row).any() or (b == row).any():
                out["springs"] = total
        if self.gravity_on:
            out["gravity"] = np.array([0.0, -self.mass_kg[row] * GRAVITY_MPS2])
        return out
