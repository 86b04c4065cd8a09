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

from airtable.physics import contacts
from airtable.physics.storage import non_negative

if TYPE_CHECKING:
    from airtable.physics.context import StepContext
    from airtable.physics.storage import Storage

# A pressed contact (one whose pucks this step's forces push: gravity, springs, pulls)
# approaching slower than this (m/s) rests instead of bouncing: the speed of a 2 mm fall.
# Without it a pile's pucks, shaken at a few cm/s by their neighbours, bounce off each
# other at restitution cr_puck and keep each other shaking; Box2D's threshold is 1 m/s.
PRESSED_REST_MPS = 0.2
# How many times the contact stage may start again with a wider margin (hold).
MARGIN_TRIES = 3


def rest_speeds(table: Storage, ctx: StepContext) -> None:
    """Each puck's rest speeds towards other pucks and towards the walls (ctx.rest, ctx.rest_walls;
    None: all zero), and the walls' with the contacts' hold of last step (ctx.wall_rest).

    The rest speed is rest_speed_mps, and where this step's forces gave the puck a kick,
    PRESSED_REST_MPS and twice the kick; a contact rests when its bounce would be slower
    than that (contacts.rest_for_restitution: at restitution 0, always).
    """
    floor = non_negative(table.rest_speed_mps, "rest_speed_mps")
    if ctx.kick is None and floor == 0.0:
        return  # nothing presses: every contact is a collision, as in the course's model
    rest = np.full(table.n_pucks, floor)
    if ctx.kick is not None:
        kick = np.asarray(ctx.kick)
        np.maximum(rest, np.where(kick > 0.0, np.maximum(2.0 * kick, PRESSED_REST_MPS), 0.0), out=rest)
    ctx.rest = contacts.rest_for_restitution(rest, table.cr_puck)
    ctx.rest_walls = contacts.rest_for_restitution(rest, table.cr_wall)
    ctx.wall_rest = table.contact_solver.wall_rest(ctx.rest_walls)


def hold(table: Storage, ctx: StepContext) -> bool:
    """Hold the resting contacts (contacts.py), from where the step began; return whether there were any.

    The contacts are the pairs and walls within a margin (contacts.margin_m) of each other, as far as
    the pucks may travel towards them at the speeds they have. A puck squeezed out of a wedge (a
    small one under a big one falling) can leave faster than any puck came: if the answer moves a
    puck faster than the margin allowed, the stage starts again with the margin of the answer's
    speeds, so the puck's path meets its new neighbours as contacts (MARGIN_TRIES times at most).
    The pairs it may take are the neighbour list's: a pair within the margin but beyond the list's
    skin is not offered (a step of 1/30 s with a puck at several m/s can leave one out).
    """
    if ctx.rest is None:
        return False
    asleep = None if ctx.sleepers is None else table.puck_columns.view("asleep")
    pucks = (table.pos_m, table.vel_mps, table.radius_m, table.mass_kg)
    solver = table.contact_solver
    rest = (ctx.rest, ctx.dt, asleep)
    if table.puck_collisions:
        candidates = table.neighbour_list.pairs(table.pos_m, table.radius_m)
    else:
        none = np.empty(0, dtype=np.intp)
        candidates = (none, none, np.empty(0))
    margin = contacts.margin_m(table.vel_mps, ctx.dt)
    for tries in range(1, MARGIN_TRIES + 1):
        before = table.pos_m.copy(), table.vel_mps.copy(), solver.save()
        held = solver.solve(*pucks, table.size_m, candidates, *rest, ctx.rest_walls, ctx.began, margin)
        needed = contacts.margin_m(table.vel_mps, ctx.dt)
        if needed - contacts.MARGIN_M <= margin or tries == MARGIN_TRIES:  # a pair left out cannot close its gap
            return held
        table.pos_m[:], table.vel_mps[:] = before[0], before[1]
        solver.restore(before[2])
        margin = needed
    return held
