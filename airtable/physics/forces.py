"""Forces of one step: pulls (cursor strings), springs and gravity, in newtons.

Gravity is the same acceleration g for every puck, so the step adds g dt to
the velocities directly rather than m g to the forces.

A pull is a spring from a fixed anchor (the cursor) to a puck, plus a drag
-c v on that puck. A spring between two pucks pushes them along their line of
centres: F1 = k (L - d) n - c ((v1 - v2) . n) n on puck 1 and -F1 on puck 2,
with n the unit vector from puck 2 to puck 1.

Explicit and implicit parts. Semi-implicit Euler (v += F/m dt, then
x += v dt) keeps a spring's energy without drift, which the course shows,
but it blows up once a puck's springs are too stiff for its mass: the limit
is per puck, the sum over its springs of k dt^2 / m (and of c dt / m for the
dampers). So each puck gets a budget (EXPLICIT_STIFFNESS, EXPLICIT_DAMPING):
springs within it are taken explicitly, exactly as before, and what a spring
has beyond it is taken implicitly (backward Euler along the spring's current
line, see implicit.py). The force is always the full k and c asked for, so a
spring under load stretches exactly as k says. The implicit part damps every
mode it takes, the slow ones too, so a step first tries substeps short enough
for its springs to be explicit (substeps.py). A pull's drag is always implicit.

Only a spring so stiff that the implicit solve would lose its digits to
round-off (k dt^2 / mu over SOFTENING_LIMIT, mu the pair's reduced mass) is
softened: `effective_spring` says to what, and the table reports it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from airtable.physics import vectors

GRAVITY_MPS2 = 9.8
# Per puck, the springs' sum of k dt^2 / m and of c dt / m taken explicitly
# (Gershgorin: the fastest mode then has omega dt <= 1, well inside the
# limit of 2); the rest is taken implicitly. A pull gets a budget of its own.
EXPLICIT_STIFFNESS = 0.5
EXPLICIT_DAMPING = 0.25
# Beyond k dt^2 / mu (and c dt / mu) this large a spring is softened: the
# implicit solve's matrix would hold numbers 1e16 apart and lose the masses.
SOFTENING_LIMIT = 1e6


@dataclass(frozen=True)
class Pull:
    """A cursor string: a spring k from the fixed point `anchor_m` to the puck in `row`, plus a drag -c v."""

    row: int  # the puck's row in the table's arrays
    anchor_m: tuple[float, float]
    k_Npm: float
    drag_Nspm: float


@dataclass
class Implicit:
    """What one step takes implicitly (see implicit.py), gathered by the force stage.

    `diag` (N, 2): each puck's terms dt c + dt^2 k on each axis (pulls' drag and stiff pulls);
    `lag` (N, 2): the matching -dt k v forces; for springs with an implicit part,
    rows `a`, `b`, unit vectors `n` (from b to a), the weight along n,
    `w` = dt c_i + dt^2 k_i, and `k` = k_i.
    """

    diag: np.ndarray
    lag: np.ndarray
    a: np.ndarray | None = None
    b: np.ndarray | None = None
    n: np.ndarray | None = None
    w: np.ndarray | None = None
    k: np.ndarray | None = None  # the implicit part k_i of each of those springs
    fixed: np.ndarray | None = None  # (N, 2) velocity components a wall sets (implicit.brace_walls) ...
    fixed_dv: np.ndarray | None = None  # ... their velocity changes ...
    fixed_side: np.ndarray | None = None  # ... and +1 where the wall pushes towards +x or +y, -1 the other way

    @classmethod
    def empty(cls, count: int) -> Implicit:
        return cls(np.zeros((count, 2)), np.zeros((count, 2)))

    @property
    def any(self) -> bool:
        return bool(self.diag.any()) or (self.a is not None and len(self.a) > 0)


def pull_forces(pulls: Sequence[Pull], pos: np.ndarray) -> list[tuple[int, np.ndarray, float, float]]:
    """(row, spring force k (anchor - x) in N, drag c in N s/m, k) for each pull."""
    out = []
    for pull in pulls:
        row = pull.row
        if not 0 <= row < len(pos):
            raise ValueError(f"a pull acts on puck row {row}, but the table has {len(pos)} pucks")
        out.append((row, pull.k_Npm * (np.asarray(pull.anchor_m) - pos[row]), pull.drag_Nspm, pull.k_Npm))
    return out


def add_pull_forces(
    force: np.ndarray,
    implicit: Implicit,
    pulls: Sequence[Pull],
    pos: np.ndarray,
    vel: np.ndarray,
    mass: np.ndarray,
    dt_s: float,
) -> None:
    """Add each pull's force k (anchor - x) - c v to `force`; its drag, and its k beyond the budget, to `implicit`."""
    for row, f, c, k in pull_forces(pulls, pos):
        k_implicit = max(0.0, k - EXPLICIT_STIFFNESS * mass[row] / (dt_s * dt_s))
        force[row] += f - c * vel[row]
        implicit.diag[row] += dt_s * c + dt_s * dt_s * k_implicit
        implicit.lag[row] -= dt_s * k_implicit * vel[row]


