"""Forces of one step: pulls (cursor strings), springs and gravity, in newtons.

Gravity is the same acceleration g for every puck, so the step adds g dt to
the velocities directly rather than m g to the forces.

A pull is a spring from a fixed anchor (the cursor) to a puck, plus a drag
-c v on that puck. The drag is applied implicitly by the step (backward
Euler), so it is collected apart from the forces. A spring between two pucks
pushes them along their line of centres: F1 = k (L - d) n - c ((v1 - v2) . n) n
on puck 1 and -F1 on puck 2, with n the unit vector from puck 2 to puck 1.

Springs and pulls stiffer than a step can integrate are softened (see
STIFFNESS_LIMIT), which keeps semi-implicit Euler stable for any mass.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from airtable.physics import vectors

GRAVITY_MPS2 = 9.8
# Springs and pulls are softened to at most this fraction of what a step can
# integrate: k dt^2 / m, and a spring's c dt / m, at most this. A pull's drag
# needs no limit: it is applied implicitly.
STIFFNESS_LIMIT = 0.5


@dataclass(frozen=True)
class Pull:
    """A cursor string: a spring k from the fixed point `anchor_m` to the puck in `row`, plus a drag -c v."""

    row: int  # the puck's row in the table's arrays
    anchor_m: tuple[float, float]
    k_Npm: float
    drag_Nspm: float


def pull_forces(
    pulls: Sequence[Pull], pos: np.ndarray, mass: np.ndarray, dt_s: float
) -> list[tuple[int, np.ndarray, float]]:
    """(row, spring force k (anchor - x) in N, drag c in N s/m) for each pull, k softened for the step."""
    out = []
    for pull in pulls:
        row = pull.row
        if not 0 <= row < len(pos):
            raise ValueError(f"a pull acts on puck row {row}, but the table has {len(pos)} pucks")
        k = min(pull.k_Npm, STIFFNESS_LIMIT * mass[row] / (dt_s * dt_s))
        out.append((row, k * (np.asarray(pull.anchor_m) - pos[row]), pull.drag_Nspm))
    return out


def add_pull_forces(
    force: np.ndarray, drag: np.ndarray, pulls: Sequence[Pull], pos: np.ndarray, mass: np.ndarray, dt_s: float
) -> None:
    """Add each pull's spring force to `force` and its drag coefficient to `drag`, in place."""
    for row, f, c in pull_forces(pulls, pos, mass, dt_s):
        force[row] += f
        drag[row] += c


def spring_forces(
    pos: np.ndarray,
    vel: np.ndarray,
    mass: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    length_m: np.ndarray,
    k_Npm: np.ndarray,
    damper_Nspm: np.ndarray,
    dt_s: float,
) -> np.ndarray:
    """(S, 2) force on puck a[s] of each spring s joining pucks a[s] and b[s]; puck b[s] gets minus that."""
    n, dist = vectors.unit_vectors(vectors.take(pos, a) - vectors.take(pos, b))
    m_a, m_b = mass.take(a), mass.take(b)
    mu = m_a * m_b / (m_a + m_b)  # the pair's reduced mass: what the spring's k and c act on
    k = np.minimum(k_Npm, STIFFNESS_LIMIT * mu / (dt_s * dt_s))
    c = np.minimum(damper_Nspm, STIFFNESS_LIMIT * mu / dt_s)
    vn = vectors.dot_rows(vectors.take(vel, a) - vectors.take(vel, b), n)
    return (k * (length_m - dist) - c * vn)[:, None] * n


def add_spring_forces(force: np.ndarray, a: np.ndarray, b: np.ndarray, f1: np.ndarray) -> None:
    """Add f1 to the pucks a and -f1 to the pucks b, in place (a puck on several springs gets them all)."""
    vectors.add_at(force, a, f1)
    vectors.add_at(force, b, -f1)
