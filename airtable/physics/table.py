"""AirTable: the physics world of pucks, springs and walls (SI units, no pygame).

The table is its storage (storage.py: the columns, one row per puck and per
spring, the settings and the parts kept from step to step) and the API on it:
Puck and Spring handles onto the rows (bodies.py), adding and removing them,
timed events, and the queries the HUD and the tests ask (energies, momentum).
`step(dt_s, pulls)` runs the course's loop, which reads top to bottom in
step.py, one stage a line.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence

import numpy as np

from airtable.physics import forces, integrate, vectors
from airtable.physics import step as stepping
from airtable.physics.bodies import Handles, Puck, Spring, as_vector
from airtable.physics.collision import Collisions, PairRecords
from airtable.physics.colors import rgb
from airtable.physics.forces import Pull
from airtable.physics.storage import TABLE_HEIGHT_M, TABLE_WIDTH_M, Storage, non_negative, positive

__all__ = ["AirTable", "TABLE_HEIGHT_M", "TABLE_WIDTH_M", "kinetic_energy_J"]


def kinetic_energy_J(mass_kg: np.ndarray, vel_mps: np.ndarray) -> float:
    """Sum of m v^2 / 2 over the rows (einsum's row dot is five times slower here)."""
    return float(0.5 * np.dot(mass_kg, vectors.squared_lengths(vel_mps)))


class AirTable(Storage):
    """A rectangular air table with walls at x = 0..width_m and y = 0..height_m."""

    # The handles are parts too: a restored table gives the same handles their rows back (state.py).
    PARTS = (*Storage.PARTS, "puck_handles", "spring_handles")
    # What the last step's collisions did: not state (a restored table reports none until it steps).
    NOT_SAVED = (*Storage.NOT_SAVED, "_last_records", "_last_collisions")

    def __init__(self, width_m: float = TABLE_WIDTH_M, height_m: float = TABLE_HEIGHT_M) -> None:
        super().__init__(width_m, height_m)
        self.puck_handles = Handles()
        self.spring_handles = Handles()
        self.clear()

    @property
    def spring_pairs(self) -> np.ndarray:
        """(S, 2) puck rows joined by each spring."""
        return np.stack(self.spring_ends, axis=1)

    @property
    def pucks(self) -> tuple[Puck, ...]:
        return tuple(self.puck_handles)

    @property
    def springs(self) -> tuple[Spring, ...]:
        return tuple(self.spring_handles)

    @property
    def asleep(self) -> np.ndarray:
        """(N,) which pucks sleep (read-only): at rest, not moved by the step until disturbed (sleep.py)."""
        out = self.puck_columns.view("asleep").view()
        out.flags.writeable = False
        return out

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
        pos = self._nearest_inside(as_vector(pos_m, "pos_m"), positive(radius_m, "radius_m"))
        vel = as_vector(vel_mps, "vel_mps")
        r = positive(radius_m, "radius_m")
        rho = positive(density_kgpm2, "density_kgpm2")
        row = self.puck_columns.append(pos=pos, vel=vel, radius=r, mass=rho * math.pi * r * r, color=rgb(color))
        handle = Puck(self, row)
        self.puck_handles.append(handle)
        self.changed = True
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
            if not isinstance(p, Puck) or not p.is_on(self):
                raise ValueError("a spring must join two pucks of this table")
        if p1 is p2:
            raise ValueError("a spring needs two different pucks")
        row = self.spring_columns.append(
            i=p1.index,
            j=p2.index,
            length=non_negative(length_m, "length_m"),
            k=non_negative(k_Npm, "k_Npm"),
            damper=non_negative(damper_Nspm, "damper_Nspm"),
            width=positive(width_m, "width_m"),
            color=rgb(color),
        )
        handle = Spring(self, row, p1, p2)
        self.spring_handles.append(handle)
        self.changed = True
        return handle

    def remove_puck(self, puck: Puck) -> None:
        """Remove a puck and every spring attached to it."""
        if not isinstance(puck, Puck) or not puck.is_on(self):
            raise ValueError("that puck is not on this table")
        row = puck.index
        si, sj = self.spring_ends
        dead_springs = np.flatnonzero((si == row) | (sj == row))
        if len(dead_springs):
            self.spring_handles.renumber(self.spring_columns.delete(dead_springs))
        remap = self.puck_columns.delete(np.array([row]))
        self.puck_handles.renumber(remap)
        si, sj = self.spring_ends
        si[:] = remap[si]
        sj[:] = remap[sj]
        self.changed = True

    def clear(self) -> None:
        """Remove every puck, spring and scheduled event; time starts again at 0."""
        self.puck_handles.clear()
        self.spring_handles.clear()
        self.clear_storage()
        self._last_records: list[PairRecords] = []  # what the last step's collisions did (its context's records)
        self._last_collisions: Collisions | None = None  # ... joined, once asked for

    def schedule(self, t_s: float, fn: Callable[[AirTable], None]) -> None:
        """Run fn(table) at the start of the first step at or after simulation time t_s."""
        t = float(t_s)
        if not math.isfinite(t):
            raise ValueError(f"schedule time must be a finite number of seconds, not {t_s!r}")
        self.timed.add(t, fn)

    # ------------------------------------------------------------ queries

    def puck_at(self, point_m: Sequence[float], within_m: float = 0.0) -> Puck | None:
        """The puck under `point_m` (the last created, i.e. drawn on top); else the one whose edge is
        nearest it if that is within `within_m` (a click beside a small puck); else None."""
        p = as_vector(point_m, "point_m")
        if self.n_pucks == 0:
            return None
        d = self.pos_m - p
        inside = np.flatnonzero(vectors.squared_lengths(d) <= self.radius_m**2)
        if len(inside):
            return self.puck_handles[int(inside[-1])]
        gap = vectors.lengths(d) - self.radius_m
        nearest = int(np.argmin(gap))
        return self.puck_handles[nearest] if gap[nearest] <= within_m else None

    def springs_on(self, puck: Puck) -> tuple[Spring, ...]:
        """The springs attached to `puck`, in creation order."""
        return tuple(s for s in self.spring_handles if s.p1 is puck or s.p2 is puck)

    def kinetic_energy_J(self) -> float:
        return kinetic_energy_J(self.mass_kg, self.vel_mps)

    def spring_energy_J(self) -> float:
        """Elastic energy stored in the springs, sum of k (d - L)^2 / 2, with the k the step uses."""
        if self.n_springs == 0:
            return 0.0
        stretch = self.spring_stretch_m()
        return float(0.5 * np.dot(self.spring_k_effective_Npm, stretch * stretch))

    def gravity_energy_J(self) -> float:
        """m g y summed over pucks (floor at y = 0); 0 while gravity is off."""
        if not self.gravity_on:
            return 0.0
        return float(self.gravity_mps2 * np.dot(self.mass_kg, self.pos_m[:, 1]))

    def momentum_Ns(self) -> np.ndarray:
        return self.mass_kg @ self.vel_mps if self.n_pucks else np.zeros(2)

    def center_of_mass_m(self) -> np.ndarray:
        """Mass-weighted mean position (the table centre when there are no pucks)."""
        if self.n_pucks == 0:
            return 0.5 * self.size_m
        return self.mass_kg @ self.pos_m / self.mass_kg.sum()

    def center_of_mass_vel_mps(self) -> np.ndarray:
        if self.n_pucks == 0:
            return np.zeros(2)
        return self.momentum_Ns() / self.mass_kg.sum()

    @property
    def last_collisions(self) -> Collisions:
        """What the puck-puck collisions of the last step did (collision.Collisions)."""
        if self._last_collisions is None:  # joined on first read: most steps nobody asks
            self._last_collisions = Collisions.of_records(self._last_records)
        return self._last_collisions

    def last_collisions_later(self) -> Callable[[], Collisions] | None:
        """The last step's collisions as a function that joins them when first called; None if it had none.

        For whoever keeps each step's collisions in case they are wanted (the momenta diagram): a
        10000-puck gas collides some 600 times a step, and joining them all is a tenth of a millisecond.
        """
        if self._last_collisions is not None or not any(r.count for r in self._last_records):
            c = self._last_collisions
            return None if c is None or len(c) == 0 else lambda: c
        records = self._last_records
        return functools.cache(lambda: Collisions.of_records(records))

    def restore_settings(self, names: tuple[str, ...], values: tuple) -> None:
        """Storage.restore_settings; a restored table reports no collisions until it steps."""
        super().restore_settings(names, values)
        self._last_records, self._last_collisions = [], None

    # ------------------------------------------------------------ the step

    def step(self, dt_s: float, pulls: Sequence[Pull] = ()) -> None:
        """Advance the simulation by dt_s seconds, stage by stage (step.py).

        `pulls` are the cursor strings acting during this step (forces.Pull).
        """
        dt = float(dt_s)
        if not (math.isfinite(dt) and dt >= 0.0):
            raise ValueError(f"dt_s must be zero or a positive number of seconds, not {dt_s!r}")
        self._last_records, self._last_collisions = stepping.step(self, dt, pulls).records, None

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
        if self.n_springs:
            a, b, f1 = integrate.spring_forces(self, dt_s)
            total = f1[a == row].sum(axis=0) - f1[b == row].sum(axis=0)
            if (a == row).any() or (b == row).any():
                out["springs"] = total
        if self.gravity_on:
            out["gravity"] = np.array([0.0, -self.mass_kg[row] * self.gravity_mps2])
        return out
