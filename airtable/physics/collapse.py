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
(the contacts that push) with a linear solve each (block pivoting, starting
from the contacts that pushed in the last step, if known), not by iterating:
for a light puck between heavy ones, sequential impulses converge as slowly
as the hits themselves. Where block pivoting goes round in circles
(dependent contacts: a puck wedged under two others and on the floor), a
safe variant of it (Judice and Pires's: one contact at a time, by Murty's
rule, where the count of wrong ones stops falling) settles it.
"""

from __future__ import annotations

import numpy as np

# Active sets tried by block pivoting, which settles in a few on most clusters; then block pivoting
# made safe (_settle) on the problem made definite, which settles on any, but on a few hundred
# dependent contacts may take hundreds of tries: PIVOTS_PER_CONTACT per contact, PIVOTS at most.
# (Murty's single pivots alone, from where block pivoting stopped, took thousands on a 68-puck heap,
# and stopped at their cap with no answer, which sank the heap 0.4 m into itself.)
TRIES = 12
AFTER_SETTLING = 4
SLACK = 3
PIVOTS_PER_CONTACT = 20
PIVOTS = 100
# Where contacts are dependent (a puck wedged in a corner under another: more contacts than ways to
# move), the active set's equations may have no exact solution; a compliance this small beside each
# contact's own response (ODE's constraint force mixing) makes the problem strictly convex, with
# one answer, which block pivoting can miss and _settle finds.
COMPLIANCE = 1e-10
ROUND_OFF = 1e-12  # of a sum, relative to its largest terms: what an active set may miss by
# Impulses this many times those that would stop each contact on its own are round-off along a
# dependence of contacts (see _pushes), not an answer.
OUT_OF_SCALE = 1e6


def impulses(n: np.ndarray, vn: np.ndarray, a: np.ndarray, b: np.ndarray, inv_mass: np.ndarray) -> np.ndarray:
    """The impulse (N s, >= 0) of each contact k between body a[k] and body b[k] (b[k] < 0: a wall,
    which never moves) along the unit normal n[k] (complex, from b to a), whose relative normal
    velocity is vn[k] (m/s, negative: approaching), so that none approaches after them.

    inv_mass: 1 / mass of each body (kg^-1), indexed by a and b.
    """
    p = solve(response(n, a, b, inv_mass), vn)
    return np.zeros(len(vn)) if p is None else p  # (not met on clusters of a few: the pair stage parts them)


def response(n: np.ndarray, a: np.ndarray, b: np.ndarray, inv_mass: np.ndarray) -> np.ndarray:
    """(m, m) how each contact's relative normal velocity changes per unit impulse of each (see impulses).

    Two contacts act on each other only through a body they share: entry (k, l) sums, over the bodies
    k and l share, the body's 1 / mass times n_k . n_l, signed by the sides (a or b) they touch it on.
    Built from those pairs alone: a pile's contacts share a body with a handful of others each.
    """
    m = len(n)
    out = np.zeros((m, m))
    flat = out.reshape(-1)
    on_wall = b < 0
    np.fill_diagonal(out, inv_mass.take(a) + np.where(on_wall, 0.0, inv_mass.take(np.maximum(b, 0))))
    pucks = np.flatnonzero(~on_wall)
    body = np.concatenate([a, b.take(pucks)])  # each contact's ends on a puck: a always, b unless a wall
    contact = np.concatenate([np.arange(m), pucks])
    side = np.concatenate([n, -n.take(pucks)])  # the normal as it pushes that body
    order = np.argsort(body, kind="stable")
    body, contact, side = body.take(order), contact.take(order), side.take(order)
    for gap in range(1, len(body)):  # ends `gap` apart in body order that share a body (a handful of gaps)
        same = np.flatnonzero(body[gap:] == body[:-gap])
        if len(same) == 0:
            break
        first, second = contact.take(same), contact.take(same + gap)
        value = inv_mass.take(body.take(same)) * (side.take(same) * side.take(same + gap).conjugate()).real
        np.add.at(flat, np.concatenate([first * m + second, second * m + first]), np.concatenate([value, value]))
    return out


def solve(a_mat: np.ndarray, vn: np.ndarray, pushed: np.ndarray | None = None, safe: bool = True) -> np.ndarray | None:
    """The impulses p >= 0 with vn + a_mat p >= 0 and p (vn + a_mat p) = 0 (see impulses; a_mat: response);
    None if the pivoting did not settle within its tries (a few hundred contacts, some dependent).

    pushed: the contacts likely to push (those that pushed in the last step), to start from: a pile's
    active set changes little from step to step, and block pivoting then settles in a try or two.
    safe: where block pivoting does not settle in TRIES, the safe pivoting (_settle) goes on; else None.
    """
    active = vn < 0.0 if pushed is None else (vn < 0.0) | pushed
    p = _block_pivoting(a_mat, vn, active, TRIES)
    return p if p is not None or not safe else _settle(a_mat, vn, active)


def _block_pivoting(a_mat: np.ndarray, vn: np.ndarray, active: np.ndarray, tries: int) -> np.ndarray | None:
    """Block pivoting from `active` (changed in place): every contact that pulls lets go, every one
    that closes pushes; the answer, or None if `tries` sets were wrong or one came round again."""
    tried = set()
    for _ in range(tries):
        p = _pushes(a_mat, vn, active)
        wrong = _wrong(a_mat, vn, active, p)
        if not wrong.any():
            return np.maximum(p, 0.0)
        tried.add(active.tobytes())
        active ^= wrong
        if active.tobytes() in tried:
            break  # round in circles
    return None


def _pushes(a_mat: np.ndarray, vn: np.ndarray, active: np.ndarray, definite: bool = False) -> np.ndarray:
    """The impulses with which the `active` contacts stop approaching (the others: 0).

    By LU, quick. Unless a_mat is `definite` (and LU's answer finite), where LU's answer is out of
    all scale, again by least squares: on dependent contacts (more than the ways their pucks can
    move) LU's equations are singular but for round-off, and its impulses push and pull against each
    other along the dependence, where least squares gives the smallest that stop the contacts."""
    p = np.zeros(len(vn))
    if not active.any():
        return p
    sub, rhs = a_mat[np.ix_(active, active)], -vn[active]
    try:
        p[active] = np.linalg.solve(sub, rhs)
    except np.linalg.LinAlgError:  # (singular to the last bit)
        p[active] = np.nan
    if definite and np.isfinite(p).all():
        return p
    # Stopping each contact on its own takes |vn| / A_kk; a pile passes support along (N pucks: N times
    # that) and a shallow wedge magnifies it (1 / tan of its angle), but not by OUT_OF_SCALE.
    scale = OUT_OF_SCALE * float(np.abs(rhs).sum()) / max(float(np.diag(sub).min()), 1e-300)
    if not np.abs(p).max() <= scale:  # (NaN too)
        p[active] = np.linalg.lstsq(sub, rhs, rcond=None)[0]
    return p


def _wrong(a_mat: np.ndarray, vn: np.ndarray, active: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Which contacts the active set has wrong: an active one that pulls or still approaches (its equations
    had no exact answer), an idle one that approaches; each beyond its round-off."""
    after = vn + a_mat @ p
    off = ROUND_OFF * (np.abs(vn).max() + np.abs(a_mat) @ np.abs(p))  # (the sum's terms: its round-off)
    pulls = p < -ROUND_OFF * np.abs(p).max()
    return np.where(active, pulls | (after < -off), after < -off)


def _settle(a_mat: np.ndarray, vn: np.ndarray, active: np.ndarray) -> np.ndarray | None:
    """Block pivoting from `active` made safe (Judice and Pires, 1994), on a_mat made positive definite
    by COMPLIANCE: every contact the set has wrong flips while their count falls to a new low, or for
    SLACK tries more; else only the first (Murty's least-index rule, which ends on a definite matrix).
    Then block pivoting on the exact a_mat from the set found, which is the answer or near it: the
    exact answer if it settles in AFTER_SETTLING tries, else the soft one, which may leave contacts
    approaching at COMPLIANCE times their own velocity change. None if PIVOTS tries did not settle it."""
    soft = a_mat + COMPLIANCE * np.diag(np.diag(a_mat))
    fewest, slack = len(vn) + 1, SLACK
    for _ in range(min(PIVOTS_PER_CONTACT * len(vn), PIVOTS)):
        p = _pushes(soft, vn, active, definite=True)
        wrong = np.flatnonzero(_wrong(soft, vn, active, p))
        if len(wrong) == 0:
            exact = _block_pivoting(a_mat, vn, active.copy(), AFTER_SETTLING)
            return exact if exact is not None else np.maximum(p, 0.0)
        if len(wrong) < fewest:
            fewest, slack = len(wrong), SLACK
        elif slack:
            slack -= 1
        else:
            wrong = wrong[:1]
        active[wrong] = ~active[wrong]
    return None
