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
converge as slowly as the hits themselves. Where block pivoting goes round
in circles (dependent contacts: a puck wedged under two others and on the
floor), Murty's method, one contact at a time, settles it.
"""

from __future__ import annotations

import numpy as np

# Active sets tried by block pivoting, which settles in a few on most clusters; then Murty's
# single pivots (MURTY_TRIES per contact at most), which settle on any.
TRIES = 12
MURTY_TRIES = 20
# Where contacts are dependent (a puck wedged in a corner under another: more contacts than ways to
# move), the active set's equations may have no exact solution; a compliance this small beside each
# contact's own response (ODE's constraint force mixing) makes the problem strictly convex, with
# one answer, which block pivoting can miss and Murty's method finds.
COMPLIANCE = 1e-10
ROUND_OFF = 1e-12  # of a sum, relative to its largest terms: what an active set may miss by


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
    active = vn < 0.0
    for _ in range(TRIES):  # block pivoting: every contact that pulls lets go, every one that closes pushes
        p = _pushes(a_mat, vn, active, _least_squares)
        wrong = _wrong(a_mat, vn, active, p)
        if not wrong.any():
            return np.maximum(p, 0.0)
        active ^= wrong
    return _murty(a_mat + COMPLIANCE * np.diag(np.diag(a_mat)), vn, active)


def _pushes(a_mat: np.ndarray, vn: np.ndarray, active: np.ndarray, solver) -> np.ndarray:
    """The impulses with which the `active` contacts stop approaching (the others: 0), by solver(A, b)."""
    p = np.zeros(len(vn))
    if active.any():
        p[active] = solver(a_mat[np.ix_(active, active)], -vn[active])
    return p


def _least_squares(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.linalg.lstsq(a, b, rcond=None)[0]


def _wrong(a_mat: np.ndarray, vn: np.ndarray, active: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Which contacts the active set has wrong: an active one that pulls or still approaches (its equations
    had no exact answer), an idle one that approaches; each beyond its round-off."""
    after = vn + a_mat @ p
    off = ROUND_OFF * (np.abs(vn).max() + np.abs(a_mat) @ np.abs(p))  # (the sum's terms: its round-off)
    pulls = p < -ROUND_OFF * np.abs(p).max()
    return np.where(active, pulls | (after < -off), after < -off)


def _murty(a_mat: np.ndarray, vn: np.ndarray, active: np.ndarray) -> np.ndarray:
    """Murty's least-index principal pivoting from `active`: flip the first contact the set has wrong,
    until none is. a_mat is positive definite here, so it ends, at the one answer."""
    p = np.zeros(len(vn))
    for _ in range(MURTY_TRIES * len(vn)):
        p = _pushes(a_mat, vn, active, np.linalg.solve)
        wrong = np.flatnonzero(_wrong(a_mat, vn, active, p))
        if len(wrong) == 0:
            break
        active[wrong[0]] = not active[wrong[0]]
    return np.maximum(p, 0.0)
