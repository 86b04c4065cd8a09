"""The numbers behind the momenta diagram and the values panel (no pygame).

The momenta diagram, as PhET's Collision Lab draws it: every puck's momentum
m v as an arrow, tip to tail, so the arrow from the first tail to the last
tip is the total; once just before the latest collision and once just after
it, at one shared scale, so a student sees the total come out the same.
"Before" and "after" are the velocities the step's collisions found and left
(a puck's first collision and its last). A collision conserves momentum, so
the totals come out the same whatever else acts in the step: gravity's pull,
a spring, the floor holding a puck up are in neither. (The step's start and
end have them: a puck sliding on the floor into another drew its arrows
pointing down before and flat after; pucks meeting in the air showed
gravity's M g dt as momentum gained.) Only a wall can come between: one hit
by a puck between two of its collisions, or behind a puck resting on it that
a heavier one lands on (it bounces off the wall through it); the diagram
then says what came from outside (lessons_paint.momenta_titles). The pucks
that did not collide have their velocity at the step's end in both.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from airtable.model.readout import SceneScale, figures
from airtable.physics.collision import Collisions
from airtable.physics.table import AirTable, kinetic_energy_J

# Pucks are numbered from 1 wherever the app names one (values, momenta, predict, inspect, the CSV files,
# the numbers drawn on the pucks): puck_number is that numbering, the table's rows count from 0.
FIRST_PUCK_NUMBER = 1
FEW_PUCKS = 6  # the values panel lists every puck up to this many, else the puck under the cursor
MAX_DIAGRAM_PUCKS = 40  # more than this: the diagram draws the pucks that collided (at most this many), and the total


@dataclass(frozen=True)
class MomentaAround:
    """Every puck's momentum (N, 2, in N s) just before and just after the collisions of one step."""

    t_s: float
    before_Ns: np.ndarray
    after_Ns: np.ndarray
    collided: np.ndarray  # (N,) bool: the pucks whose momentum the collisions changed
    colors: np.ndarray  # (N, 3) uint8

    @property
    def total_before_Ns(self) -> np.ndarray:
        return self.before_Ns.sum(axis=0)

    @property
    def total_after_Ns(self) -> np.ndarray:
        return self.after_Ns.sum(axis=0)

    def shown(self) -> np.ndarray:
        """The rows the diagram draws: all of them when there are few; else those that collided, and of
        those, when there are still too many, the MAX_DIAGRAM_PUCKS whose momentum changed most (row order)."""
        n = len(self.before_Ns)
        if n <= MAX_DIAGRAM_PUCKS:
            return np.arange(n)
        rows = np.flatnonzero(self.collided)
        if len(rows) > MAX_DIAGRAM_PUCKS:
            change = self.after_Ns[rows] - self.before_Ns[rows]
            biggest = np.argsort(-np.hypot(change[:, 0], change[:, 1]), kind="stable")[:MAX_DIAGRAM_PUCKS]
            rows = np.sort(rows[biggest])
        return rows

    @cached_property
    def view(self) -> MomentaView:
        """What the diagram draws (made once: the students' AIDS frames send it as it is)."""
        rows = self.shown()
        return MomentaView(
            self.t_s,
            rows,
            self.before_Ns[rows],
            self.after_Ns[rows],
            self.total_before_Ns,
            self.total_after_Ns,
            self.colors[rows],
        )


@dataclass(frozen=True, eq=False)
class MomentaView:
    """The diagram as drawn: the shown rows' momenta before and after (K, 2), the totals of all pucks (2,),
    the rows' colours (K, 3). The teacher's window makes it from MomentaAround; a student's from an AIDS frame."""

    t_s: float
    rows: np.ndarray  # (K,) puck rows
    before_Ns: np.ndarray
    after_Ns: np.ndarray
    total_before_Ns: np.ndarray
    total_after_Ns: np.ndarray
    colors: np.ndarray


def momenta_around_collisions(table: AirTable) -> MomentaAround | None:
    """The momenta around the collisions of the table's last step; None if it had none."""
    seen = _seen(table)
    return None if seen is None else _momenta_around(*seen)


