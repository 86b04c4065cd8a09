"""Pucks stuck together in a squeeze, solved at once: the limit of infinitely many inelastic hits.

Below restitution 1, a light puck squeezed between two heavy ones (or a row
pushed from behind) hits its neighbours ever more often at ever smaller
speeds: the exact run has infinitely many hits in a finite time (inelastic
collapse) and ends with the pucks moving together. events.py lets a pair hit
repeat_max times in a step; after that the pair sticks for the rest of the
step, and each further hit of a stuck pair is solved together with the other
stuck pairs touching it, as one perfectly inelastic collision: no stuck
contact approaches after it, and every impulse pushes. That is where the
hits were heading; leaving them to the overlap correction let the light puck
pass through (a 0.1 kg puck between two 1 kg ones at 100 m/s, restitution 0).

This is a small linear complementarity problem (Catto's contact impulses, or
Baraff's): find impulses p >= 0 with vn + A p >= 0 and p (vn + A p) = 0. A
cluster holds a few contacts, so it is solved exactly by trying active sets
(the contacts that push) with a least-squares solve each (block pivoting),
not by iterating: for a light puck between heavy ones, sequential impulses
converge as slowly as the hits themselves (they are only the fallback).
"""

from __future__ import annotations

import numpy as np

# Active sets tried (a bound: block pivoting settles in a few on these clusters), then Gauss-Seidel sweeps
# from the best one if it has not.
TRIES = 12
SWEEPS = 50


def impulses(n: np.ndarray, vn: np.ndarray, a: np.ndarray, b: np.ndarray, inv_mass: np.ndarray) -> np.ndarray:
    """The impulse (N s, >= 0) of each contact k between body a[k] and body b[k] (b[k] < 0: a wall,
    which never moves) along the unit normal n[k] (complex, from b to a), whose relative normal
    velocity is vn[k] (m/s, negative: approaching), so that none approaches after them.

    inv_mass: 1 / mass of each body (kg^-1), indexed by a and b.
    """
    return solve(response(n, a, b, inv_mass), vn)


def response(n: np.ndarray, a: np.ndarray, b: np.ndarray, inv_mass: np.ndarray) -> np.ndarray:
    """(m, m) how each contact's relative normal velocity changes per unit impulse of each (see impulses)."""
    m = len(n)
    jac = np.zeros((m, 2 * len(inv_mass)))  # each contact's normal on body a, minus it on body b
    rows = np.arange(m)
    jac[rows, 2 * a], jac[rows, 2 * a + 1] = n.real, n.imag
    wall = b < 0
    on_b = np.where(wall, 0, b)
    jac[rows, 2 * on_b] -= np.where(wall, 0.0, n.real)
    jac[rows, 2 * on_b + 1] -= np.where(wall, 0.0, n.imag)
    return (jac * np.repeat(inv_mass, 2)) @ jac.T


def solve(a_mat: np.ndarray, vn: np.ndarray) -> np.ndarray:
    """The impulses p >= 0 with vn + a_mat p >= 0 and p (vn + a_mat p) = 0 (see impulses; a_mat: response)."""
    m = len(vn)
    tol = 1e-12 * (float(np.abs(vn).max()) + 1e-300)
    active, p = vn < 0.0, np.zeros(m)
    for _ in range(TRIES):  # block pivoting: every contact that pulls lets go, every one that closes pushes
        p = np.zeros(m)
        if active.any():
            sub = np.ix_(active, active)
            p[active] = np.linalg.lstsq(a_mat[sub], -vn[active], rcond=None)[0]
        pulls, closing = p < -tol, ~active & (vn + a_mat @ p < -tol)
        if not pulls.any() and not closing.any():
            return np.maximum(p, 0.0)
        active = (active & ~pulls) | closing
    p = np.maximum(p, 0.0)
    for _ in range(SWEEPS):  # (rare) projected Gauss-Seidel from there: every step pushes, none pulls
        for k in range(m):
            if a_mat[k, k] > 0.0:
                p[k] = max(0.0, p[k] - (vn[k] + a_mat[k] @ p) / a_mat[k, k])
    return p
