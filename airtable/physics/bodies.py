"""Puck and Spring: thin handles onto the state arrays of an AirTable.

The table stores all pucks as rows of numpy arrays (structure of arrays) so the
physics step is vectorised. A handle remembers its row and reads and writes
that row, so demo code can still say `puck.vel_mps = (1, 0)`. Getters return
copies: change a puck through its setters (`p.pos_m += (0.1, 0)` works).
Setters say what they changed, as Box2D's b2Body_SetLinearVelocity wakes the
body: a puck set through its handle wakes at the next step (Storage.touch),
and a new radius wakes every sleeper (the table `changed`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from airtable.physics.colors import rgb
from airtable.physics.storage import positive

if TYPE_CHECKING:
    from airtable.physics.storage import Storage


def as_vector(value, what: str) -> np.ndarray:
    """`value` as a finite float (2,) array, or ValueError naming `what`."""
    try:
        v = np.array(value, dtype=float).reshape(2)
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be a pair of numbers (x, y), not {value!r}") from None
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{what} must be finite, not {value!r}")
    return v


class Puck:
    """A round puck on the table. Create with `AirTable.add_puck`."""

    __slots__ = ("_table", "_index")

    def __init__(self, table: Storage, index: int) -> None:
        self._table = table
        self._index: int | None = index

    @property
    def index(self) -> int:
        """Row of this puck in the table's arrays (changes when pucks are removed)."""
        if self._index is None:
            raise ValueError("this puck was removed from the table")
        return self._index

    @property
    def alive(self) -> bool:
        return self._index is not None

    def is_on(self, table: Storage) -> bool:
        """Whether this puck is on `table` (not removed)."""
        return self._table is table and self._index is not None

    @property
    def pos_m(self) -> np.ndarray:
        return self._table.pos_m[self.index].copy()

    @pos_m.setter
    def pos_m(self, value) -> None:
        self._table.pos_m[self.index] = as_vector(value, "pos_m")
        self._table.touch(self.index)

    @property
    def vel_mps(self) -> np.ndarray:
        return self._table.vel_mps[self.index].copy()

    @vel_mps.setter
    def vel_mps(self, value) -> None:
        self._table.vel_mps[self.index] = as_vector(value, "vel_mps")
        self._table.touch(self.index)

    @property
    def radius_m(self) -> float:
        return float(self._table.radius_m[self.index])

    @radius_m.setter
    def radius_m(self, value: float) -> None:
        """A new radius (m), the mass kept; what sleepers rest on may change: every one wakes."""
        self._table.radius_m[self.index] = positive(value, "radius_m")
        self._table.changed = True

    @property
    def mass_kg(self) -> float:
        return float(self._table.mass_kg[self.index])

    @mass_kg.setter
    def mass_kg(self, value: float) -> None:
        """A new mass (kg), the radius and the velocity kept (a user test expected it to be settable)."""
        self._table.mass_kg[self.index] = positive(value, "mass_kg")
        self._table.touch(self.index)

    @property
    def color(self) -> tuple[int, int, int]:
        return tuple(int(c) for c in self._table.color_rgb[self.index])

    @color.setter
    def color(self, value) -> None:
        self._table.color_rgb[self.index] = rgb(value)

    def __repr__(self) -> str:
        if self._index is None:
            return "<Puck (removed)>"
        x, y = self.pos_m
        return f"<Puck #{self._index} at ({x:.3f}, {y:.3f}) m, r={self.radius_m} m>"


class Spring:
    """A spring with a damper between two pucks. Create with `AirTable.add_spring`."""

    __slots__ = ("_table", "_index", "p1", "p2")

    def __init__(self, table: Storage, index: int, p1: Puck, p2: Puck) -> None:
        self._table = table
        self._index: int | None = index
        self.p1 = p1
        self.p2 = p2

    @property
    def index(self) -> int:
        if self._index is None:
            raise ValueError("this spring was removed from the table (one of its pucks was removed)")
        return self._index

    @property
    def alive(self) -> bool:
        return self._index is not None

    def _get(self, name: str) -> float:
        return float(getattr(self._table, name)[self.index])

    @property
    def length_m(self) -> float:
        return self._get("spring_length_m")

    @property
    def k_Npm(self) -> float:
        return self._get("spring_k_Npm")

    @property
    def k_effective_Npm(self) -> float:
        """The stiffness the step uses: k_Npm unless the spring had to be softened (see AirTable.notices)."""
        return self._get("spring_k_effective_Npm")

    @property
    def damper_Nspm(self) -> float:
        return self._get("spring_damper_Nspm")

    @property
    def width_m(self) -> float:
        return self._get("spring_width_m")

    @property
    def color(self) -> tuple[int, int, int]:
        return tuple(int(c) for c in self._table.spring_color_rgb[self.index])

    def __repr__(self) -> str:
        if self._index is None:
            return "<Spring (removed)>"
        return f"<Spring #{self._index} L={self.length_m} m k={self.k_Npm} N/m>"


class Handles(list):
    """A table's handles (Puck or Spring), in row order: handle k has row k."""

    def renumber(self, remap: np.ndarray) -> None:
        """After rows were deleted (remap: old row -> new row, -1 for deleted): each handle gets its new
        row; those of deleted rows are marked removed and dropped."""
        kept = []
        for h in self:
            h._index = new = int(remap[h._index])
            if new < 0:
                h._index = None
            else:
                kept.append(h)
        self[:] = kept

    def clear(self) -> None:
        for h in self:
            h._index = None
        super().clear()

    def save(self, like: tuple | None = None) -> tuple:
        """The handles in row order (the very objects: a demo's code keeps them)."""
        saved = tuple(self)
        return like if like == saved else saved

    def restore(self, saved: tuple) -> None:
        """The handles of `saved` get their rows back (their place in it); the others are marked removed."""
        for h in self:
            h._index = None
        for row, h in enumerate(saved):
            h._index = row
        self[:] = saved