def _seen(table: AirTable) -> tuple | None:
    """What the momenta around the last step's collisions are made of (copied: the table steps on),
    as _momenta_around's arguments; None if the step had no collision."""
    collisions = table.last_collisions_later()  # joined only if the diagram is drawn
    if collisions is None:
        return None
    return float(table.time_s), collisions, table.vel_mps.copy(), table.mass_kg.copy(), table.color_rgb.copy()


def _momenta_around(
    t_s: float, collisions: Callable[[], Collisions], vel_end: np.ndarray, mass_kg: np.ndarray, colors: np.ndarray
) -> MomentaAround:
    """The momenta around the collisions() of a step that ended at t_s with velocities `vel_end`."""
    c = collisions()
    rows = np.stack([c.i, c.j], axis=1).ravel()  # the collisions' pucks, in the order they collided
    found = np.stack([c.vel_i_before, c.vel_j_before], axis=1).reshape(-1, 2)
    left = np.stack([c.vel_i_after, c.vel_j_after], axis=1).reshape(-1, 2)
    _, first = np.unique(rows, return_index=True)
    _, last_from_end = np.unique(rows[::-1], return_index=True)
    last = len(rows) - 1 - last_from_end
    vel_before, vel_after = vel_end.copy(), vel_end.copy()
    vel_before[rows[first]] = found[first]
    vel_after[rows[last]] = left[last]
    collided = np.zeros(len(vel_after), dtype=bool)
    collided[rows] = True
    mass = mass_kg[:, None]
    return MomentaAround(t_s, mass * vel_before, mass * vel_after, collided, colors)


class MomentaLog:
    """The momenta around the latest collision seen (kept until the next one, or a new demo).

    `observe` runs after every step and only keeps what the diagram will need;
    the momenta are worked out when asked for (a 10000-puck gas collides every
    step, and the diagram is drawn at most once a frame, often never)."""

    def __init__(self) -> None:
        self._seen: tuple | None = None  # (_momenta_around's arguments) of the latest collision
        self._latest: MomentaAround | None = None

    def clear(self) -> None:
        self._seen = self._latest = None

    def observe(self, table: AirTable) -> None:
        seen = _seen(table)
        if seen is not None:
            self._seen, self._latest = seen, None

    @property
    def latest(self) -> MomentaAround | None:
        if self._latest is None and self._seen is not None:
            self._latest = _momenta_around(*self._seen)
        return self._latest


