"""Walls: keep every puck inside the box [0, width] x [0, height] and bounce it off the walls."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from airtable.physics import broadphase, collision, vectors
from airtable.physics.collision import WALL_NORMALS
from airtable.physics.pairs import OVERLAP_SLOP_M

if TYPE_CHECKING:
    from airtable.physics.context import StepContext
    from airtable.physics.storage import Storage


def still_past(table: Storage, ctx: StepContext) -> None:
    """Stage 3b: put back what is still past a wall after the hits (wall_correction off, or resting on
    it); slow pucks are left to the contact stage."""
    bounced, _ = resolve_walls(*_table_walls(table), only=ctx.maybe_past, rest=ctx.wall_rest)
    table.wall_collision_count += bounced


def again(table: Storage, ctx: StepContext, contacts_held: bool) -> None:
    """Stage 6: walls again, since parting pairs can push a puck into a wall: every puck, put on the wall
    without a bounce where it rests, if the contacts held some (`contacts_held`); else only the pucks
    the pair stage moved. A puck wedged between two walls ends the step stopped between them."""
    if stop_wedged(table.pos_m, table.vel_mps, table.radius_m, table.size_m):
        table.notices.say("wedged", WEDGED_NOTICE)
    if contacts_held:
        rest = table.contact_solver.wall_rest(ctx.rest.walls)
        bounced, _ = resolve_walls(*_table_walls(table), rest=rest, hold_slow=True)
    elif ctx.moved is not None:
        bounced, back = resolve_walls(*_table_walls(table), only=ctx.moved)
        if len(back) and table.puck_collisions:
            pushed = off_the_wall(table.pos_m, table.vel_mps, table.radius_m, table.size_m, table.cr_wall, back)
            if pushed:  # (pushed off one wall, a puck may be pushed into another: a narrow table, a corner)
                bounced += resolve_walls(*_table_walls(table), only=np.array(pushed, dtype=np.intp))[0]
    else:
        return
    table.wall_collision_count += bounced


# Said once when a puck is found wedged (a user test: a puck taller than the table stood through both walls,
# and nothing said why it moved along the table only).
WEDGED_NOTICE = (
    "A puck as wide or as tall as the table fits only at its middle across it: it stays there and moves along"
    " the table only."
)


def stop_wedged(pos, vel, radius, size_m) -> bool:
    """Put each puck wedged between two walls (collision.wedged) in the middle between them, stopped across
    them, in place; whether there was one. No hit does it: the hit stage never predicts one there (it would
    come at once, again and again: 100000 hits a step, the app frozen), nor do the contacts hold it (one
    wall against the other)."""
    if len(radius) == 0 or not collision.wedged(float(radius.max()), float(size_m.min())):
        return False  # (the usual case)
    rows, axes = collision.wedged(radius[:, None], size_m).nonzero()
    vel[rows, axes] = 0.0
    pos[rows, axes] = 0.5 * size_m.take(axes)
    return len(rows) > 0


def off_the_wall(pos, vel, radius, size_m, cr_wall: float, rows: np.ndarray) -> list[int]:
    """Pucks overlapping one of `rows` (just put back inside, near the wall they were past: the nearest)
    where the wall backs it: pushed off it by the whole overlap along the line of centres, in place, and
    their speed towards it (the wall's frame) reversed times cr_wall, as if they had hit the wall through
    it: no energy is gained. A row put back beyond a puck that is nearer its wall (mirrored through it)
    goes on the wall instead: the wall backs it there. Returns the pucks pushed.

    A heavy puck pushing a light one into a wall below restitution 1 makes ever faster hits of the two (the
    exact run has infinitely many; at cr_wall 0 the heavy one stops). Pair by pair, each step the pair stage
    pushed the light puck into the wall, the wall put it back into the heavy one, and the overlap grew
    until the heavy one passed through it. The wall backs a puck where taking the overlap along the line of
    centres would put it past the wall: there it cannot give way.
    """
    z, zv = vectors.as_complex(pos), vectors.as_complex(vel)
    pushed = []
    for a in np.unique(rows).tolist():
        za, ra = z.item(a), radius.item(a)
        near = [b for b in broadphase.rows_near(z, radius, za, ra, -OVERLAP_SLOP_M).tolist() if b != a]
        rooms = list(collision.wall_rooms(za.real, za.imag, ra, size_m))
        k = rooms.index(min(rooms))
        if any(vectors.dot(z.item(b) - za, WALL_NORMALS[k]) < 0.0 for b in near):  # put back through b: onto the wall
            z[a] = za = za - rooms[k] * WALL_NORMALS[k]
            rooms[k] = 0.0
        for b in near:
            d = z.item(b) - za
            dist = abs(d)
            if dist == 0.0:
                continue
            n = d / dist  # from a to b
            overlap = ra + radius.item(b) - dist
            if not any(overlap * vectors.dot(n, w) > room for w, room in zip(WALL_NORMALS, rooms, strict=True)):
                continue  # a can give way: the pair stage's push stands
            z[b] += overlap * n
            pushed.append(b)
            vn = vectors.dot(zv.item(b), n)  # towards the wall, a part of it here (a's own motion is a's)
            if vn < 0.0:
                zv[b] -= (1.0 + cr_wall) * vn * n
    return pushed


def _table_walls(table: Storage) -> tuple:
    """resolve_walls' first arguments for the table's pucks and walls."""
    return table.pos_m, table.vel_mps, table.radius_m, table.size_m, table.cr_wall, table.wall_correction


def resolve_walls(
    pos: np.ndarray,
    vel: np.ndarray,
    radius: np.ndarray,
    size_m: np.ndarray,
    cr_wall: float,
    correction: bool,
    only: np.ndarray | None = None,
    rest: np.ndarray | None = None,
    hold_slow: bool = False,
) -> tuple[int, np.ndarray]:
    """Keep every puck inside the box [0, size_m], in place; return (how many bounced, the rows
    that were past a wall: moved, or left for the contact stage).

    `only`, if given, limits the check to those rows (the pucks that moved).
    A puck past a wall is moved back: mirrored by its penetration when
    `correction` is on (where it would be had it bounced at the surface), else
    just placed on the surface. Its normal velocity reverses, times `cr_wall`,
    only if it was moving into that wall.

    `rest`, if given, is each puck's rest speed (m/s; (N,) or (N, 2) per axis): a puck past a wall that
    moves into it no faster than that is left alone, for the contact stage
    (contacts.py) to hold it up without a bounce; with `hold_slow` (the last
    pass, after that stage) it is put on the surface and stopped there
    instead: a resting contact never bounces.
    """
    if len(pos) == 0:
        return 0, np.empty(0, dtype=np.intp)
    p, r = (pos, radius) if only is None else (vectors.take(pos, only), radius.take(only))
    room = room_to_walls(p, r, size_m)
    if len(room) == 0 or room.min() >= 0.0:
        return 0, np.empty(0, dtype=np.intp)  # the usual case: nobody is past a wall
    out = (~(room >= 0.0)).nonzero()[0]  # NaN counts as outside
    if only is not None:
        out = only.take(out)
    past = out
    if rest is not None:
        fast = _fast_ones(pos, vel, radius, size_m, rest, out)
        if hold_slow:
            _hold(pos, vel, radius, size_m, out.take((~fast).nonzero()[0]))
        out = out.take(fast.nonzero()[0])
        if len(out) == 0:
            return 0, past  # a pile's usual case: every puck past a wall rests there
    # `only` may name a row twice (the rows the pairs moved): bounced, and counted, once.
    return _bounce_rows(pos, vel, radius, size_m, cr_wall, correction, np.unique(out)), past


def room_to_walls(pos: np.ndarray, radius: np.ndarray, size_m) -> np.ndarray:
    """Each puck's room between its edge and the nearest wall of the box [0, size_m] (m; negative:
    past it, NaN for a NaN position): the least of its collision.wall_rooms."""
    left, bottom, right, top = collision.wall_rooms(pos[:, 0], pos[:, 1], radius, (float(size_m[0]), float(size_m[1])))
    return np.minimum(np.minimum(left, bottom), np.minimum(right, top))


def _bounce_rows(pos, vel, radius, size_m, cr_wall: float, correction: bool, out: np.ndarray) -> int:
    """Bounce the rows `out` (past a wall) back inside, in place; return how many walls they bounced off."""
    p, v = vectors.take(pos, out), vectors.take(vel, out)
    lo = radius.take(out)[:, None]
    hi = size_m - lo
    below, above = p < lo, p > hi
    into = (below & (v < 0.0)) | (above & (v > 0.0))
    into &= ~collision.wedged(lo, size_m)  # (no hit: stop_wedged stops it there)
    vectors.put(vel, out, np.where(into, collision.bounce(v, cr_wall), v))
    # Mirrored by the penetration; where it moved into the wall, as two-step backs up a pair: back along its
    # path to the surface and on from there at the bounce's speed, cr_wall times the penetration (on the
    # surface at 0: it used to bounce as far as at 1). Without correction, the clamp below puts it on the surface.
    e = np.where(into, cr_wall, 1.0)
    target = np.where(below, (1.0 + e) * lo - e * p, np.where(above, (1.0 + e) * hi - e * p, p)) if correction else p
    # Clamp into [lo, hi]: a mirror of a huge penetration can land past the
    # opposite wall. A puck wider than the table (lo > hi) sits in the middle.
    half = 0.5 * size_m
    vectors.put(pos, out, np.minimum(np.maximum(target, np.minimum(lo, half)), np.maximum(hi, half)))
    return int(np.count_nonzero(into))


def _fast_ones(pos, vel, radius, size_m, rest, out: np.ndarray) -> np.ndarray:
    """Which of the rows `out` (past a wall) move into a wall they are past faster than their rest speed."""
    p, v = vectors.take(pos, out), vectors.take(vel, out)
    lo = radius.take(out)[:, None]
    r = rest.take(out, axis=0)
    r = r[:, None] if r.ndim == 1 else r
    fast = ((p < lo) & (v < -r)) | ((p > size_m - lo) & (v > r))
    return fast[:, 0] | fast[:, 1]


def _hold(pos, vel, radius, size_m, rows: np.ndarray) -> None:
    """Put the rows on the surface of the walls they are past and stop their motion into them."""
    if len(rows) == 0:
        return
    p, v = vectors.take(pos, rows), vectors.take(vel, rows)
    lo = radius.take(rows)[:, None]
    hi = size_m - lo
    into = ((p < lo) & (v < 0.0)) | ((p > hi) & (v > 0.0))
    vectors.put(vel, rows, np.where(into, 0.0, v))
    half = 0.5 * size_m
    vectors.put(pos, rows, np.minimum(np.maximum(p, np.minimum(lo, half)), np.maximum(hi, half)))
