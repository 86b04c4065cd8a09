"""Contact impulses of many contacts at once, to a tolerance: conjugate gradients that keep impulses >= 0.

The contact stage's problem (contacts.py, collapse.py) is a linear complementarity problem: impulses
p >= 0 such that no contact approaches after them, w = A p + q >= 0, and a contact that pushes stops
exactly there (p w = 0). A is how each contact's relative normal velocity changes per unit impulse of
each (collapse.response); q is the normal velocities before, less the bounds. It is the same as
the least of f(p) = p.A p / 2 + q.p over p >= 0: w is f's gradient.

Sequential impulses (contacts._iterate) pass a push along a chain of contacts about one link an
iteration; a slab of 20 rows landing needs hundreds. Conjugate gradients carry it along the whole chain
(square slabs of 200 to 340 pucks landing: 10 to 300 steps). This is Dostal and Schoberl's MPRGP
(modified proportioning with reduced gradient projections, 2005): conjugate gradients on the contacts
that push, a step that frees a contact that should push (proportioning) when those are wrong by more
than the free ones, and a projected gradient step when a conjugate step would make an impulse pull
(expansion). On a positive semidefinite A (as here: more contacts than ways to move, in a square slab)
it still converges; it stops when every contact is within `tol` of its bound (m/s).

A is never built: A p is "push each contact's bodies by p along its normal, then read the contacts'
relative normal velocities" (`Response`): a dozen numpy calls on the contacts' rows, however many, where
the matrix would be m x m and almost all zeros (a pile's contact shares a body with a handful of others).
"""

from __future__ import annotations

import numpy as np

# The gradient projection's step, as a share of 2 / |A| (the largest step that always descends).
STEP_SHARE = 0.95
# Every this many steps, the worst contact's distance from its bound (in tolerances) must have fallen to
# STALL_SHARE of what it was at the last look, or the solve stops, unsettled: on contacts that depend on each
# other (demo 4's 54 pucks stacked in a grid, struck, 131 contacts) it wandered at 1e-4 to 1e-2 m/s for all its
# 2000 steps, 120 ms a step. (Slabs that settle fall by decades in as many, but not steadily: at 250 steps and
# half, hexagonal slabs of masses three decades apart stopped short and sank 16 mm.)
STALL_STEPS = 500
STALL_SHARE = 0.9


class Response:
    """The map p -> A p (see the module docstring) for contacts k between body a[k] and body b[k] along
    the unit normal n[k] (complex, from b to a); inv[body] = 1 / its mass (0: a wall, a sleeper).

    The problem is solved scaled by the diagonal (each contact's own response, 1 / its pair's reduced mass):
    impulses y = p / scale with scale = A_kk^(-1/2), so that every contact answers a unit push alike (the bound
    y >= 0 is p >= 0). Masses decades apart along a chain still slow it: six decades took 3000 to 10000 steps.
    """

    def __init__(self, n: np.ndarray, a: np.ndarray, b: np.ndarray, inv: np.ndarray) -> None:
        self.n, self.a, self.b, self.inv, self.bodies = n, a, b, inv, len(inv)
        own = inv.take(a) + inv.take(b)
        self.scale = 1.0 / np.sqrt(np.where(own > 0.0, own, 1.0))
        # |scale A scale| is at most its largest row sum of |entries| (Gershgorin): a body shared by
        # contacts k and l adds scale_k scale_l / its mass times |n_k . n_l| <= 1 to row k.
        shared = np.bincount(a, self.scale, self.bodies) + np.bincount(b, self.scale, self.bodies)
        load = inv * shared
        self.norm_bound = float((self.scale * (load.take(a) + load.take(b))).max()) if len(a) else 0.0

    def __call__(self, p: np.ndarray) -> np.ndarray:
        """A p."""
        push = p * self.n
        a, b, k = self.a, self.b, self.bodies
        dv = (np.bincount(a, push.real, k) - np.bincount(b, push.real, k)) * self.inv
        dv = dv + 1j * ((np.bincount(a, push.imag, k) - np.bincount(b, push.imag, k)) * self.inv)
        return (self.n.conjugate() * (dv.take(a) - dv.take(b))).real

    def scaled(self, y: np.ndarray) -> np.ndarray:
        """scale A scale y: the scaled problem's map."""
        return self.scale * self(self.scale * y)


