"""The collision formulas, each written once: read these first.

* `collide_1d`: the 1D collision along the normal (momentum kept, the relative
  speed reversed times the restitution); a wall is the same collision with an
  infinitely heavy body at rest (`bounce`);
* `collide_along`: the 2D collision of two pucks: their normal velocities
  collide in 1D, their tangential velocities are kept;
* `contact_time`: when two moving discs first touch (the time of first
  contact, forward or back), and `wall_time`: when a puck reaches a wall;
* `Collisions`: the record of what the collisions of a step did, which the
  log, the momenta panel and the collision aids read.

Every stage calls these: the hits in time order (events.py) for one pair at a
time in Python numbers, the overlapping pairs (pairs.py) and the walls
(walls.py) for many at once in numpy arrays. The same lines serve both: they
use only arithmetic and `vectors.dot`, which takes either.

Vectors are complex numbers x + iy (see vectors.as_complex). Puck 1 and puck 2
touch when their centres are r1 + r2 (their reach) apart. The normal n is the
unit vector from puck 2 to puck 1 along the line of centres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from airtable.physics import vectors

# How a pair stage corrects the positions of a colliding pair (pairs.py; DESIGN.md 3).
CORRECTION_MODES = ("off", "two-step", "perfect-kiss")


def mass_shares(m1, m2):
    """(m2 / (m1 + m2), m1 / (m1 + m2)): each body's part of a change in their relative motion.

    The lighter body takes the larger part, so momentum is kept.
    """
    m_sum = m1 + m2
    return m2 / m_sum, m1 / m_sum


def collide_1d(u1, u2, m1, m2, cr):
    """Speeds (v1, v2) after a 1D collision of masses m1, m2 (kg) arriving at u1, u2 (m/s).

    Momentum is kept and the relative speed reverses, times the restitution cr:
    v1 - v2 = -cr (u1 - u2). The relative speed changes by -(1 + cr)(u1 - u2),
    shared by mass (`mass_shares`). A wall is the limit m2 -> inf, u2 = 0: `bounce`.
    """
    share1, share2 = mass_shares(m1, m2)
    change = -(1.0 + cr) * (u1 - u2)
    return u1 + change * share1, u2 - change * share2


def bounce(u, cr):
    """Speed after hitting a wall at u (m/s, along the wall's normal): -cr u.

    The special case of `collide_1d` for a wall, a body infinitely heavy and at
    rest: as m2 -> inf, share1 -> 1, and v1 = u1 - (1 + cr) u1 = -cr u1.
    """
    return -cr * u


def collide_along(n, v1, v2, m1, m2, cr):
    """Velocities (v1, v2) after two pucks collide along the unit normal n (vectors complex).

    The normal parts collide in 1D (`collide_1d`); the tangential parts are kept.
    """
    u1, u2 = vectors.dot(v1, n), vectors.dot(v2, n)
    w1, w2 = collide_1d(u1, u2, m1, m2, cr)
    return v1 + (w1 - u1) * n, v2 + (w2 - u2) * n


def contact_time(d, w, reach):
    """(t, u): when two discs on straight paths first touch (s from now), and how fast they then
    approach along the line of centres (m/s).

    d = x1 - x2 (m) and w = v1 - v2 (m/s) now, reach = r1 + r2. They touch when
    |d + w t| = reach: w.w t^2 + 2 d.w t + d.d - reach^2 = 0, and first contact is
    the smaller root, written c / (sqrt(disc) - d.w) so that no digits cancel.
    t > 0: they touch in t (events.py); t <= 0: they overlap now and first
    touched -t ago (pairs.py backs them up to then). u = sqrt(disc) / reach.

    The one rule for whether they touch at all: they approach now (d.w < 0) and
    their paths come within reach (disc > 0: more than a graze). Where they do
    not, t = inf and u = 0. One pair (complex d and w) or many (numpy arrays).
    """
    dw = vectors.dot(d, w)
    one = isinstance(dw, float)  # one pair, in Python numbers
    if one and not dw < 0.0:
        return math.inf, 0.0  # parting or still (the rule below, checked first: half the calls stop here)
    c = vectors.dot(d, d) - reach * reach
    disc = dw * dw - vectors.dot(w, w) * c
    meets = (dw < 0.0) & (disc > 0.0)
    if one:  # skip the division where they do not meet
        root = math.sqrt(disc) if meets else 0.0
        return (c / (root - dw) if meets else math.inf), root / reach
    root = np.sqrt(np.where(meets, disc, 0.0))
    return np.where(meets, c / np.where(meets, root - dw, 1.0), np.inf), root / reach


def closest_time_in_step(d: np.ndarray, w: np.ndarray, dt: float) -> np.ndarray:
    """(rows) the t in [0, dt] where two straight paths, d = x1 - x2 apart (m) at w = v1 - v2 (m/s) when a step
    begins, pass closest: d.w < 0 and they close until -d.w / w.w, else they are closest now."""
    return np.clip(-vectors.dot_rows(d, w) / np.maximum(vectors.squared_lengths(w), 1e-300), 0.0, dt)


# The four walls' unit normals pointing into the table (complex x + iy), in each_wall's order:
# left, bottom, right and top.
WALL_NORMALS = (1.0, 1j, -1.0, -1j)


def wall_rooms(x, y, radius, size_m) -> tuple:
    """The room (m; negative: past it) between the edge of a puck of `radius` centred at (x, y) and the
    left, bottom, right and top walls, in that order (WALL_NORMALS'): numbers, or arrays of them."""
    width, height = size_m
    return (x - radius, y - radius, width - x - radius, height - y - radius)


def wedged(radius, size):
    """Whether a puck of `radius` is wedged between two walls `size` apart (2 r >= size: a demo's puck too
    big for the table along an axis, which add_puck centres on it): it cannot move across them, and never
    hits them (numbers, or arrays that broadcast)."""
    return radius + radius >= size


def each_wall(pos: np.ndarray, vel: np.ndarray, radius: np.ndarray, size_m) -> tuple:
    """For the left, bottom, right and top walls, in that order (WALL_NORMALS'): each puck's
    room between its edge and the wall (m; negative: past it) and its speed away from it (m/s)."""
    vx, vy = vel[:, 0], vel[:, 1]
    return tuple(zip(wall_rooms(pos[:, 0], pos[:, 1], radius, size_m), (vx, vy, -vx, -vy), strict=True))


def wall_time(x: float, v: float, lo: float, hi: float) -> float | None:
    """How long until a centre at x moving at v (along one axis) reaches lo (moving down) or hi
    (moving up): where a puck of radius r touches the walls at 0 and size (lo = r, hi = size - r).
    0 if it is there or past already; None if it does not move along this axis."""
    if v < 0.0:
        return max((lo - x) / v, 0.0)
    if v > 0.0:
        return max((hi - x) / v, 0.0)
    return None


@dataclass
class Collisions:
    """What the puck-puck collisions of one step did, for diagnostics and drawing.

    One row per collision (a pair whose velocities were changed): puck rows i
    and j, the contact normal (unit, from j to i), the contact point, the
    overlap when detected (0 for a hit found at its time), the pair's reach
    (sum of the radii) and both pucks' positions and velocities before and
    after this collision. Vectors are (k, 2) rows.
    """

    i: np.ndarray
    j: np.ndarray
    normal: np.ndarray
    contact_m: np.ndarray
    overlap_m: np.ndarray
    reach_m: np.ndarray
    pos_i_before: np.ndarray
    pos_j_before: np.ndarray
    pos_i_after: np.ndarray
    pos_j_after: np.ndarray
    vel_i_before: np.ndarray
    vel_j_before: np.ndarray
    vel_i_after: np.ndarray
    vel_j_after: np.ndarray

    @classmethod
    def of_pairs(cls, i, j, n, touch_j, overlap, reach, r_j, *states) -> Collisions:
        """The record of the pairs (i, j) that collided along n; touch_j: puck j's centre when they
        touched; reach: r_i + r_j; `states`: the positions and velocities before and after, in the
        fields' order. Vectors complex (one per pair): the columns of `PairRecords`."""
        contact = touch_j + r_j * n  # on puck j's edge, along the normal
        n, contact, *states = (vectors.as_rows(np.ascontiguousarray(z)) for z in (n, contact, *states))
        return cls(i, j, n, contact, overlap, reach, *states)

    @classmethod
    def of_records(cls, records: list[PairRecords]) -> Collisions:
        """One record of what the stages kept as they went (PairRecords), made when someone reads it."""
        columns = [r.columns() for r in records if r.count]
        if not columns:
            return cls.empty()
        if len(columns) == 1:
            return cls.of_pairs(*columns[0])
        return cls.of_pairs(*(np.concatenate(c) for c in zip(*columns, strict=True)))

    @property
    def separation_m(self) -> np.ndarray:
        """The gap the position correction left (m); negative: still overlapping."""
        return vectors.lengths(self.pos_i_after - self.pos_j_after) - self.reach_m

    @classmethod
    def empty(cls) -> Collisions:
        z = np.empty(0)
        zi = np.empty(0, dtype=np.intp)
        z2 = np.empty((0, 2))
        return cls(zi, zi, z2, z2, z, z, *([z2] * 8))

    def __len__(self) -> int:
        return len(self.i)

    def take(self, k: np.ndarray) -> Collisions:
        """Only the collisions k (indices into this record)."""
        return Collisions(*(getattr(self, f).take(k, axis=0) for f in self.__dataclass_fields__))


class PairRecords:
    """Pair collisions as a stage resolved them, kept raw: made into `Collisions` only when read.

    Most steps nobody reads them (AirTable.last_collisions), and turning a stage's complex columns
    into rows costs a dozen numpy calls a round. Either numpy columns, with `pick` the indices of
    the pairs that collided (None: all), or `rows`, one tuple per collision (the hits of events.py):
    the fields of `Collisions.of_pairs` in its order, (i, j, n, xj at contact, overlap, reach, rj,
    xi, xj before, xi, xj after, vi, vj before, after).
    """

    __slots__ = ("_columns", "_pick", "_rows", "count")

    def __init__(self, count: int, columns: tuple = (), pick: np.ndarray | None = None, rows: list = ()) -> None:
        self.count = int(count)  # how many collisions (a numpy count is not a plain int: state.py saves it)
        self._columns, self._pick, self._rows = columns, pick, rows

    def hit_rows(self) -> np.ndarray:
        """The rows of the pucks that collided (i, then j; a row may repeat)."""
        if self._rows:
            return np.array([row[k] for k in (0, 1) for row in self._rows], dtype=np.intp)
        i, j = self._columns[0], self._columns[1]
        return np.concatenate((i, j) if self._pick is None else (i.take(self._pick), j.take(self._pick)))

    def columns(self) -> tuple:
        """The fields of `Collisions.of_pairs`, one numpy column each."""
        if self._rows:
            return tuple(np.array(column) for column in zip(*self._rows, strict=True))
        if self._pick is None:
            return self._columns
        return tuple(f.take(self._pick) for f in self._columns)