def tip_to_tail(momenta_Ns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(tails, tips), each (N, 2): arrow k starts where arrow k - 1 ends; the first starts at 0."""
    tips = np.cumsum(momenta_Ns, axis=0)
    return tips - momenta_Ns, tips


@dataclass(frozen=True)
class ChainFit:
    """How to draw several tip-to-tail chains in boxes of one size, at one shared scale."""

    px_per_Ns: float
    centers_Ns: tuple[tuple[float, float], ...]  # the point of each chain drawn at its box's centre

    def to_px(self, chain: int, points_Ns: np.ndarray, size_px: tuple[int, int]) -> np.ndarray:
        """Points of chain `chain` in pixels from its box's top-left corner (y down on screen)."""
        c = np.asarray(self.centers_Ns[chain])
        d = (np.asarray(points_Ns, dtype=float) - c) * self.px_per_Ns
        return np.column_stack((size_px[0] / 2 + d[..., 0], size_px[1] / 2 - d[..., 1]))


def fit_chains(chains: list[np.ndarray], size_px: tuple[int, int], margin: float = 0.1) -> ChainFit:
    """One scale for every chain (the points of its arrows, in N s) so each fits a box of `size_px`
    with `margin` of the box left on each side; each chain is centred on its own box."""
    usable = np.asarray(size_px, dtype=float) * (1.0 - 2.0 * margin)
    scale, centers = math.inf, []
    for pts in chains:
        pts = np.vstack([np.zeros((1, 2)), np.asarray(pts, dtype=float).reshape(-1, 2)])
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        centers.append((float((lo[0] + hi[0]) / 2), float((lo[1] + hi[1]) / 2)))
        span = hi - lo
        for k in (0, 1):
            if span[k] > 0:
                scale = min(scale, usable[k] / span[k])
    return ChainFit(scale if math.isfinite(scale) else 1.0, tuple(centers))


def puck_number(row: int) -> int:
    """The number a class sees for the puck in table row `row`."""
    return int(row) + FIRST_PUCK_NUMBER


@dataclass(frozen=True)
class PuckValues:
    """What the values panel shows of one puck (or the total of all)."""

    name: str
    mass_kg: float
    speed_mps: float | None  # None for the total: a sum of speeds means nothing
    momentum_Ns: float
    kinetic_J: float
    row: int | None = None  # the puck's table row (None for the total)

    def cells(self) -> tuple[str, str, str, str, str]:
        speed = "" if self.speed_mps is None else figures(self.speed_mps)
        return (self.name, figures(self.mass_kg), speed, figures(self.momentum_Ns), figures(self.kinetic_J))


VALUE_HEADINGS = ("puck", "m kg", "|v| m/s", "|p| N s", "KE J")  # mass, speed, momentum, kinetic energy


def own_scale(mass_kg: np.ndarray, vel_mps: np.ndarray) -> SceneScale:
    """A round-off scale from these pucks alone (when the scene's is not known): their kinetic energy and
    the sum of the sizes of their momenta."""
    scale = SceneScale()
    m, v = np.asarray(mass_kg, dtype=float), np.asarray(vel_mps, dtype=float).reshape(-1, 2)
    scale.observe((kinetic_energy_J(m, v),), float(m @ np.hypot(v[:, 0], v[:, 1])), float(m.sum()))
    return scale


def puck_values(
    mass_kg: np.ndarray, vel_mps: np.ndarray, rows: Sequence[int], scale: SceneScale | None = None
) -> list[PuckValues]:
    """Mass, speed, |momentum| and kinetic energy of each puck (named by its number, as in the CSV);
    `mass_kg` (K,) and `vel_mps` (K, 2) are those of `rows`. Round-off of the scene's `scale` shows as 0
    (a cradle's still pucks keep 1e-13 m/s)."""
    scale = own_scale(mass_kg, vel_mps) if scale is None else scale
    out = []
    for k, row in enumerate(rows):
        m = float(mass_kg[k])
        v = vel_mps[k]
        speed = math.hypot(float(v[0]), float(v[1]))
        speed = speed if scale.momentum(m * speed) else 0.0
        ke = scale.energy(0.5 * m * speed * speed)
        out.append(PuckValues(str(puck_number(row)), m, speed, m * speed, ke, int(row)))
    return out


def every_puck_values(mass_kg: np.ndarray, vel_mps: np.ndarray, scale: SceneScale | None = None) -> list[PuckValues]:
    """Every puck and, if there are several, their total (the teacher's table, or a student's copy of it)."""
    mass_kg, vel_mps = np.asarray(mass_kg, dtype=float), np.asarray(vel_mps, dtype=float).reshape(-1, 2)
    scale = own_scale(mass_kg, vel_mps) if scale is None else scale
    n = len(mass_kg)
    rows = puck_values(mass_kg, vel_mps, range(n), scale)
    if n > 1:
        p = scale.momentum(math.hypot(*(mass_kg @ vel_mps)))  # equal and opposite: 0, not 1e-17
        ke = scale.energy(kinetic_energy_J(mass_kg, vel_mps))
        rows.append(PuckValues("total", float(mass_kg.sum()), None, p, ke))
    return rows


def values_for(table: AirTable, cursor_row: int | None, scale: SceneScale | None = None) -> list[PuckValues]:
    """Every puck and their total when there are few; else the puck under the cursor (none: empty).
    `scale`: the scene's round-off scale (the energy chart keeps it), else one from the pucks shown."""
    n = len(table.pos_m)
    if n <= FEW_PUCKS:
        return every_puck_values(table.mass_kg, table.vel_mps, scale)
    if cursor_row is None:
        return []
    return puck_values(table.mass_kg[[cursor_row]], table.vel_mps[[cursor_row]], [cursor_row], scale)
