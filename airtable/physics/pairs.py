"""Puck pairs: collide the overlapping pairs one pair at a time, then part them.

Sequential resolution matters: each pair sees the velocities left by the pairs
before it, which conserves momentum and (restitution 1) energy to round-off.
To keep that and still vectorise, `disjoint_rounds` splits the pairs into
rounds in which no puck appears twice (a colouring of the graph of pairs that
keeps their order); pairs in one round cannot affect each other, so resolving
a round at once gives exactly the result of resolving its pairs one by one.

A round is resolved by the function of the table's correction mode, all three
built from the same two pieces: `collision.collide_along` (the 1D collision
with restitution along the line of centres; the tangential velocity is kept)
and `separate` (move the pair apart along a normal, then push apart what still
overlaps).

* "off": velocities only; the pucks stay overlapping ("stickiness").
* "two-step": back both pucks up along their normal velocities for the
  penetration time t_p = overlap / |vn|, then forward t_p with the
  post-collision normal velocities: the pair parts by (1 + e) times the
  overlap, so it ends e times the overlap apart (as far apart as it
  overlapped at e = 1, touching at e = 0).
* "perfect-kiss": back the pair up along its full relative motion to the
  moment of first contact (`collision.contact_time`), take the normal there,
  collide, and go forward again by the same time.

One pair or a thousand, a round takes the same path: the formulas are those
of collision.py, on numpy arrays (or, for a round of a few pairs, on Python
numbers one pair at a time: the same lines, the same bits; see "one round").
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from airtable.physics import broadphase, collapse, collision, either, vectors
from airtable.physics.collision import CORRECTION_MODES, PairRecords
from airtable.physics.rest_speeds import RestSpeeds, still_held

if TYPE_CHECKING:
    from airtable.physics.context import StepContext
    from airtable.physics.storage import Storage

# After the first pass over the overlapping pairs, up to this many more passes
# over the pairs the corrections pushed into overlap: collisions again, then a
# last pass that only pushes apart.
EXTRA_PASSES = 2
# Overlaps smaller than this (m) are left to the next step: round-off only.
OVERLAP_SLOP_M = 1e-9

# A round of at most this many pairs is resolved one pair at a time in Python numbers, by the
# same lines (see "one round" below): a round in numpy costs some eighty numpy calls, about as
# much as this many pairs in Python numbers. A gas step's later rounds mostly hold one or two.
FEW_PAIRS = 4

# Below restitution 1, the pairs the passes leave overlapping stick (stick_left) with every pair touching them, up
# to this many contacts (an exact solve, collapse.py: its cost grows as their cube); beyond, only those pairs.
STICK_MAX = 200

# A relative normal speed smaller than this (m/s) counts as "not moving": such
# an overlap cannot be explained by the last step's motion.
REST_SPEED_MPS = 1e-9


def overlapping(table: Storage, ctx: StepContext) -> None:
    """Stage 4: collide and part the pairs still overlapping (the candidates from the neighbour list),
    then look again at those the corrections pushed into overlap; ctx.moved gets the rows moved (a row
    may repeat). Pairs approaching slower than their rest speed (ctx.rest) are left to the contact stage.
    """
    if not table.puck_collisions:
        return
    pos, vel, radius, mass, nl = table.pos_m, table.vel_mps, table.radius_m, table.mass_kg, table.neighbour_list
    ci, cj, _ = nl.pairs(pos, radius)
    close = broadphase.squared_distances(pos, ci, cj) < nl.reach_squared()
    i, j = _colliding(table, ctx.rest, *broadphase.pairs_where(close, ci, cj, len(pos), nl.sorted_order))
    records, moved, mode = [], [], table.puck_correction
    for attempt in range(1 + EXTRA_PASSES):
        if len(i) == 0:
            break
        if attempt < EXTRA_PASSES:
            records += resolve_pairs(pos, vel, radius, mass, i, j, table.cr_puck, mode, ctx.dt, in_time_order=True)
        else:
            if table.cr_puck < 1.0 and mode != "off":
                records += stick_left(pos, vel, radius, mass, table.size_m, *_touching_them(pos, radius, ci, cj, i, j))
            push_apart(pos, radius, mass, i, j)
        moved += [i, j]
        if mode == "off" or attempt == EXTRA_PASSES:
            break  # the last pass; or "off", where overlaps stay: that is what it shows
        # Parting a pair can push one of its pucks into a third one that
        # was already handled: look again among the same candidates (those
        # that may have come within reach: nothing else changed), collide
        # those pairs too, and at last just push apart what is left.
        # Only pairs with a puck this pass moved can have changed: the others were left as they were.
        ki, kj, near_sq = _with_rows(ci, cj, nl.reach_squared(OVERLAP_SLOP_M), np.concatenate([i, j]), len(pos))
        i, j = _colliding(table, ctx.rest, *broadphase.overlapping_pairs(pos, ki, kj, None, reach_sq=near_sq))
    if moved:
        ctx.records += records
        table.collision_count += sum(r.count for r in records)
        ctx.moved = np.concatenate(moved)


def _touching_them(pos: np.ndarray, radius: np.ndarray, ci: np.ndarray, cj: np.ndarray, i: np.ndarray, j: np.ndarray):
    """(i, j) of the candidate pairs (ci, cj) that touch or overlap, in the clusters of touching pucks that hold
    the pairs (i, j) (overlapping: among them)."""
    k = broadphase.touching(pos, ci, cj, broadphase.pair_reach(radius, ci, cj)).nonzero()[0]
    ti, tj = ci.take(k), cj.take(k)
    cluster = broadphase.clusters(len(pos), ti, tj)
    theirs = np.isin(cluster, cluster.take(np.concatenate([i, j])))
    k = theirs.take(ti).nonzero()[0]
    if len(k) > STICK_MAX:  # (a pile: these alone)
        return i, j
    return ti.take(k), tj.take(k)


def stick_left(pos, vel, radius, mass, size_m, i: np.ndarray, j: np.ndarray) -> list[PairRecords]:
    """Below restitution 1, the overlapping pairs (i, j) the passes leave, with the walls their pucks are on or
    past, collide at once, perfectly inelastically (collapse.py, as events.py's stuck pairs), in place: the
    limit of the hits left. A row of touching pucks pushed into a wall hits on and on at ever smaller speeds
    (inelastic collapse); two passes a step left its pucks approaching, the wall stage sent the first back into
    the next, and the row's end swapped order. Returns the records of the pairs it pushed (a list of one, or none)."""
    z, zv = vectors.as_complex(pos), vectors.as_complex(vel)
    bodies = np.unique(np.concatenate([i, j]))
    a, b = np.searchsorted(bodies, i), np.searchsorted(bodies, j)
    x, v, r = z.take(bodies), zv.take(bodies), radius.take(bodies)
    n_pairs, _ = vectors.units(x.take(a) - x.take(b), lambda: i + j)
    rooms = np.array(collision.wall_rooms(x.real, x.imag, r, (float(size_m[0]), float(size_m[1]))))
    side, on = (rooms <= r * 1e-9).nonzero()  # (wall, body): the walls each is on (to round-off) or past
    n = np.concatenate([n_pairs, np.array(collision.WALL_NORMALS).take(side)])
    first, second = np.concatenate([a, on]), np.concatenate([b, np.full(len(on), -1)])
    v_second = np.where(second >= 0, v.take(second.clip(0)), 0.0)
    vn = vectors.dot(v.take(first) - v_second, n)
    if not np.count_nonzero(vn < -REST_SPEED_MPS):
        return []
    m = mass.take(bodies)
    push = collapse.impulses(n, vn, first, second, 1.0 / m) * n
    dv = np.zeros(len(bodies), dtype=complex)
    np.add.at(dv, first, push / m.take(first))
    pairs = second >= 0
    np.subtract.at(dv, second[pairs], push[pairs] / m.take(second[pairs]))
    zv[bodies] = v + dv
    hit = np.flatnonzero(push[: len(a)] != 0.0)
    if len(hit) == 0:
        return []
    ka, kb = a.take(hit), b.take(hit)
    xa, xb, reach = x.take(ka), x.take(kb), r.take(ka) + r.take(kb)
    columns = (i.take(hit), j.take(hit), n_pairs.take(hit), xb, reach - np.abs(xa - xb), reach, r.take(kb), xa, xb)
    return [
        PairRecords(
            len(hit), (*columns, xa, xb, v.take(ka), v.take(kb), v.take(ka) + dv.take(ka), v.take(kb) + dv.take(kb))
        )
    ]


def _with_rows(ci, cj, reach_sq, rows: np.ndarray, n: int):
    """(ci, cj, reach_sq) of only the candidate pairs that have one of `rows` (reach_sq: per pair, or one number)."""
    touched = np.zeros(n, dtype=bool)
    touched[rows] = True
    k = (touched.take(ci) | touched.take(cj)).nonzero()[0]
    return ci.take(k), cj.take(k), reach_sq if np.ndim(reach_sq) == 0 else reach_sq.take(k)


def _colliding(table: Storage, rest: RestSpeeds | None, i: np.ndarray, j: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pairs (i, j) that collide: all of them if rest is None, else those that approach
    faster than their rest speed and did not press on each other in the last step (or approach faster than HELD_MPS)."""
    if rest is None or len(i) == 0:
        return i, j
    pos, vel = table.pos_m, table.vel_mps
    n, _ = vectors.unit_vectors(vectors.take(pos, i) - vectors.take(pos, j), i + j)
    vn = vectors.dot_rows(vectors.take(vel, i) - vectors.take(vel, j), n)
    fast = (vn < -rest.pairs(i, j, vectors.as_complex(np.ascontiguousarray(n)))).nonzero()[0]  # few: look these up
    held = still_held(table.contact_solver.held(i.take(fast), j.take(fast)), -vn.take(fast))
    fast = fast.take((~held).nonzero()[0])
    return i.take(fast), j.take(fast)


def sharing_pairs(i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Indices k of the pairs (i, j) that share a puck with another pair."""
    if len(i) <= FEW_PAIRS:  # a few pairs: in Python numbers, as their rounds go
        a, b = i.tolist(), j.tolist()
        uses = Counter(a + b)
        return np.array([k for k, (p, q) in enumerate(zip(a, b)) if uses[p] > 1 or uses[q] > 1], dtype=np.intp)
    uses = np.bincount(np.concatenate([i, j]))  # as long as the largest row in a pair, no longer
    return ((uses.take(i) > 1) | (uses.take(j) > 1)).nonzero()[0]


def disjoint_rounds(i: np.ndarray, j: np.ndarray, since=None, shared: np.ndarray | None = None) -> list[np.ndarray]:
    """Split pairs into rounds in which no puck appears twice.

    Keeps the pairs' order: a pair goes into the first round after every
    earlier pair that shares a puck with it. Resolving the rounds in turn is
    therefore the same as resolving the pairs one by one in the given order.
    since(k), if given, says how long ago the pairs k met: then the pairs
    that share a puck are taken in the order they met (events in time order)
    instead of the given one. `shared`: sharing_pairs(i, j), if the caller
    has it already.
    """
    m = len(i)
    if m == 0:
        return []
    if shared is None:
        shared = sharing_pairs(i, j)
    if len(shared) == 0:
        return [np.arange(m)]  # the common case: no puck in two pairs
    # A pair whose pucks are in no other pair can go in any round: the first.
    # For the others, level[k] = how many earlier pairs form a chain into
    # pair k. One pass in Python over just those, a handful per step.
    if since is not None:  # the earliest contact first (a stable sort: ties keep the pairs' order)
        shared = shared.take(np.argsort(-since(shared), kind="stable"))
    level = np.zeros(m, dtype=np.intp)
    level[shared] = _chain_levels(i.take(shared).tolist(), j.take(shared).tolist())
    # Each round in the pairs' order: a stable sort by round.
    by_round, ends = np.argsort(level, kind="stable"), np.cumsum(np.bincount(level)).tolist()
    return [by_round[start:end] for start, end in zip([0, *ends], ends)]


def _chain_levels(i: list[int], j: list[int]) -> list[int]:
    """For each pair in turn, how many earlier pairs form a chain into it (its round)."""
    busy_until: dict[int, int] = {}  # per puck: first level at which it is free again
    levels = []
    for a, b in zip(i, j, strict=True):
        la, lb = busy_until.get(a, 0), busy_until.get(b, 0)
        lvl = la if la > lb else lb
        levels.append(lvl)
        busy_until[a] = busy_until[b] = lvl + 1
    return levels


def time_back_to_contact(d, w, reach, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """(t, explained): how long ago (s) each overlapping pair d = x1 - x2 apart, moving at
    w = v1 - v2, first touched (collision.contact_time), and whether this step's motion explains
    it (it touched at most dt_s ago). t is 0 where it does not."""
    t, _ = collision.contact_time(d, w, reach)
    explained = (t <= 0.0) & (t >= -dt_s)
    return either.where(explained, -t, 0.0), explained


def resolve_pairs(
    pos: np.ndarray,
    vel: np.ndarray,
    radius: np.ndarray,
    mass: np.ndarray,
    i: np.ndarray,
    j: np.ndarray,
    cr_puck: float,
    mode: str,
    dt_s: float,
    in_time_order: bool = False,
    few_pairs: int = FEW_PAIRS,
) -> list[PairRecords]:
    """Collide the overlapping pairs (i, j) in order, in place (see the module docstring).

    in_time_order: pairs that share a puck go in the order they met during
    the step, not the given one. A round of `few_pairs` pairs or fewer goes pair by pair in Python
    numbers (see "one round" below). Returns the records of each round that collided anything;
    `Collisions.of_records` joins them, which is left to whoever reads them.
    """
    if mode not in CORRECTION_MODES:
        raise ValueError(f"puck_correction must be one of {CORRECTION_MODES}, not {mode!r}")
    zpos, zvel = vectors.as_complex(pos), vectors.as_complex(vel)  # the rounds' vectors (see _Round)

    def since_met(a, b):  # how long ago pucks a and b met (dt_s where the step does not explain it)
        d, w = either.take(zpos, a) - either.take(zpos, b), either.take(zvel, a) - either.take(zvel, b)
        t, explained = time_back_to_contact(d, w, either.take(radius, a) + either.take(radius, b), dt_s)
        return either.where(explained, t, dt_s)

    def since(k):  # ... the pairs k (a few: one by one in Python numbers, see "one round")
        if len(k) > few_pairs:
            return since_met(i.take(k), j.take(k))
        return np.array([since_met(i.item(x), j.item(x)) for x in k.tolist()])

    records, pucks = [], (zpos, zvel, radius, mass)
    for r in disjoint_rounds(i, j, since if in_time_order else None):
        if len(r) > few_pairs:
            done = _resolve_round(*pucks, i.take(r), j.take(r), cr_puck, mode, dt_s)
            if done is not None:
                count, columns, approach = done
                records.append(PairRecords(count, columns, None if count == len(approach) else approach.nonzero()[0]))
            continue
        rows = [_resolve_round(*pucks, i.item(k), j.item(k), cr_puck, mode, dt_s) for k in r.tolist()]
        rows = [row for _, row, _ in filter(None, rows)]
        if rows:
            records.append(PairRecords(len(rows), rows=rows))
    return records


def push_apart(pos: np.ndarray, radius: np.ndarray, mass: np.ndarray, i: np.ndarray, j: np.ndarray) -> None:
    """Move each overlapping pair (i, j) apart along its line of centres, in place.

    Positions only: each puck moves its mass-weighted share of the overlap
    (the lighter one more), so the centre of mass stays put. Pairs that share
    a puck add their pushes. Used for the small overlaps a correction leaves
    behind; velocities (and so energy and momentum) are untouched.
    """
    n, dist = vectors.unit_vectors(vectors.take(pos, i) - vectors.take(pos, j), i + j)
    left = np.maximum(radius.take(i) + radius.take(j) - dist, 0.0)
    m_i, m_j = mass.take(i), mass.take(j)
    push = (left / (m_i + m_j))[:, None] * n
    vectors.add_at(pos, i, push * m_j[:, None])
    vectors.add_at(pos, j, -push * m_i[:, None])


# ---------------------------------------------------------------- one round
#
# A round holds its vectors as complex numbers x + iy (vectors.as_complex: views of the
# table's rows, no copies), one array for the first pucks of the pairs (table rows a) and one
# for the second (rows b). Gathering, moving and scattering a round are then one 1-D numpy
# operation per array, and each line reads as the course's formula for one pair: on a few
# dozen pairs a numpy call costs more than its rows, so fewer calls is what counts.
#
# A round of a few pairs goes through the very same lines one pair at a time, in Python numbers
# (a and b ints, the vectors Python complex numbers): there a numpy call costs a microsecond
# for one number, the arithmetic of a whole pair a few. The few operations that differ
# between the two are those of either.py; the bits are the same either way (test_pairs.py).


@dataclass(slots=True)
class _Round:
    """The overlapping pairs of one round, gathered: puck 1 is row a, puck 2 row b.

    Vectors are complex (x + iy), one per pair (arrays, or Python numbers for one pair).
    """

    a: np.ndarray
    b: np.ndarray
    x1: np.ndarray  # positions
    x2: np.ndarray
    v1: np.ndarray  # velocities
    v2: np.ndarray
    m1: np.ndarray  # masses
    m2: np.ndarray
    share1: np.ndarray  # a puck's part of a change in relative motion (collision.mass_shares)
    share2: np.ndarray
    r2: np.ndarray
    reach: np.ndarray  # r1 + r2
    d: np.ndarray  # x1 - x2
    n: np.ndarray  # unit normal from puck 2 to puck 1, along the line of centres
    overlap: np.ndarray
    vrel: np.ndarray  # v1 - v2
    vn: np.ndarray  # relative normal speed, negative when approaching

    def keys(self) -> np.ndarray:
        """a + b: one key per pair for `vectors.units`, made only where a distance is 0."""
        return self.a + self.b


@dataclass(slots=True)
class _Outcome:
    """What a correction mode did to a round (vectors complex, as in _Round)."""

    n: np.ndarray  # the normal the pair collided along
    contact_from: np.ndarray  # centre of puck 2 when they touched
    approach: np.ndarray  # which pairs collided
    count: int  # how many
    v1: np.ndarray  # velocities after
    v2: np.ndarray
    x1: np.ndarray  # positions after
    x2: np.ndarray


def _approaching(approach: np.ndarray) -> tuple[int, np.ndarray | None]:
    """(how many pairs approach, the mask to apply to them): None when all do, as they mostly do."""
    count = either.count(approach)
    return count, (None if count == either.size(approach) else approach)


def _gather(zpos, zvel, radius, mass, a, b) -> _Round | None:
    """The pairs (a, b) that still overlap (an earlier round may have parted some); None if none do.

    zpos, zvel: the table's positions and velocities as complex numbers.
    """
    take = np.ndarray.take if isinstance(a, np.ndarray) else np.ndarray.item  # (see either.take, once)
    x1, x2 = take(zpos, a), take(zpos, b)
    d, r2 = x1 - x2, take(radius, b)
    reach = take(radius, a) + r2
    n, dist = vectors.units(d, lambda: a + b)
    overlap = reach - dist
    if either.count(overlap > 0.0) < either.size(a):
        if not isinstance(a, np.ndarray):
            return None
        keep = (overlap > 0.0).nonzero()[0]
        if len(keep) == 0:
            return None
        a, b, x1, x2, d, r2, reach, n, overlap = (v.take(keep) for v in (a, b, x1, x2, d, r2, reach, n, overlap))
    v1, v2 = take(zvel, a), take(zvel, b)
    m1, m2 = take(mass, a), take(mass, b)
    vrel = v1 - v2
    shares = collision.mass_shares(m1, m2)
    return _Round(a, b, x1, x2, v1, v2, m1, m2, *shares, r2, reach, d, n, overlap, vrel, vectors.dot(vrel, n))


def _collide(g: _Round, n: np.ndarray, only: np.ndarray | None, cr: float):
    """(v1, v2) after the pairs (only those in `only`, if given) collide along n (collision.collide_along)."""
    v1, v2 = collision.collide_along(n, g.v1, g.v2, g.m1, g.m2, cr)
    if only is None:
        return v1, v2
    return either.where(only, v1, g.v1), either.where(only, v2, g.v2)


def separate(g: _Round, n: np.ndarray, move: np.ndarray, only: np.ndarray | None):
    """(x1, x2) after moving each pair (only those in `only`, if given) `move` apart along n.

    Each puck moves its share. Whatever still overlaps (separating, resting,
    created on top of each other, or capped) is then pushed apart along its
    line of centres, by the same shares.
    """
    if only is not None:
        move = either.where(only, move, 0.0)
    x1, x2 = g.x1 + (move * g.share1) * n, g.x2 - (move * g.share2) * n
    d = x1 - x2
    if either.count(vectors.squared_abs(d) < g.reach * g.reach):
        n_now, dist_now = vectors.units(d, g.keys)
        left = either.maximum(g.reach - dist_now, 0.0)
        x1, x2 = x1 + (left * g.share1) * n_now, x2 - (left * g.share2) * n_now
    return x1, x2


def _round_off(g: _Round, cr: float, dt_s: float) -> _Outcome:
    """Velocities only: the overlap stays, which is what this mode shows."""
    approach = g.vn < -REST_SPEED_MPS
    count, only = _approaching(approach)
    v1, v2 = _collide(g, g.n, only, cr)
    return _Outcome(g.n, g.x2, approach, count, v1, v2, g.x1, g.x2)


def _two_step_move(g: _Round, cr: float, dt_s: float) -> np.ndarray:
    """How far the two-step correction parts each pair along the normal.

    Back up t_p = overlap / |vn| (the pair parts by |vn| t_p, the overlap),
    then forward t_p with the normal velocities after the collision (it
    parts by another e |vn| t_p): (1 + e) times the overlap in all. An
    overlap deeper than one step of approach can explain is capped there;
    `separate` pushes the rest apart.
    """
    return (1.0 + cr) * either.minimum(g.overlap, g.vn * -dt_s)


def _round_two_step(g: _Round, cr: float, dt_s: float) -> _Outcome:
    approach = g.vn < -REST_SPEED_MPS
    count, only = _approaching(approach)
    v1, v2 = _collide(g, g.n, only, cr)
    x1, x2 = separate(g, g.n, _two_step_move(g, cr, dt_s), only)
    return _Outcome(g.n, g.x2, approach, count, v1, v2, x1, x2)


def _round_perfect_kiss(g: _Round, cr: float, dt_s: float) -> _Outcome:
    """Collide at first contact; pairs whose overlap this step cannot explain get the two-step correction."""
    t_b, kiss = time_back_to_contact(g.d, g.vrel, g.reach, dt_s)
    kissing = either.count(kiss)
    if not kissing:
        return _round_two_step(g, cr, dt_s)
    c1, c2 = g.x1 - t_b * g.v1, g.x2 - t_b * g.v2  # both centres at first contact
    n, _ = vectors.units(c1 - c2, g.keys)
    # They approach now, so they approached at contact (on straight paths d.w only grows). Going
    # forward t_b with the new velocities parts the pair by (1 + cr) |vn| t_b, vn the normal speed there.
    contact_from, approach, move = c2, kiss, -(1.0 + cr) * vectors.dot(g.vrel, n) * t_b
    if kissing < either.size(kiss):  # the others: the two-step's normal, approach and move
        n, contact_from = np.where(kiss, n, g.n), np.where(kiss, contact_from, g.x2)
        approach = kiss | (g.vn < -REST_SPEED_MPS)
        move = np.where(kiss, move, _two_step_move(g, cr, dt_s))
    count, only = _approaching(approach)
    v1, v2 = _collide(g, n, only, cr)
    x1, x2 = separate(g, n, move, only)
    return _Outcome(n, contact_from, approach, count, v1, v2, x1, x2)


_ROUND_BY_MODE: dict[str, Callable[[_Round, float, float], _Outcome]] = {
    "off": _round_off,
    "two-step": _round_two_step,
    "perfect-kiss": _round_perfect_kiss,
}


def _resolve_round(zpos, zvel, radius, mass, a, b, cr, mode, dt_s) -> tuple[int, tuple, np.ndarray] | None:
    """Resolve pairs that share no puck, all at once, in place (see `disjoint_rounds`), on the
    table's positions and velocities as complex numbers (vectors.as_complex); or one pair (a, b ints).

    Returns (how many collided, the record's columns: the fields of `Collisions.of_pairs`, which
    of them collided), None if none did; for one pair the columns are its row.
    """
    g = _gather(zpos, zvel, radius, mass, a, b)
    if g is None:
        return None
    out = _ROUND_BY_MODE[mode](g, cr, dt_s)
    # No row repeats within a round, so each scatter writes each row once.
    zvel[g.a], zvel[g.b] = out.v1, out.v2
    if mode != "off":
        zpos[g.a], zpos[g.b] = out.x1, out.x2
    if not out.count:
        return None
    record = (g.a, g.b, out.n, out.contact_from, g.overlap, g.reach, g.r2, g.x1, g.x2, out.x1, out.x2)
    return out.count, (*record, g.v1, g.v2, out.v1, out.v2), out.approach