def objective(response: Response, q: np.ndarray, p: np.ndarray) -> float:
    """p.A p / 2 + q.p, which the answer makes least over p >= 0 (the module docstring)."""
    return 0.5 * float(p @ response(p)) + float(q @ p)


def solve(response: Response, q: np.ndarray, start: np.ndarray, tol: float, most: int, stall=True):
    """(p, settled): the impulses p >= 0 of the problem (response: p -> A p; q as in the module docstring)
    from `start`, after at most `most` steps; settled: every contact within `tol` of its bound (m/s). `stall`:
    whether to stop where it comes no nearer (STALL_STEPS; not where the masses differ: there it comes nearer as
    slowly as they differ, and stopped so, hexagonal slabs of masses three decades apart sank 2.6 mm).

    A step is one of three. Proportioning, where the contacts that push not but should (beta) are wrong
    by more than the pushing ones could still move (the reduced free gradient): push those. Else a
    conjugate gradient step on the pushing contacts, as far as the minimum along it or, where that would
    make an impulse pull, as far as it can go and then a projected gradient step (expansion).
    """
    if response.norm_bound <= 0.0:
        return np.zeros_like(q), False
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):  # (a problem with no answer diverges)
        p, settled = _steps(response, q, start, tol, most, STALL_STEPS if stall else most + 1)
    return p, settled and bool(np.isfinite(p).all())


def _steps(response: Response, q: np.ndarray, start: np.ndarray, tol: float, most: int, stall: int):
    """solve's steps; every `stall` steps, the look at whether they came nearer."""
    scale, apply = response.scale, response.scaled
    alpha = 2.0 * STEP_SHARE / response.norm_bound
    tol = tol * scale  # (w_k = g_k / scale_k)
    p = np.maximum(start, 0.0) / scale
    g = apply(p) + q * scale
    q = q * scale
    free = p > 0.0
    phi = np.where(free, g, 0.0)
    direction = phi
    last = np.inf
    for k in range(most):
        beta = np.where(free, 0.0, np.minimum(g, 0.0))
        if (np.abs(phi) <= tol).all() and (-beta <= tol).all():
            return p * scale, True
        if k % stall == 0:  # (k = 0: the first look)
            worst = float((np.maximum(np.abs(phi), -beta) / tol).max())
            if not worst <= STALL_SHARE * last:
                return p * scale, False
            last = worst
        reduced = np.where(free, np.minimum(p / alpha, phi), 0.0)
        if beta @ beta > reduced @ phi:  # proportioning: release the contacts that should push
            image = apply(beta)
            step = (beta @ beta) / (beta @ image)
            p, g = p - step * beta, g - step * image
            free = p > 0.0
            phi = direction = np.where(free, g, 0.0)
            continue
        image = apply(direction)
        curvature = direction @ image
        if curvature <= 0.0:  # (round-off: the pushing contacts' problem is solved)
            return p * scale, False
        step = (g @ direction) / curvature
        shrinks = direction > 0.0
        room = float((p[shrinks] / direction[shrinks]).min()) if shrinks.any() else np.inf
        if step <= room:  # conjugate gradient
            p, g = p - step * direction, g - step * image
            free = p > 0.0
            phi = np.where(free, g, 0.0)
            direction = phi - ((phi @ image) / curvature) * direction
            continue
        # expansion: as far as the pushing contacts may go, then a gradient step projected onto p >= 0
        p, g = np.maximum(p - room * direction, 0.0), g - room * image
        p = np.maximum(p - alpha * np.where(p > 0.0, g, 0.0), 0.0)
        g = apply(p) + q
        free = p > 0.0
        phi = direction = np.where(free, g, 0.0)
    return p * scale, False
