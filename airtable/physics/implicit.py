"""The implicit part of a step: the velocity change dv of every puck, from

    (M + D + sum over springs of B_s) dv = dt F,

a backward-Euler step linearised along each spring's current line. M holds
the masses, D the pulls' terms dt c + dt^2 k (and walls bracing a body, see
AirTable._brace_walls) on each axis, and B_s the 2 x 2
block of spring s, w n n^T, added on its two pucks'
diagonal and subtracted off it (forces.Implicit gathers them). F is the
step's whole force, gravity included, with the lag terms -dt K v.

The matrix is symmetric positive definite, so the step is stable for any k:
a spring far too stiff for the step just holds its pucks at its length. A puck
on no implicit spring needs a division only; the pucks joined by implicit
springs share one small system, solved directly while it is small and by
conjugate gradients, preconditioned with each puck's own 2 x 2 block, beyond
(a 10 x 10 jelly: about 30 iterations, a millisecond a step).
"""

from __future__ import annotations

import numpy as np

from airtable.physics import vectors
from airtable.physics.forces import Implicit

# Up to this many pucks joined by implicit springs, solve the system directly
# (beyond, numpy's solver starts threads that cost more than they save).
DENSE_LIMIT = 50
# Conjugate gradients beyond that: stop at this relative residual, or after
# this many iterations.
CG_TOLERANCE = 1e-8
CG_MAX_ITERATIONS = 200


def velocity_change(mass: np.ndarray, implicit: Implicit, rhs: np.ndarray) -> np.ndarray:
    """(N, 2) dv solving the step's implicit system; `rhs` is dt F."""
    m = mass[:, None] + implicit.diag
    dv = rhs / m
    if implicit.a is None or len(implicit.a) == 0:
        return dv
    rows = coupled_rows(implicit)
    local = np.full(len(mass), -1, dtype=np.intp)
    local[rows] = np.arange(len(rows))
    system = _System(m[rows], local[implicit.a], local[implicit.b], _blocks(implicit.n, implicit.w))
    solve = system.solve_dense if len(rows) <= DENSE_LIMIT else system.solve_cg
    dv[rows] = solve(rhs[rows])
    return dv


def coupled_rows(implicit: Implicit) -> np.ndarray:
    """The rows of the pucks on implicit springs (sorted)."""
    if implicit.a is None:
        return np.empty(0, dtype=np.intp)
    return np.unique(np.concatenate([implicit.a, implicit.b]))


def _blocks(n: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(S, 2, 2) blocks w n n^T."""
    return w[:, None, None] * n[:, :, None] * n[:, None, :]


class _System:
    """The coupled pucks' matrix diag(m) + sum of spring blocks, in local rows 0..P-1 (m is (P, 2): per axis)."""

    def __init__(self, m: np.ndarray, a: np.ndarray, b: np.ndarray, blocks: np.ndarray) -> None:
        self.m, self.a, self.b, self.blocks = m, a, b, blocks

    def solve_dense(self, rhs: np.ndarray) -> np.ndarray:
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
        return np.linalg.solve(matrix, rhs.reshape(-1)).reshape(-1, 2)

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

    def solve_cg(self, rhs: np.ndarray) -> np.ndarray:
        inv = self._preconditioner()
        x = np.einsum("pij,pj->pi", inv, rhs)
        r = rhs - self.apply(x)
        z = np.einsum("pij,pj->pi", inv, r)
        p, rz = z.copy(), float(np.vdot(r, z))
        stop = CG_TOLERANCE**2 * max(float(np.vdot(rhs, rhs)), 1e-300)
        for _ in range(CG_MAX_ITERATIONS):
            if float(np.vdot(r, r)) <= stop:
                break
            ap = self.apply(p)
            alpha = rz / float(np.vdot(p, ap))
            x += alpha * p
            r -= alpha * ap
            z = np.einsum("pij,pj->pi", inv, r)
            rz, rz_old = float(np.vdot(r, z)), rz
            p = z + (rz / rz_old) * p
        return x
