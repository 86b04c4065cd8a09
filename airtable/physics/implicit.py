"""The implicit part of a step: the velocity change dv of every puck, from

    (M + D + sum over springs of B_s) dv = dt F,

a backward-Euler step linearised along each spring's current line. M holds
the masses, D the pulls' terms dt c + dt^2 k on each axis, and B_s the 2 x 2
block w n n^T of spring s, added on its two pucks' diagonal and subtracted
off it (forces.Implicit gathers them). F is the
step's whole force, gravity included, with the lag terms -dt K v. Velocity
components that a wall sets (brace_walls) are known, and solved around.

The matrix is symmetric positive definite, so the step is stable for any k:
a spring far too stiff for the step just holds its pucks at its length. A puck
on no implicit spring needs a division only; the pucks joined by implicit
springs share one small system, solved directly while it is small and by
conjugate gradients, preconditioned with each puck's own 2 x 2 block, beyond
(a 10 x 10 jelly: about 30 iterations, a millisecond a step).
"""

from __future__ import annotations

import numpy as np

from airtable.physics import collision, vectors
from airtable.physics.forces import Implicit

# Up to this many pucks joined by implicit springs, solve the system directly
# (beyond, numpy's solver starts threads that cost more than they save).
DENSE_LIMIT = 50
# Conjugate gradients beyond that: stop at this relative residual, or after
# this many iterations.
CG_TOLERANCE = 1e-8
CG_MAX_ITERATIONS = 200
# Solve again for the springs' turning (correct_for_turning) when the stretch
# it misses holds more than this share of the coupled pucks' kinetic energy.
TURNING_SHARE = 1e-4


def velocity_change(mass: np.ndarray, implicit: Implicit, rhs: np.ndarray) -> np.ndarray:
    """(N, 2) dv solving the step's implicit system; `rhs` is dt F. Components in `implicit.fixed` are given."""
    dv = rhs / (mass[:, None] + implicit.diag)
    fixed = implicit.fixed
    if fixed is not None:
        dv[fixed] = implicit.fixed_dv[fixed]
    if implicit.a is None or len(implicit.a) == 0:
        return dv
    rows = coupled_rows(implicit)
    local = np.full(len(mass), -1, dtype=np.intp)
    local[rows] = np.arange(len(rows))
    system = _System(
        mass[rows, None] + implicit.diag[rows],
        local[implicit.a],
        local[implicit.b],
        _blocks(implicit.n, implicit.w),
        np.zeros((len(rows), 2), dtype=bool) if fixed is None else fixed[rows],
    )
    solve = system.solve_dense if len(rows) <= DENSE_LIMIT else system.solve_cg
    dv[rows] = solve(rhs[rows], dv[rows])
    return dv


def brace_walls(
    pos: np.ndarray,
    vel: np.ndarray,
    dv: np.ndarray,
    radius: np.ndarray,
    walls: tuple[np.ndarray, float],
    implicit: Implicit,
    released: np.ndarray,
    dt: float,
) -> bool:
    """Make the walls part of the solve for pucks on implicit springs that would cross one; return whether any.

    The wall stage bounces one puck at a time, after the step; a puck on
    stiff springs would then be jerked against its neighbours, whose springs
    store the jerk as energy they never had (a stiff jelly landing gained 100
    times its energy). Instead such a puck's velocity into the wall is fixed
    in the solve itself, to -cr_wall times its approach (or to just reach the
    wall, at restitution 0), so the whole body takes the impact in the same
    step. `vel` is the velocity at the start of the step and `dv` the last
    solve's change; `walls` is (table size, cr_wall); components in
    `released` (walls that would have had to pull) stay out. Solve again after a True.
    """
    rows = coupled_rows(implicit)
    if len(rows) == 0:
        return False
    if implicit.fixed is None:
        implicit.fixed, implicit.fixed_dv, implicit.fixed_side = (
            np.zeros(vel.shape, dtype=bool),
            np.zeros(vel.shape),
            np.zeros(vel.shape),
        )
    size_m, cr_wall = walls
    x, r, v0 = pos[rows], radius[rows][:, None], vel[rows]
    v1 = v0 + dv[rows]
    ends = x + v1 * dt
    lo, hi = r, size_m - r
    fresh = ~(implicit.fixed[rows] | released[rows])
    below, above = (ends < lo) & (v1 < 0.0) & fresh, (ends > hi) & (v1 > 0.0) & fresh
    if not (below.any() or above.any()):
        return False
    bounce = collision.bounce(v1, cr_wall)
    target = np.where(below, np.maximum(bounce, (lo - x) / dt), np.minimum(bounce, (hi - x) / dt))
    hit = below | above
    implicit.fixed[rows] |= hit
    implicit.fixed_dv[rows] = np.where(hit, target - v0, implicit.fixed_dv[rows])
    implicit.fixed_side[rows] = np.where(below, 1.0, np.where(above, -1.0, implicit.fixed_side[rows]))
    return True


def wall_impulses(mass: np.ndarray, implicit: Implicit, rhs: np.ndarray, dv: np.ndarray) -> np.ndarray:
    """(N, 2) the impulse (N s) that held each fixed component at its value: (M + D + B) dv - rhs there, else 0."""
    out = np.zeros_like(dv)
    if implicit.fixed is None or not implicit.fixed.any():
        return out
    rows = coupled_rows(implicit)
    local = np.full(len(mass), -1, dtype=np.intp)
    local[rows] = np.arange(len(rows))
    m = mass[rows, None] + implicit.diag[rows]
    system = _System(m, local[implicit.a], local[implicit.b], _blocks(implicit.n, implicit.w), implicit.fixed[rows])
    out[rows] = (system.apply(dv[rows]) - rhs[rows]) * implicit.fixed[rows]
    return out


