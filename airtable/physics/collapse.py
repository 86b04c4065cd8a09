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
(the contacts that push) with a least-squares solve each, not by iterating:
for a light puck between heavy ones, sequential impulses converge as slowly
as the hits themselves.
"""

from __future__ import annotations

import numpy as np

# Active sets tried per contact before giving up on an exact answer (then the best so far, clipped).
TRIES_PER_CONTACT = 3


def impulses(n: np.ndarray, vn: np.ndarray, a: np.ndarray, b: np.ndarray, inv_mass: np.ndarray) -> np.ndarray:
    """The impulse (N s, >= 0) of each contact k between body a[k] and body b[k] (b[k] < 0: a wall,
    which never moves) along the unit normal n[k] (complex, from b to a), whose relative normal
    velocity is vn[k] (m/s, negative: approaching), so that none approaches after them.

    inv_mass: 1 / mass of each body (kg^-1), indexed by a and b.
    """
    m = len(vn)
    jac = np.zeros((m, 2 * len(inv_mass)))  # each contact's normal on body a, minus it on body b
    rows = np.arange(m)
    jac[rows, 2 * a], jac[rows, 2 * a + 1] = n.real, n.imag
    wall = b < 0
    on_b = np.where(wall, 0, b)
    jac[rows, 2 * on_b] -= np.where(wall, 0.0, n.real)
    jac[rows, 2 * on_b + 1] -= np.where(wall, 0.0, n.imag)
    a_mat = (jac * np.repeat(inv_mass, 2)) @ jac.T  # relative normal velocity change per unit impulse
    active = vn < 0.0
    best = np.zeros(m)
    tol = 1e-12 * (float(np.abs(vn).max()) + 1e-300)
    for _ in range(TRIES_PER_CONTACT * m + 1):
        p = np.zeros(m)
        if active.any():
            sub = np.ix_(active, active)
            p[active] = np.linalg.lstsq(a_mat[sub], -vn[active], rcond=None)[0]
        if (p < -tol).any():  # a contact that would pull: it lets go
            active[np.argmin(p)] = False
            continue
        best = np.maximum(p, 0.0)
        after = vn + a_mat @ best
        closing = ~active & (after < -tol)
        if not closing.any():
            break
        active[np.argmin(np.where(closing, after, np.inf))] = True  # the one approaching most pushes too
    return best