def reduced_masses(mass: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Each spring's reduced mass m_a m_b / (m_a + m_b): what its k and c act on."""
    m_a, m_b = mass.take(a), mass.take(b)
    return m_a * m_b / (m_a + m_b)


def effective_spring(
    k_Npm: np.ndarray, damper_Nspm: np.ndarray, mu: np.ndarray, dt_s: float
) -> tuple[np.ndarray, np.ndarray]:
    """(k, c) the step uses: as asked, unless beyond SOFTENING_LIMIT for the step and the pair's reduced mass."""
    k = np.minimum(k_Npm, SOFTENING_LIMIT * mu / (dt_s * dt_s))
    c = np.minimum(damper_Nspm, SOFTENING_LIMIT * mu / dt_s)
    return k, c


def explicit_fractions(
    mass: np.ndarray, a: np.ndarray, b: np.ndarray, k: np.ndarray, c: np.ndarray, dt_s: float
) -> tuple[np.ndarray, np.ndarray]:
    """The fraction of each spring's k and c taken explicitly: the most both its pucks' budgets allow."""
    out = []
    for coeff, budget, power in ((k, EXPLICIT_STIFFNESS, 2), (c, EXPLICIT_DAMPING, 1)):
        per_puck = np.bincount(a, coeff, len(mass)) + np.bincount(b, coeff, len(mass))
        limit = budget * mass / dt_s**power
        room = np.ones(len(mass))  # (divided only where over budget: a puck with none would overflow)
        np.divide(limit, per_puck, out=room, where=per_puck > limit)
        out.append(np.minimum(room.take(a), room.take(b)))
    return out[0], out[1]


def spring_forces(
    pos: np.ndarray,
    vel: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    length_m: np.ndarray,
    k: np.ndarray,
    c: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """(unit vectors n, forces on puck a[s]) of each spring s; puck b[s] gets minus the force."""
    n, dist = vectors.unit_vectors(vectors.take(pos, a) - vectors.take(pos, b))
    vn = vectors.dot_rows(vectors.take(vel, a) - vectors.take(vel, b), n)
    return n, (k * (length_m - dist) - c * vn)[:, None] * n


def implicit_springs(
    implicit: Implicit,
    vel: np.ndarray,
    springs: tuple[np.ndarray, np.ndarray, np.ndarray],
    k_i: np.ndarray,
    c_i: np.ndarray,
    dt_s: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Record the springs' implicit parts k_i, c_i in `implicit`; return (a, b, lag force on a).

    The lag force is -dt k_i ((v_a - v_b) . n) n; b gets minus that.

    `springs` is (a, b, n) of each spring. Only the stiffness along the line
    is taken implicitly: the impulses then stay along the lines of centres at
    the start of the step, as in semi-implicit Euler, so angular momentum is
    kept exactly (taking the across-the-line stiffness too made a spinning
    stiff jelly stop within seconds).
    """
    a, b, n = springs
    keep = (k_i > 0.0) | (c_i > 0.0)
    a, b, n, k_i, c_i = a[keep], b[keep], n[keep], k_i[keep], c_i[keep]
    implicit.a, implicit.b, implicit.n = a, b, n
    implicit.w = dt_s * c_i + dt_s * dt_s * k_i
    implicit.k = k_i
    along = vectors.dot_rows(vectors.take(vel, a) - vectors.take(vel, b), n)
    return a, b, -(dt_s * k_i * along)[:, None] * n


def add_spring_forces(force: np.ndarray, a: np.ndarray, b: np.ndarray, f1: np.ndarray) -> None:
    """Add f1 to the pucks a and -f1 to the pucks b, in place (a puck on several springs gets them all)."""
    vectors.add_at(force, a, f1)
    vectors.add_at(force, b, -f1)