def correct_for_turning(
    pos: np.ndarray, vel: np.ndarray, mass: np.ndarray, implicit: Implicit, rhs: np.ndarray, dt: float
) -> bool:
    """Add to `rhs` the stretch the solve's first-order lengths miss; return whether it matters (then solve again).

    The solve takes each spring's length at the end of the step as
    d + dt (v_a - v_b) . n, but a spring that turns by an angle t also
    lengthens by about d t^2 / 2. On a spring of 1e7 N/m that unseen stretch
    held as much energy as a whole jelly had, at the moment it hit a wall.
    So with the new velocities `vel`, each implicit spring pulls as well by
    k_i times that stretch, still along n (so angular momentum stays exact).
    """
    a, b, n, k = implicit.a, implicit.b, implicit.n, implicit.k
    if a is None or len(a) == 0:
        return False
    d = vectors.take(pos, a) - vectors.take(pos, b)
    end = d + dt * (vectors.take(vel, a) - vectors.take(vel, b))
    missed = vectors.lengths(end) - vectors.dot_rows(end, n)
    # Worth a second solve only where it is a visible share of the pucks' kinetic energy.
    rows = coupled_rows(implicit)
    kinetic = 0.5 * float(np.dot(mass[rows], vectors.squared_lengths(vel[rows])))
    if 0.5 * float(np.dot(k, missed * missed)) <= TURNING_SHARE * kinetic:
        return False
    pull = (dt * k * missed)[:, None] * n
    vectors.add_at(rhs, a, -pull)
    vectors.add_at(rhs, b, pull)
    return True


def coupled_rows(implicit: Implicit) -> np.ndarray:
    """The rows of the pucks on implicit springs (sorted)."""
    if implicit.a is None:
        return np.empty(0, dtype=np.intp)
    return np.unique(np.concatenate([implicit.a, implicit.b]))


def _blocks(n: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(S, 2, 2) blocks w n n^T."""
    return w[:, None, None] * n[:, :, None] * n[:, None, :]


class _System:
    """The coupled pucks' matrix diag(m) + sum of spring blocks, in local rows 0..P-1 (m is (P, 2): per axis).

    Components marked `fixed` (P, 2) are known (a wall sets them): the
    solves keep them at their given values and solve for the others.
    """

    def __init__(self, m: np.ndarray, a: np.ndarray, b: np.ndarray, blocks: np.ndarray, fixed: np.ndarray) -> None:
        self.m, self.a, self.b, self.blocks, self.fixed = m, a, b, blocks, fixed

    def solve_dense(self, rhs: np.ndarray, given: np.ndarray) -> np.ndarray:
        size = 2 * len(self.m)
        c = np.arange(2)
        # Flat indices of entry (2 p + r, 2 q + s) for the four (p, q) of each spring.
        rows = 2 * np.stack([self.a, self.b, self.a, self.b], axis=1)[:, :, None, None] + c[:, None]
        cols = 2 * np.stack([self.a, self.b, self.b, self.a], axis=1)[:, :, None, None] + c[None, :]
        signs = np.array([1.0, 1.0, -1.0, -1.0])[None, :, None, None]
        weights = signs * self.blocks[:, None, :, :]
        flat = np.broadcast_to(rows * size + cols, weights.shape)
        matrix = np.bincount(flat.ravel(), weights.ravel(), size * size).reshape(size, size)
        matrix[np.arange(size), np.arange(size)] += self.m.reshape(-1)
        b = rhs.reshape(-1).copy()
        known = np.flatnonzero(self.fixed.reshape(-1))
        if len(known):
            values = given.reshape(-1)[known]
            b -= matrix[:, known] @ values
            matrix[known, :] = 0.0
            matrix[:, known] = 0.0
            matrix[known, known] = 1.0
            b[known] = values
        return np.linalg.solve(matrix, b).reshape(-1, 2)

    def apply(self, x: np.ndarray) -> np.ndarray:
        y = self.m * x
        d = vectors.take(x, self.a) - vectors.take(x, self.b)
        f = np.einsum("sij,sj->si", self.blocks, d)
        vectors.add_at(y, self.a, f)
        vectors.add_at(y, self.b, -f)
        return y

    def _preconditioner(self) -> np.ndarray:
        """(P, 2, 2) inverses of each puck's own diagonal block."""
        diag = np.zeros((len(self.m), 2, 2))
        diag[:, 0, 0], diag[:, 1, 1] = self.m[:, 0], self.m[:, 1]
        np.add.at(diag, self.a, self.blocks)
        np.add.at(diag, self.b, self.blocks)
        return np.linalg.inv(diag)

    def solve_cg(self, rhs: np.ndarray, given: np.ndarray) -> np.ndarray:
        """Conjugate gradients on the free components (the fixed ones start at their values and stay)."""
        inv, free = self._preconditioner(), ~self.fixed
        x = np.where(self.fixed, given, np.einsum("pij,pj->pi", inv, rhs))
        r = (rhs - self.apply(x)) * free
        z = np.einsum("pij,pj->pi", inv, r) * free
        p, rz = z.copy(), float(np.vdot(r, z))
        stop = CG_TOLERANCE**2 * max(float(np.vdot(rhs * free, rhs * free)), 1e-300)
        for _ in range(CG_MAX_ITERATIONS):
            if float(np.vdot(r, r)) <= stop or rz <= 0.0:
                break
            ap = self.apply(p) * free
            alpha = rz / float(np.vdot(p, ap))
            x += alpha * p
            r -= alpha * ap
            z = np.einsum("pij,pj->pi", inv, r) * free
            rz, rz_old = float(np.vdot(r, z)), rz
            p = z + (rz / rz_old) * p
        return x
