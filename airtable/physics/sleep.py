"""Sleeping: pucks at rest in a pile are set aside until something disturbs them.

A pile that has come to rest still costs a full contact solve every step, and
an iterative solver never quite converges: the pucks keep a faint jitter.
Box2D and Chipmunk put bodies to sleep once they have stayed still for a
while; we do the same, puck by puck (Box2D does it per island):

* a puck falls asleep once its speed has stayed under SLEEP_MPS for SLEEP_S
  and every puck touching it has too (or sleeps already). Its velocity is
  then exactly 0 and the step neither moves it nor solves its contacts with
  the walls or with other sleepers: for the awake pucks resting on it, it is
  an immovable body, like a wall. Only under gravity (without it a still
  puck stays still exactly anyway) and never a puck on a spring.
* it wakes when anything touches or moves it: a velocity, position or force
  written from outside (a drag, a throw, reverse time, a restore), a cursor
  string, an awake puck coming to touch it (however slowly), or one already
  touching it moving faster than WAKE_MPS (or pulled, however slowly), or a
  collision that gives it a velocity; and
  with it every sleeper joined to it by touching sleepers (its island, as
  Box2D wakes islands), so that none stays up when what held it moves.
  Everything wakes when the world changes: gravity, the table's size, a puck
  or spring added or removed, a radius, the correction mode (their setters
  mark the table `changed`, storage.py).

The state of sleep is four columns of the pucks: `still` (seconds), `asleep`,
`rest_pos` (where a sleeper sleeps, or where an awake puck's still time
began) and `touched` (set by the puck's setters), so capture and restore keep
it with the rest of a puck's row. The stage's three steps are `wake` (the
step's start), `wake_hit` (after the collisions) and `fall_asleep` (its end).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from airtable.physics import vectors

if TYPE_CHECKING:
    from airtable.physics.context import StepContext
    from airtable.physics.storage import Storage

# A puck slower than this (m/s) for SLEEP_S seconds, all the while within SLEEP_DRIFT_M of
# where that time began, falls asleep (with its neighbours). Box2D's default threshold is
# 0.05 m/s too: a pile's contacts, solved by a few iterations, leave about 0.02 m/s of jitter.
SLEEP_MPS = 0.05
SLEEP_DRIFT_M = 0.005
SLEEP_S = 0.5
# ... unless, touching no other puck, it slides: a lone puck at rest jitters about where its still time
# began, one sliding steadily along the floor (at 1 cm/s: SLEEP_DRIFT_M in SLEEP_S) comes away from there
# by what its speed carries it. Such a puck sleeps only if it came less than half of that, plus this (m).
# (A pile's pucks creep a little every way as they settle: among them the drift alone decides.)
SLEEP_JITTER_M = 1e-4
# A sleeper wakes when an awake puck touching it moves faster than this (m/s).
WAKE_MPS = 0.1
# Extra room (m) in "within reach": what a step moves a puck, plus this.
WAKE_SKIN_M = 1e-3


def written_from_outside(pos, vel, force, rest_pos, sleepers: np.ndarray) -> np.ndarray:
    """The sleepers (rows) given a velocity, position or force since the last step."""
    v, f = vectors.take(vel, sleepers), vectors.take(force, sleepers)
    moved = vectors.take(pos, sleepers) != vectors.take(rest_pos, sleepers)
    touched = (v != 0.0) | (f != 0.0) | moved
    return sleepers.take(np.flatnonzero(touched[:, 0] | touched[:, 1]))


def touching(pos, candidates) -> tuple[np.ndarray, np.ndarray]:
    """The candidate pairs (i, j) that touch: closer than their reach plus WAKE_SKIN_M."""
    ci, cj, reach = candidates
    lim = reach + WAKE_SKIN_M
    touch = np.flatnonzero(vectors.squared_lengths(vectors.take(pos, ci) - vectors.take(pos, cj)) < lim * lim)
    return ci.take(touch), cj.take(touch)


def island(pos, rows: np.ndarray, asleep, candidates) -> np.ndarray:
    """`rows` and every sleeper joined to them by a chain of touching sleepers (Box2D wakes a
    whole island): a sleeper must not stay up in the air when the puck it rests on wakes."""
    i, j = touching(pos, candidates)
    both = np.flatnonzero(asleep.take(i) & asleep.take(j))  # the chains run through sleepers
    i, j = np.concatenate([i.take(both), j.take(both)]), np.concatenate([j.take(both), i.take(both)])
    woken = np.zeros(len(pos), dtype=bool)
    woken[rows] = True
    new = woken & asleep
    for _ in range(len(pos)):  # each pass reaches one more puck along the chains
        reached = j.take(np.flatnonzero(new.take(i)))
        new = np.zeros(len(pos), dtype=bool)
        new[reached] = True
        new &= ~woken
        if not new.any():
            break
        woken |= new
    return np.flatnonzero(woken)


def near_movers(pos, vel, asleep, candidates, dt: float, pulled: np.ndarray = ()) -> np.ndarray:
    """The sleepers (rows) an awake puck may touch in this step, unless it touches them already and is
    neither faster than WAKE_MPS nor pulled by a cursor string (a slow drag pushes too). "May touch":
    within the sum of the radii, plus what the awake puck moves in a step, plus WAKE_SKIN_M.

    A puck that rests on a sleeper touches it already: it wakes nothing. One that comes to touch it,
    however slowly, wakes it, as a contact beginning to touch wakes a body in Box2D: a sleeper is a wall
    to the contacts, and a puck sliding along the floor at 5 cm/s stopped dead at one."""
    ci, cj, reach = candidates
    awake = ~asleep
    pick = np.flatnonzero((awake.take(ci) & asleep.take(cj)) | (awake.take(cj) & asleep.take(ci)))
    if len(pick) == 0:
        return np.empty(0, dtype=np.intp)
    i, j, reach = ci.take(pick), cj.take(pick), reach.take(pick)
    speed = vectors.lengths(vel)
    fast = speed > WAKE_MPS
    fast[pulled] = True
    mover = np.where(awake.take(i), i, j)  # the awake puck of each pair
    squared = vectors.squared_lengths(vectors.take(pos, i) - vectors.take(pos, j))
    lim = reach + speed.take(mover) * dt + WAKE_SKIN_M
    touching = squared < (reach + WAKE_SKIN_M) ** 2
    wake = np.flatnonzero((squared < lim * lim) & (fast.take(mover) | ~touching))
    i, j = i.take(wake), j.take(wake)
    return np.unique(np.where(asleep.take(i), i, j))


def still_for_long(pos, vel, still, anchor, asleep, free, dt: float) -> np.ndarray | None:
    """Count this step into each awake puck's still time; return the mask of pucks still for SLEEP_S
    (`free` ones: no spring or pull), or None if none of them is awake.

    A puck slower than SLEEP_MPS starts its still time (dt) at its position (`anchor`); it grows by
    dt while the puck stays slow and within SLEEP_DRIFT_M of there, and is 0 otherwise. Moving
    pucks keep 0 and their anchor: nothing changes in the columns, so a history of states shares them.
    """
    awake = ~asleep
    slow = awake & (vectors.squared_lengths(vel) < SLEEP_MPS * SLEEP_MPS)
    start = np.flatnonzero(slow & (still == 0.0))
    near = vectors.squared_lengths(pos - anchor) < SLEEP_DRIFT_M * SLEEP_DRIFT_M
    still[np.flatnonzero(slow & near & (still > 0.0))] += dt
    still[np.flatnonzero(awake & ~(slow & near))] = 0.0
    anchor[start] = pos[start]
    still[start] = dt
    ready = (still > SLEEP_S - 1e-9) & free  # a sum of dt: 120 steps of 1/240 s make 0.4999...
    return ready if (ready & awake).any() else None


def sliding_alone(pos, vel, anchor, still, ready, touching_pairs) -> np.ndarray:
    """Which of the `ready` pucks touch no other puck (`touching_pairs`: i, j) and slide (SLEEP_JITTER_M): a
    helper's user test saw lone pucks on the floor under 1.2 cm/s stop dead, 0.5 s after they began, on a
    frictionless table."""
    out = np.zeros(len(pos), dtype=bool)
    i, j = touching_pairs
    alone = ready.copy()
    alone[i] = False
    alone[j] = False
    k = np.flatnonzero(alone)
    drift = vectors.lengths(vectors.take(pos, k) - vectors.take(anchor, k))
    out[k] = drift >= 0.5 * vectors.lengths(vectors.take(vel, k)) * still.take(k) + SLEEP_JITTER_M
    return out


def with_still_neighbours(ready, asleep, touching_pairs) -> np.ndarray:
    """The awake `ready` pucks (rows) every touching neighbour of which (`touching_pairs`: i, j) is ready or
    asleep: they fall asleep."""
    ok = ready | asleep  # a neighbour that lets a puck sleep
    i, j = touching_pairs
    blocked = np.zeros(len(ready), dtype=bool)
    blocked[i.take(np.flatnonzero(~ok.take(j)))] = True
    blocked[j.take(np.flatnonzero(~ok.take(i)))] = True
    return np.flatnonzero(ready & ~asleep & ~blocked)


def wake(table: Storage, ctx: StepContext) -> bool:
    """Wake the sleepers that must wake; return whether any puck is awake (if none, the step only
    advances time). Sets ctx.sleepers to the rows that sleep through this step.

    Every sleeper wakes when the table `changed` (a setting, the pucks or the springs: their setters
    mark it, storage.py). A sleeper wakes, with its island, when its handle's setters touched it, and
    when a velocity, position or force was written into the arrays: numpy arrays written from outside
    run no setter, so those are found by comparing the sleeper with where it sleeps
    (written_from_outside); when a cursor string pulls it, or an awake puck comes fast within reach.
    """
    columns = table.puck_columns
    asleep, marked = columns.view("asleep"), None
    changed, table.changed = table.changed, False
    if table.any_touched:
        touched, table.any_touched = columns.view("touched"), False
        marked = touched.nonzero()[0]
        touched[marked] = False
    if not np.count_nonzero(asleep):
        return True
    if changed or not (table.sleeping and table.gravity_on):
        set_awake(table, np.flatnonzero(asleep), with_island=False)
        return True
    pos, vel = table.pos_m, table.vel_mps
    sleepers = np.flatnonzero(asleep)
    woken = written_from_outside(pos, vel, table.force_N, columns.view("rest_pos"), sleepers)
    if marked is not None:
        woken = np.union1d(woken, marked.take(np.flatnonzero(asleep.take(marked))))
    pulled = np.array([p.row for p in ctx.pulls], dtype=np.intp)
    set_awake(table, np.concatenate([woken, pulled]))
    if np.count_nonzero(asleep) < table.n_pucks:  # someone is awake: is it coming near a sleeper?
        candidates = table.neighbour_list.pairs(pos, table.radius_m)
        set_awake(table, near_movers(pos, vel, asleep, candidates, ctx.dt, pulled))
    sleepers = np.flatnonzero(asleep)
    if len(sleepers) == table.n_pucks:
        return False
    ctx.sleepers = sleepers if len(sleepers) else None
    return True


def set_awake(table: Storage, rows: np.ndarray, with_island: bool = True) -> None:
    """Wake the pucks in `rows` (their still time starts again) and, `with_island`, every sleeper
    touching them, and every one touching those, and so on (see island)."""
    if len(rows) == 0:
        return
    columns = table.puck_columns
    asleep = columns.view("asleep")
    if with_island and len(rows) < table.n_pucks:
        rows = island(table.pos_m, rows, asleep, table.neighbour_list.pairs(table.pos_m, table.radius_m))
    asleep[rows] = False
    columns.view("still")[rows] = 0.0


def wake_hit(table: Storage, ctx: StepContext) -> None:
    """Wake the sleepers a collision gave a velocity (this step's later stages then move them)."""
    if ctx.sleepers is None:
        return
    v = vectors.take(table.vel_mps, ctx.sleepers)
    hit = ctx.sleepers.take(np.flatnonzero((v[:, 0] != 0.0) | (v[:, 1] != 0.0)))
    if len(hit):
        set_awake(table, hit)
        keep = np.flatnonzero(table.puck_columns.view("asleep").take(ctx.sleepers))
        ctx.sleepers = ctx.sleepers.take(keep) if len(keep) else None


def fall_asleep(table: Storage, ctx: StepContext) -> None:
    """Put to sleep the pucks that have been still for long enough (still_for_long), with their neighbours."""
    ctx.sleepers = None
    if not (table.sleeping and table.gravity_on):
        return
    columns, pos, vel = table.puck_columns, table.pos_m, table.vel_mps
    asleep = columns.view("asleep")
    free = np.ones(table.n_pucks, dtype=bool)
    a, b = table.spring_ends
    free[a] = False
    free[b] = False
    free[[p.row for p in ctx.pulls]] = False
    still, anchor = columns.view("still"), columns.view("rest_pos")
    # A puck that hit something in this step is not at rest: a slow one bouncing off a wall stayed within
    # SLEEP_DRIFT_M of where its still time began for SLEEP_S, and fell asleep leaving it.
    hit = [np.array(ctx.bounced, dtype=np.intp), *(r.hit_rows() for r in ctx.records)]
    still[np.concatenate(hit if ctx.moved is None else [*hit, ctx.moved])] = 0.0
    ready = still_for_long(pos, vel, still, anchor, asleep, free, ctx.dt)
    if ready is not None:
        touching_pairs = touching(pos, table.neighbour_list.pairs(pos, table.radius_m))
        ready &= ~sliding_alone(pos, vel, anchor, still, ready, touching_pairs)
        asleep[with_still_neighbours(ready, asleep, touching_pairs)] = True
    sleepers = np.flatnonzero(asleep)
    if len(sleepers):
        vel[sleepers] = 0.0
        anchor[sleepers] = pos[sleepers]
