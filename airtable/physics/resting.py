"""Stage 5: resting contacts. Pucks that press on each other or on a wall are held up together.

Where this step's forces press a puck (gravity, springs, pulls), its contacts
approaching slower than a rest speed do not bounce: the contact solver
(contacts.py) holds them by impulses, walls and pairs together. The earlier
stages leave such contacts to this one. Nothing presses in a gas: then every
contact is a collision, as in the course's model, and the stage is skipped.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from airtable.physics import broadphase, contacts, events, vectors
from airtable.physics.rest_speeds import RestSpeeds
from airtable.physics.storage import non_negative

if TYPE_CHECKING:
    from airtable.physics.context import StepContext
    from airtable.physics.storage import Storage

# A pressed contact (one whose pucks this step's forces push: gravity, springs, pulls)
# approaching slower than this (m/s) rests instead of bouncing: the speed of a 2 mm fall.
# Without it a pile's pucks, shaken at a few cm/s by their neighbours, bounce off each
# other at restitution cr_puck and keep each other shaking; Box2D's threshold is 1 m/s.
PRESSED_REST_MPS = 0.2
# How many times the contact stage may start again with a wider margin or more pairs (hold): each start may move
# a squeezed puck anew (a light puck in a heap thrown down at dt 1/30 met the pair it passed into at the fourth).
MARGIN_TRIES = 6


def rest_speeds(table: Storage, ctx: StepContext) -> None:
    """The step's rest speeds (ctx.rest, rest_speeds.py; None: every contact collides) and the walls'
    with the contacts' hold of last step (ctx.wall_rest).

    Where this step's forces gave a puck a kick dv, it presses along dv at PRESSED_REST_MPS or twice
    the kick, whichever is more; the table's rest_speed_mps holds in every direction.
    """
    floor = non_negative(table.rest_speed_mps, "rest_speed_mps")
    if ctx.kick is None and floor == 0.0:
        return  # nothing presses: every contact is a collision, as in the course's model
    press = np.zeros(table.n_pucks, dtype=complex)
    if ctx.kick is not None:
        kick = np.broadcast_to(vectors.as_complex(np.ascontiguousarray(ctx.kick, dtype=float)), press.shape)
        size = np.abs(kick)
        pressed = np.flatnonzero(size > 0.0)
        along = kick.take(pressed) / size.take(pressed)
        press[pressed] = along * np.maximum(2.0 * size.take(pressed), PRESSED_REST_MPS)
    ctx.rest = RestSpeeds(press, floor, table.cr_puck, table.cr_wall, table.contact_solver.piled(table.n_pucks))
    ctx.wall_rest = table.contact_solver.wall_rest(ctx.rest.walls)


def hold(table: Storage, ctx: StepContext) -> bool:
    """Hold the resting contacts (contacts.py), from where the step began; return whether there were any.

    The contacts are the pairs and walls within a margin (contacts.margin_m) of each other, as far as
    the pucks may travel towards them at the speeds they have. A puck squeezed out of a wedge (a
    small one under a big one falling) can leave faster than any puck came: if the answer moves a
    puck faster than the margin allowed, the stage starts again with the margin of the answer's
    speeds, so the puck's path meets its new neighbours as contacts; and so too if the answer made a puck
    fast along a path that meets a puck not among the pairs taken (MARGIN_TRIES times at most).
    The pairs it may take are the neighbour list's, and those of the pucks fast enough to pass through
    one in a step (_candidates).
    """
    if ctx.rest is None:
        return False
    asleep = None if ctx.sleepers is None else table.puck_columns.view("asleep")
    pucks = (table.pos_m, table.vel_mps, table.radius_m, table.mass_kg)
    solver = table.contact_solver
    rest = (ctx.rest, ctx.dt, asleep)
    margin = contacts.margin_m(table.vel_mps, ctx.dt)
    none = np.empty(0, dtype=np.intp)
    candidates = _candidates(table, ctx.dt, margin) if table.puck_collisions else (none, none, np.empty(0))
    for tries in range(1, MARGIN_TRIES + 1):
        before = table.pos_m.copy(), table.vel_mps.copy(), solver.save()
        held = solver.solve(*pucks, table.size_m, candidates, *rest, ctx.began, margin)
        if tries == MARGIN_TRIES:
            return held
        needed = contacts.margin_m(table.vel_mps, ctx.dt)
        wider = needed - contacts.MARGIN_M > margin  # a pair left out cannot close its gap
        paths = _along_fast_paths(table, ctx.dt, needed) if table.puck_collisions else (none, none)
        if not wider and not _any_new(len(table.radius_m), candidates, paths):
            return held
        candidates = _union(table.radius_m, candidates, paths)
        table.pos_m[:], table.vel_mps[:] = before[0], before[1]
        solver.retry(before[2])
        margin = max(margin, needed)
    return held


def _candidates(table: Storage, dt: float, margin: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(i, j, reach): the pairs the contact stage may take. The neighbour list holds every pair touching
    where the step ends, and those near it; a pair that meets and would pass through within one step is
    never near where a step ends. So the pucks that move FAST_FRACTION of the smallest radius in a step
    (events.py's fast pucks) are paired too with every puck their motion may bring within reach.
    (At restitution 0 a hit is the contact stage's however fast: a puck at 30 m/s, dt 1/60, passed through
    another, the pair never in the list.)"""
    listed = table.neighbour_list.pairs(table.pos_m, table.radius_m)
    paths = _along_fast_paths(table, dt, margin)
    return _union(table.radius_m, listed, paths) if len(paths[0]) else listed


