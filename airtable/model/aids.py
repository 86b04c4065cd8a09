"""Teaching aids: the numbers behind what the window shows (no pygame).

The physics exposes what it did (AirTable.last_collisions, energies,
forces_on); this module keeps short histories of those numbers for drawing:
collision annotations that fade, and the energy strip chart.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from airtable.model.readout import SceneScale
from airtable.physics.table import AirTable

SLOW_MOTION_FACTORS = (1.0, 1 / 2, 1 / 4, 1 / 8, 1 / 16)
ANNOTATION_LIFE_S = 3.0
ANNOTATION_FADE_S = 1.0  # full strength, then fading over the last second
MAX_ANNOTATIONS = 4  # a gas makes hundreds a second; show the newest few
WIGGLE_WINDOW_S = 2.0
CHART_WINDOW_S = 10.0


@dataclass(frozen=True)
class TargetPush:
    """How the target (the slower puck) was pushed, against a push along the first-contact normal."""

    actual_deg: float  # between its push and the incoming relative path
    ideal_deg: float  # the same, had the normal been the line of centres at first contact
    pos_m: tuple[float, float]  # the target after the collision
    push_dir: tuple[float, float]  # unit
    ideal_dir: tuple[float, float]  # unit


@dataclass(frozen=True)
class Annotation:
    """One puck-puck collision as the physics computed it, plus when it was seen."""

    born_s: float  # app clock (real seconds), for fading
    contact_m: tuple[float, float]
    normal: tuple[float, float]  # unit, from puck j to puck i
    overlap_m: float  # overlap when detected
    separation_m: float  # gap after the correction (negative: still overlapping)
    pos_i_before: tuple[float, float]
    pos_j_before: tuple[float, float]
    pos_i_after: tuple[float, float]
    pos_j_after: tuple[float, float]
    radius_i_m: float
    radius_j_m: float
    angle_deg: float | None  # between the two outgoing paths, for an equal-mass hit on a still puck
    # The target (the slower puck) is pushed along the normal the physics used; with a
    # perfect contact normal it would be pushed along the line of centres at first
    # contact, asin(b / (r_i + r_j)) off the incoming path, b the miss distance.
    target: TargetPush | None = None

    @property
    def ratio(self) -> float | None:
        """separation / overlap: 1.0000 for the two-step correction."""
        return self.separation_m / self.overlap_m if self.overlap_m > 0 else None

    def alpha(self, now_s: float) -> float:
        """1 while fresh, fading to 0 over the last ANNOTATION_FADE_S of its life."""
        left = ANNOTATION_LIFE_S - (now_s - self.born_s)
        return min(1.0, max(0.0, left / ANNOTATION_FADE_S))


def _tuple(v) -> tuple[float, float]:
    return (float(v[0]), float(v[1]))


def _paths_angle_deg(c, k: int, m_i: float, m_j: float) -> float | None:
    """Angle between the outgoing paths of an equal-mass hit on a still puck (90 degrees, elastic)."""
    vi0, vj0 = c.vel_i_before[k], c.vel_j_before[k]
    still = min(np.hypot(*vi0), np.hypot(*vj0)) <= 1e-9 * max(np.hypot(*vi0), np.hypot(*vj0), 1e-300)
    if abs(m_i - m_j) > 1e-9 * max(m_i, m_j) or not still:
        return None
    vi, vj = c.vel_i_after[k], c.vel_j_after[k]
    si, sj = np.hypot(*vi), np.hypot(*vj)
    if si <= 1e-9 or sj <= 1e-9:  # a head-on hit leaves one puck still: no angle
        return None
    return math.degrees(math.acos(float(np.clip(np.dot(vi, vj) / (si * sj), -1.0, 1.0))))


def target_push(c, k: int, reach_m: float) -> TargetPush | None:
    """The target's push in collision k of `c`, or None when nothing moved.

    Its change of velocity points along the normal the physics used; the ideal
    normal is the line of centres at first contact, asin(b / reach) off the
    incoming path, where b is how far the centres' relative path misses (b = 0
    head on). On the Shift demos: 29.4 against 14.5 degrees (asin 0.25).
    """
    vi0, vj0 = np.asarray(c.vel_i_before[k]), np.asarray(c.vel_j_before[k])
    v_rel = vi0 - vj0
    speed = float(np.hypot(*v_rel))
    if speed <= 1e-12 or reach_m <= 0:
        return None
    target_i = np.hypot(*vi0) < np.hypot(*vj0)
    # Seen from the target, the other puck comes in along `u`.
    u = -v_rel / speed if target_i else v_rel / speed
    push = (np.asarray(c.vel_i_after[k]) - vi0) if target_i else (np.asarray(c.vel_j_after[k]) - vj0)
    push_len = float(np.hypot(*push))
    if push_len <= 1e-12:
        return None
    push = push / push_len
    d = np.asarray(c.pos_i_before[k]) - np.asarray(c.pos_j_before[k])
    d = d if target_i else -d  # from the other puck to the target
    side = d - np.dot(d, u) * u  # the target's offset across the incoming path
    miss = min(float(np.hypot(*side)), reach_m)
    ideal = (math.sqrt(reach_m**2 - miss**2) * u + side) / reach_m
    return TargetPush(
        actual_deg=math.degrees(math.acos(min(1.0, abs(float(np.dot(push, u)))))),
        ideal_deg=math.degrees(math.asin(miss / reach_m)),
        pos_m=_tuple(c.pos_i_after[k] if target_i else c.pos_j_after[k]),
        push_dir=_tuple(push),
        ideal_dir=_tuple(ideal / max(float(np.hypot(*ideal)), 1e-300)),
    )


def loses_energy(table: AirTable) -> bool:
    """Whether anything on `table` loses energy: a spring's damper, a bounce below restitution 1."""
    return bool(np.any(table.spring_damper_Nspm)) or table.cr_puck < 1.0 or table.cr_wall < 1.0


