"""One step of the table, read top to bottom: the course's loop, one stage a line.

Each stage is a function in a file of its own, taking the table (its storage,
storage.py) and the step's context (context.py), which carries what one stage
hands the next: the sleepers, the forces' kick, the rest speeds, the rows the
pairs moved, the collisions' records. The numpy work of each stage is beside
it in the same file, its formulas in collision.py.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from airtable.physics import events, integrate, pairs, quiet, resting, sleep, substeps, walls
from airtable.physics.context import StepContext
from airtable.physics.forces import Pull

if TYPE_CHECKING:
    from airtable.physics.storage import Storage


def step(table: Storage, dt: float, pulls: Sequence[Pull] = ()) -> StepContext:
    """Advance `table` by dt seconds with the cursor strings `pulls`; return the step's context.

    Sleeping pucks are not moved: the step first wakes those something
    disturbed; when every puck sleeps, or the table is quiet (quiet.py), it only
    advances time. Where springs are
    too stiff for dt or many pucks are fast (a gas stirred hot), the step is
    taken in pieces, each the whole loop (substeps.py); the context returned
    is the last piece's, with every piece's collisions.
    """
    table.run_due_events()  # 0. a demo's timed events whose time has come (storage.py)
    if table.quiet is not None and table.quiet.holds(table, pulls):  # 0a. nothing moves, nothing acts (quiet.py)
        table.time_s += dt
        table.steps += 1
        return StepContext(dt, pulls)
    at_rest = quiet.before_step(table, pulls)
    mode = table.puck_correction if table.puck_collisions else "none"  # (no pair hits: nothing to cut for)
    n = max(substeps.pieces(table.vel_mps, table.radius_m, dt, mode), substeps.for_contacts(table, dt))
    outside = table.force_N.copy() if n > 1 and table.force_N.any() else None  # forces set from outside
    records = []
    for piece in range(n):
        if piece and outside is not None:
            table.force_N[:] = outside  # act in every piece, as they would through the whole step
        ctx = _piece(table, dt / n, pulls)
        records += ctx.records
    ctx.records = records
    table.quiet = quiet.after_step(table, at_rest, len(records) + len(ctx.bounced))
    table.time_s += dt
    table.steps += 1
    return ctx


def _piece(table: Storage, dt: float, pulls: Sequence[Pull]) -> StepContext:
    """The stages of a step of dt, in order."""
    ctx = StepContext(dt, pulls)
    if table.n_pucks and sleep.wake(table, ctx):  # 0b. wake the sleepers something disturbed
        ctx.began = table.pos_m.copy()  # where the step began (the contacts start there)
        if dt > 0.0:
            integrate.forces_and_integrate(table, ctx)  # 1-2. forces; v += F/m dt, x += v dt
        table.force_N[:] = 0.0  # the accumulators hold one step's forces
        resting.rest_speeds(table, ctx)  # below these, contacts rest instead of bouncing
        if dt > 0.0:
            events.hits_in_order(table, ctx)  # 3. wall and pair hits, earliest first
            sleep.wake_hit(table, ctx)
        walls.still_past(table, ctx)  # 3b. what is still past a wall
        pairs.overlapping(table, ctx)  # 4. pairs still overlapping: collide, then part them
        sleep.wake_hit(table, ctx)
        held = resting.hold(table, ctx)  # 5. resting contacts: piles, squeezed pairs
        walls.again(table, ctx, held)  # 6. walls again: parting pairs can push a puck into one
        sleep.fall_asleep(table, ctx)  # 7. pucks still for long enough fall asleep
    return ctx