def _along_fast_paths(table: Storage, dt: float, margin: float) -> tuple[np.ndarray, np.ndarray]:
    """(i, j): the pucks moving FAST_FRACTION of the smallest radius in a step, each with every puck
    their motion in the step (ending where the pucks are) may bring within reach: those within reach
    plus MARGIN_M where the step began, plus as far as the two move towards each other in the step at
    the most (their relative speed, and the stage's pushes). Not only where their straight paths pass
    closest: a wall or a contact may turn a path (a puck falling fast onto the floor beside another, 2 mm
    away, was stopped there and the other slid into it: straight, their paths parted)."""
    pos, vel, radius = table.pos_m, table.vel_mps, table.radius_m
    travel = np.sqrt(vectors.squared_lengths(vel)) * dt
    fast = np.flatnonzero(travel >= events.FAST_FRACTION * float(radius.min()))
    if len(fast) == 0:
        none = np.empty(0, dtype=np.intp)
        return none, none
    fi, fj = broadphase.pairs_near(pos, radius, fast, margin + 2.0 * float(travel.max()))
    d, w = vectors.take(pos, fi) - vectors.take(pos, fj), vectors.take(vel, fi) - vectors.take(vel, fj)
    apart = vectors.squared_lengths(d - w * dt)  # (where the step began)
    closing = np.sqrt(vectors.squared_lengths(w)) + contacts.MAX_PUSH_MPS
    meet = broadphase.pair_reach(radius, fi, fj) + contacts.MARGIN_M + closing * dt
    k = np.flatnonzero(apart < meet * meet)
    return fi.take(k), fj.take(k)


def _any_new(n: int, candidates: tuple, pairs: tuple) -> bool:
    """Whether any of `pairs` (i, j) is not among `candidates` (i, j, ...)."""
    if len(pairs[0]) == 0:
        return False
    return not np.isin(broadphase.pair_keys(n, *pairs[:2]), broadphase.pair_keys(n, *candidates[:2])).all()


def _union(radius: np.ndarray, *pairs: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(i, j, reach) of every pair in any of `pairs` (each (i, j, ...), i < j), each once, in (i, j) order."""
    i, j = broadphase.each_pair_once(len(radius), *(np.concatenate([p[k] for p in pairs]) for k in (0, 1)))
    return i, j, broadphase.pair_reach(radius, i, j)