def annotations_from(table: AirTable, now_s: float, newest: int = MAX_ANNOTATIONS) -> list[Annotation]:
    """Annotations for the last `newest` collisions of the table's last step."""
    c = table.last_collisions
    out = []
    for k in range(max(0, len(c) - newest), len(c)):
        i, j = int(c.i[k]), int(c.j[k])
        angle = _paths_angle_deg(c, k, table.mass_kg[i], table.mass_kg[j])
        target = target_push(c, k, float(table.radius_m[i] + table.radius_m[j]))
        out.append(
            Annotation(
                born_s=now_s,
                contact_m=_tuple(c.contact_m[k]),
                normal=_tuple(c.normal[k]),
                overlap_m=float(c.overlap_m[k]),
                separation_m=float(c.separation_m[k]),
                pos_i_before=_tuple(c.pos_i_before[k]),
                pos_j_before=_tuple(c.pos_j_before[k]),
                pos_i_after=_tuple(c.pos_i_after[k]),
                pos_j_after=_tuple(c.pos_j_after[k]),
                radius_i_m=float(table.radius_m[i]),
                radius_j_m=float(table.radius_m[j]),
                angle_deg=angle,
                target=target,
            )
        )
    return out


class CollisionLog:
    """The newest collision annotations, dropping those that have faded."""

    def __init__(self) -> None:
        self.items: list[Annotation] = []

    def add(self, table: AirTable, now_s: float) -> None:
        if len(table.last_collisions):
            self.items.extend(annotations_from(table, now_s))
            del self.items[:-MAX_ANNOTATIONS]

    def live(self, now_s: float) -> list[Annotation]:
        self.items = [a for a in self.items if a.alpha(now_s) > 0.0]
        return self.items

    def clear(self) -> None:
        self.items = []


class EnergyChart:
    """A ring buffer of energy and momentum samples, one per physics step."""

    FIELDS = ("time_s", "kinetic_J", "spring_J", "gravity_J", "total_J", "momentum_Ns")

    def __init__(self, capacity: int = 8192) -> None:
        self._data = np.zeros((capacity, len(self.FIELDS)))
        self._next = 0
        self._count = 0
        self.scale = SceneScale()  # the scene's round-off scale: readouts show less than it as 0
        self.version = 0  # counts the times samples were taken back (clear, drop_after), for the students' copies

    def clear(self) -> None:
        self._next = self._count = 0
        self.scale.clear()
        self.version += 1

    def sample(self, table: AirTable) -> None:
        ke, se, ge = table.kinetic_energy_J(), table.spring_energy_J(), table.gravity_energy_J()
        p = table.momentum_Ns()
        size = float(np.hypot(p[0], p[1]))
        self._data[self._next] = (table.time_s, ke, se, ge, ke + se + ge, size)
        self._next = (self._next + 1) % len(self._data)
        self._count = min(self._count + 1, len(self._data))
        self.scale.observe((ke, se, ge), size, float(table.mass_kg.sum()))

    def append(self, row) -> None:
        """One sample made elsewhere (a student's window gets the teacher's, at the time of the snapshot it came
        with): the values of FIELDS. The same sample again (two frames between steps) is taken once, and one
        from before the last is left out: the teacher looks back at a moment it has charted, its chart as it
        was (a user test: the students' went blank). Running on from there, or a restart, takes samples back
        from the teacher's chart, and its history comes again (`version`)."""
        if self._count and row[0] <= self._data[(self._next - 1) % len(self._data), 0]:
            return
        self.scale.observe(row[1:4], row[5])
        self._data[self._next] = row
        self._next = (self._next + 1) % len(self._data)
        self._count = min(self._count + 1, len(self._data))

    def drop_after(self, t_s: float) -> None:
        """Forget the samples later than `t_s` (the table was rewound to it and runs on)."""
        count = self._count
        while self._count and self._data[(self._next - 1) % len(self._data), 0] > t_s:
            self._next = (self._next - 1) % len(self._data)
            self._count -= 1
        self.version += self._count != count

    def series(self, window_s: float = CHART_WINDOW_S) -> dict[str, np.ndarray]:
        """The samples of the last `window_s` seconds of simulation, oldest first."""
        if self._count == 0:
            return {f: np.zeros(0) for f in self.FIELDS}
        idx = (self._next - self._count + np.arange(self._count)) % len(self._data)
        rows = self._data[idx]
        rows = rows[rows[:, 0] >= rows[-1, 0] - window_s]
        return {f: rows[:, k] for k, f in enumerate(self.FIELDS)}

    def latest(self) -> dict[str, float]:
        """The newest sample, round-off shown as 0 (readout.py), and the scene's scales (`energy_scale_J`,
        `momentum_scale_Ns`) for the chart's axes."""
        scales = {"energy_scale_J": self.scale.energy_J, "momentum_scale_Ns": self.scale.momentum_Ns}
        if self._count == 0:
            return {**{f: 0.0 for f in self.FIELDS}, **scales}
        row = self._data[(self._next - 1) % len(self._data)]
        values = {f: self.scale.energy(row[k]) for k, f in enumerate(self.FIELDS)}
        values["time_s"], values["momentum_Ns"] = float(row[0]), self.scale.momentum(row[-1])
        return {**values, **scales}

    def euler_wiggle_note(self, springs: bool, lossy: bool) -> str | None:
        """One line explaining the swing of the total, when springs make it visible (`springs`: the table
        has some) and nothing on the table loses energy (`lossy`: loses_energy): else the total's changes
        are real losses. A student's window knows the springs but not the dampers (its scene has no
        such column: asking it for one failed every frame of the spring demo, a user test); a loss shows
        there as a drift of the total."""
        wiggle = self.total_wiggle(WIGGLE_WINDOW_S)
        if not springs or lossy or not (2e-3 < wiggle < 0.2) or self.total_drifts(WIGGLE_WINDOW_S):
            return None
        return (
            f"The total swings by {100 * wiggle:.2g} % but does not drift: semi-implicit Euler "
            "keeps a nearby energy exactly, so E wiggles by about omega dt / 2."
        )

    def total_drifts(self, window_s: float = CHART_WINDOW_S) -> bool:
        """True when the total moves on (a damper, friction) rather than only swinging about a level."""
        total = self.series(window_s)["total_J"]
        if len(total) < 6:
            return False
        third = len(total) // 3
        trend = abs(float(np.mean(total[-third:]) - np.mean(total[:third])))
        return trend > 0.2 * float(total.max() - total.min())

    def total_wiggle(self, window_s: float = CHART_WINDOW_S) -> float:
        """(max - min) / (2 mean) of the total energy over the window: its relative amplitude."""
        total = self.series(window_s)["total_J"]
        if len(total) < 2 or np.mean(total) <= 0:
            return 0.0
        return float((total.max() - total.min()) / (2.0 * np.mean(total)))


MIN_ARROW_SPEED_MPS = 1e-3  # slower pucks get no arrow: resting pucks stay clean


class VectorScale:
    """A round arrow scale (1, 2 or 5 x 10^k per metre of arrow) that holds for a whole demo.

    It is set by the largest value seen since the demo started and only ever
    grows, so arrows of one demo compare with each other over time; values
    under `floor` (a puck at rest) never set it.
    """

    def __init__(self, target_m: float = 1.0, floor: float = MIN_ARROW_SPEED_MPS) -> None:
        self.target_m = target_m
        self.floor = floor
        self.reset()

    def reset(self) -> None:
        self.largest = 0.0

    def update(self, values: np.ndarray) -> tuple[float, float]:
        """(round amount, metres of arrow per unit) after seeing `values` (N, 2)."""
        if len(values):
            biggest = float(np.max(np.hypot(values[:, 0], values[:, 1])))
            if math.isfinite(biggest) and biggest >= self.floor:
                self.largest = max(self.largest, biggest)
        if self.largest <= 0.0:
            return nice_scale(1.0, self.target_m)
        return nice_scale(self.largest, self.target_m)


def nice_scale(largest: float, target_m: float = 1.0) -> tuple[float, float]:
    """A round quantity (1, 2 or 5 x 10^k) and the metres per unit that draw it `target_m` long.

    Used to scale arrows so the largest is about `target_m` and the legend
    reads "1 m = 2 m/s" rather than "1 m = 1.7372 m/s".
    """
    if not (largest > 0 and math.isfinite(largest)):
        return 1.0, target_m
    exp = math.floor(math.log10(largest))
    for step in (1, 2, 5, 10):
        unit = step * 10.0**exp
        if unit >= largest:
            break
    return unit, target_m / unit
