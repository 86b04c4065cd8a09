"""Puck pairs: collide the overlapping pairs one pair at a time, then part them.

Sequential resolution matters: each pair sees the velocities left by the pairs
before it, which conserves momentum and (restitution 1) energy to round-off.
To keep that and still vectorise, `disjoint_rounds` splits the pairs into
rounds in which no puck appears twice (a colouring of the graph of pairs that
keeps their order); pairs in one round cannot affect each other, so resolving
a round at once gives exactly the result of resolving its pairs one by one.

A round is resolved by the function of the table's correction mode, all three
built from the same two pieces: `collide_along_normal` (the 1D collision with
restitution along the line of centres; the tangential velocity is kept) and
`separate` (move the pair apart along a normal, then push apart what still
overlaps).

* "off": velocities only; the pucks stay overlapping ("stickiness").
* "two-step": back both pucks up along their normal velocities for the
  penetration time t_p = overlap / |vn|, then forward t_p with the
  post-collision normal velocities: the pair parts by (1 + e) times the
  overlap, so it ends e times the overlap apart (as far apart as it
  overlapped at e = 1, touching at e = 0).
* "perfect-kiss": back the pair up along its full relative motion to the
  moment of first contact, take the normal there, collide, and go forward
  again by the same time.

reference.py does the same for one pair in plain Python floats, equation by
equation; the tests check the two agree.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from airtable.physics import vectors

CORRECTION_MODES = ("off", "two-step", "perfect-kiss")

# A relative normal speed smaller than this (m/s) counts as "not moving": such
# an overlap cannot be explained by the last step's motion.
REST_SPEED_MPS = 1e-9
# Rounds of at most this many pairs are resolved one pair at a time in plain
# floats (`_resolve_few`): a numpy call costs about a microsecond however few
# rows it has, and a round makes some forty of them, while a gas mostly has
# rounds of one to five pairs. The floats do the arrays' arithmetic in the
# same order, so both paths give the same numbers (tests/test_few_in_floats.py).
FEW_PAIRS = 8


@dataclass
class Collisions:
    """What the pair resolution of one step did, for diagnostics and drawing.

    One row per collision (an approaching pair whose velocities were changed):
    puck rows i and j, the contact normal (unit, from j to i), the contact
    point, the overlap when detected, the pair's reach (sum of the radii) and
    both pucks' positions and velocities before and after this collision.
    """

    i: np.ndarray
    j: np.ndarray
    normal: np.ndarray
    contact_m: np.ndarray
    overlap_m: np.ndarray
    reach_m: np.ndarray
    pos_i_before: np.ndarray
    pos_j_before: np.ndarray
    pos_i_after: np.ndarray
    pos_j_after: np.ndarray
    vel_i_before: np.ndarray
    vel_j_before: np.ndarray
    vel_i_after: np.ndarray
    vel_j_after: np.ndarray

    @property
    def separation_m(self) -> np.ndarray:
        """The gap the position correction left (m); negative: still overlapping."""
        return vectors.lengths(self.pos_i_after - self.pos_j_after) - self.reach_m

    @classmethod
    def empty(cls) -> Collisions:
        z = np.empty(0)
        zi = np.empty(0, dtype=np.intp)
        z2 = np.empty((0, 2))
        return cls(zi, zi, z2, z2, z, z, *([z2] * 8))

    def __len__(self) -> int:
        return len(self.i)

    @classmethod
    def concatenate(cls, parts: list[Recorded]) -> Collisions:
        """One record of all the parts (each a Collisions, or a round's record made into one now)."""
        if not parts:
            return cls.empty()
        parts = [p if isinstance(p, Collisions) else p.collisions() for p in parts]
        if len(parts) == 1:
            return parts[0]
        return cls(*(np.concatenate([getattr(p, f) for p in parts]) for f in cls.__dataclass_fields__))

    def take(self, k: np.ndarray) -> Collisions:
        """Only the collisions k (indices into this record)."""
        return Collisions(*(getattr(self, f).take(k, axis=0) for f in self.__dataclass_fields__))


def sharing_pairs(i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Indices k of the pairs (i, j) that share a puck with another pair."""
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
    if since is not None:
        shared = shared.take(np.argsort(-since(shared), kind="stable"))  # the earliest contact first
    levels = _chain_levels(i.take(shared).tolist(), j.take(shared).tolist())
    level = np.zeros(m, dtype=np.intp)
    level[shared] = levels
    order = np.argsort(level, kind="stable")
    bounds = np.searchsorted(level.take(order), np.arange(max(levels) + 2))
    return [order[bounds[r] : bounds[r + 1]] for r in range(len(bounds) - 1)]


def _chain_levels(i: list[int], j: list[int]) -> list[int]:
    """For each pair in turn, how many earlier pairs form a chain into it (its round)."""
    busy_until: dict[int, int] = {}  # per puck: first level at which it is free again
    levels = []
    for a, b in zip(i, j, strict=True):
        lvl = max(busy_until.get(a, 0), busy_until.get(b, 0))
        levels.append(lvl)
        busy_until[a] = busy_until[b] = lvl + 1
    return levels


def since_contact(pos, vel, radius, i, j, dt_s: float) -> np.ndarray:
    """How long ago each pair (i, j) first touched during the step (dt_s if its motion does not explain it)."""
    d = vectors.take(pos, i) - vectors.take(pos, j)
    w = vectors.take(vel, i) - vectors.take(vel, j)
    reach = radius.take(i) + radius.take(j)
    ww, dw = vectors.squared_lengths(w), vectors.dot_rows(d, w)
    disc = np.maximum(dw * dw - ww * (vectors.squared_lengths(d) - reach * reach), 0.0)
    back = (dw + np.sqrt(disc)) / np.where(ww > 0.0, ww, 1.0)
    return np.where((ww > 0.0) & (back >= 0.0) & (back <= dt_s), back, dt_s)


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
) -> list[Recorded]:
    """Collide the overlapping pairs (i, j) in order, in place (see the module docstring).

    in_time_order: pairs that share a puck go in the order they met during
    the step, not the given one. Returns one record per round that collided
    anything; `Collisions.concatenate` joins them, which is left to whoever reads them.
    """
    if mode not in CORRECTION_MODES:
        raise ValueError(f"puck_correction must be one of {CORRECTION_MODES}, not {mode!r}")

    def since(k):
        return since_contact(pos, vel, radius, i.take(k), j.take(k), dt_s)

    zpos, zvel = vectors.as_complex(pos), vectors.as_complex(vel)  # the rounds' vectors (see _Round)
    if len(i) <= FEW_PAIRS:
        return _resolve_few_in_order(zpos, zvel, radius, mass, i, j, cr_puck, mode, dt_s, in_time_order)
    shared = sharing_pairs(i, j)
    if len(shared) <= FEW_PAIRS:
        # A gas's usual case. The pairs whose pucks are in no other pair
        # cannot change the others: one round for them, then the few that
        # share a puck, one by one in floats, in their rounds' order.
        alone = np.ones(len(i), dtype=bool)
        alone[shared] = False
        alone, few = alone.nonzero()[0], shared
        c = _resolve_round(zpos, zvel, radius, mass, i.take(alone), j.take(alone), cr_puck, mode, dt_s)
        few_records = _resolve_few_in_order(
            zpos, zvel, radius, mass, i.take(few), j.take(few), cr_puck, mode, dt_s, in_time_order
        )
        return ([] if c is None else [c]) + few_records
    records = []
    for r in disjoint_rounds(i, j, since if in_time_order else None, shared):
        c = _resolve_round(zpos, zvel, radius, mass, i.take(r), j.take(r), cr_puck, mode, dt_s)
        if c is not None:
            records.append(c)
    return records


def _resolve_few_in_order(zpos, zvel, radius, mass, i, j, cr_puck, mode, dt_s, in_time_order) -> list[Recorded]:
    """resolve_pairs for a few pairs, in floats: in the order of their rounds, one by one."""
    il, jl = i.tolist(), j.tolist()
    order = _few_in_order(zpos, zvel, radius, il, jl, dt_s if in_time_order else None)
    if order is not None:
        il, jl = [il[k] for k in order], [jl[k] for k in order]
    c = _resolve_few(zpos, zvel, radius, mass, il, jl, cr_puck, mode, dt_s)
    return [] if c is None else [c]


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


@dataclass
class _Round:
    """The overlapping pairs of one round, gathered: puck 1 is row a, puck 2 row b.

    Vectors are complex (x + iy), one per pair.
    """

    a: np.ndarray
    b: np.ndarray
    x1: np.ndarray  # positions
    x2: np.ndarray
    v1: np.ndarray  # velocities
    v2: np.ndarray
    share1: np.ndarray  # a puck's part of a change in relative motion: m2 / (m1 + m2) for puck 1,
    share2: np.ndarray  # m1 / (m1 + m2) for puck 2 (the lighter one moves more)
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


@dataclass
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
    count = np.count_nonzero(approach)
    return count, (None if count == len(approach) else approach)


def _gather(zpos, zvel, radius, mass, a, b) -> _Round | None:
    """The pairs (a, b) that still overlap (an earlier round may have parted some); None if none do.

    zpos, zvel: the table's positions and velocities as complex numbers.
    """
    x1, x2 = zpos.take(a), zpos.take(b)
    d, r2 = x1 - x2, radius.take(b)
    reach = radius.take(a) + r2
    n, dist = vectors.units(d, lambda: a + b)
    overlap = reach - dist
    if np.count_nonzero(overlap > 0.0) < len(a):
        keep = (overlap > 0.0).nonzero()[0]
        if len(keep) == 0:
            return None
        a, b, x1, x2, d, r2, reach, n, overlap = (v.take(keep) for v in (a, b, x1, x2, d, r2, reach, n, overlap))
    v1, v2 = zvel.take(a), zvel.take(b)
    m1, m2 = mass.take(a), mass.take(b)
    m_sum = m1 + m2
    vrel = v1 - v2
    return _Round(a, b, x1, x2, v1, v2, m2 / m_sum, m1 / m_sum, r2, reach, d, n, overlap, vrel, vectors.dot(vrel, n))


def collide_along_normal(g: _Round, n: np.ndarray, vn: np.ndarray, only: np.ndarray | None, cr: float):
    """(v1, v2) after the 1D collision with restitution cr along the normal n.

    only: which pairs collide, None for all. The relative normal speed vn
    becomes -cr vn, shared so that momentum is kept (the lighter puck takes
    more of the change); the tangential velocities are untouched.
    """
    jn = -(1.0 + cr) * vn  # change of relative normal speed
    if only is not None:
        jn = np.where(only, jn, 0.0)
    return g.v1 + (jn * g.share1) * n, g.v2 - (jn * g.share2) * n


def separate(g: _Round, n: np.ndarray, move: np.ndarray, only: np.ndarray | None):
    """(x1, x2) after moving each pair (only those in `only`, if given) `move` apart along n.

    Each puck moves its share. Whatever still overlaps (separating, resting,
    created on top of each other, or capped) is then pushed apart along its
    line of centres, by the same shares.
    """
    if only is not None:
        move = np.where(only, move, 0.0)
    x1, x2 = g.x1 + (move * g.share1) * n, g.x2 - (move * g.share2) * n
    d = x1 - x2
    if np.count_nonzero(vectors.squared_abs(d) < g.reach * g.reach):
        n_now, dist_now = vectors.units(d, g.keys)
        left = np.maximum(g.reach - dist_now, 0.0)
        x1, x2 = x1 + (left * g.share1) * n_now, x2 - (left * g.share2) * n_now
    return x1, x2


def _round_off(g: _Round, cr: float, dt_s: float) -> _Outcome:
    """Velocities only: the overlap stays, which is what this mode shows."""
    approach = g.vn < -REST_SPEED_MPS
    count, only = _approaching(approach)
    v1, v2 = collide_along_normal(g, g.n, g.vn, only, cr)
    return _Outcome(g.n, g.x2, approach, count, v1, v2, g.x1, g.x2)


def _two_step_move(g: _Round, cr: float, dt_s: float) -> np.ndarray:
    """How far the two-step correction parts each pair along the normal.

    Back up t_p = overlap / |vn| (the pair parts by |vn| t_p, the overlap),
    then forward t_p with the normal velocities after the collision (it
    parts by another e |vn| t_p): (1 + e) times the overlap in all. An
    overlap deeper than one step of approach can explain is capped there;
    `separate` pushes the rest apart.
    """
    return (1.0 + cr) * np.minimum(g.overlap, g.vn * -dt_s)


def _round_two_step(g: _Round, cr: float, dt_s: float) -> _Outcome:
    approach = g.vn < -REST_SPEED_MPS
    count, only = _approaching(approach)
    v1, v2 = collide_along_normal(g, g.n, g.vn, only, cr)
    x1, x2 = separate(g, g.n, _two_step_move(g, cr, dt_s), only)
    return _Outcome(g.n, g.x2, approach, count, v1, v2, x1, x2)


def _time_since_contact(g: _Round, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """(t, ok): how long ago each pair first touched, and whether this step's motion explains it.

    Solves |d - vrel t| = reach for the larger root t, with d = x1 - x2.
    """
    vv = vectors.squared_abs(g.vrel)
    dv = vectors.dot(g.d, g.vrel)
    disc = np.maximum(dv * dv - vv * (vectors.squared_abs(g.d) - g.reach * g.reach), 0.0)
    moving = vv > REST_SPEED_MPS**2
    all_moving = np.count_nonzero(moving) == len(vv)  # as they mostly are; the count costs a quarter of np.where
    t_back = (dv + np.sqrt(disc)) / (vv if all_moving else np.where(moving, vv, 1.0))
    ok = moving & (t_back >= 0.0) & (t_back <= dt_s * (1.0 + 1e-9) + 1e-15)
    return t_back, ok


def _round_perfect_kiss(g: _Round, cr: float, dt_s: float) -> _Outcome:
    """Collide at first contact; pairs whose overlap this step cannot explain get the two-step correction."""
    t_back, kiss = _time_since_contact(g, dt_s)
    kissing = np.count_nonzero(kiss)
    if not kissing:
        return _round_two_step(g, cr, dt_s)
    t_b = t_back if kissing == len(kiss) else np.where(kiss, t_back, 0.0)
    c1, c2 = g.x1 - t_b * g.v1, g.x2 - t_b * g.v2  # both centres at first contact
    n, _ = vectors.units(c1 - c2, g.keys)
    vn = vectors.dot(g.vrel, n)
    # Approaching is judged at the contact time: a fast pair is often caught
    # after its closest approach. Going forward t_b with the new velocities
    # parts the pair by (1 + cr) |vn| t_b.
    contact_from, approach, move = c2, vn < 0.0, -(1.0 + cr) * vn * t_b
    if kissing < len(kiss):  # the others: the two-step's normal, speed and move
        n, contact_from = np.where(kiss, n, g.n), np.where(kiss, contact_from, g.x2)
        vn = np.where(kiss, vn, g.vn)
        approach = np.where(kiss, approach, g.vn < -REST_SPEED_MPS)
        move = np.where(kiss, move, _two_step_move(g, cr, dt_s))
    count, only = _approaching(approach)
    v1, v2 = collide_along_normal(g, n, vn, only, cr)
    x1, x2 = separate(g, n, move, only)
    return _Outcome(n, contact_from, approach, count, v1, v2, x1, x2)


_ROUND_BY_MODE: dict[str, Callable[[_Round, float, float], _Outcome]] = {
    "off": _round_off,
    "two-step": _round_two_step,
    "perfect-kiss": _round_perfect_kiss,
}


def _resolve_round(zpos, zvel, radius, mass, a, b, cr, mode, dt_s) -> Recorded | None:
    """Resolve pairs that share no puck, all at once, in place (see `disjoint_rounds`), on the
    table's positions and velocities as complex numbers (vectors.as_complex).

    Returns the record of the pairs that collided, None if none did.
    """
    if len(a) <= FEW_PAIRS:
        return _resolve_few(zpos, zvel, radius, mass, a.tolist(), b.tolist(), cr, mode, dt_s)
    g = _gather(zpos, zvel, radius, mass, a, b)
    if g is None:
        return None
    out = _ROUND_BY_MODE[mode](g, cr, dt_s)
    # No row repeats within a round, so each scatter writes each row once.
    zvel[g.a], zvel[g.b] = out.v1, out.v2
    if mode != "off":
        zpos[g.a], zpos[g.b] = out.x1, out.x2
    return _RoundRecord(g, out) if out.count else None


@dataclass
class _RoundRecord:
    """A round's collisions, kept as the round left them: made into `Collisions` only when read
    (most steps nobody reads them)."""

    g: _Round
    out: _Outcome

    def __len__(self) -> int:
        return self.out.count

    def collisions(self) -> Collisions:
        g, out = self.g, self.out
        contact = out.contact_from + g.r2 * out.n
        record = Collisions(
            g.a, g.b, vectors.as_rows(out.n), vectors.as_rows(contact), g.overlap, g.reach,
            *(vectors.as_rows(z) for z in (g.x1, g.x2, out.x1, out.x2, g.v1, g.v2, out.v1, out.v2)),
        )  # fmt: skip
        return record if out.count == len(g.a) else record.take(out.approach.nonzero()[0])


# ---------------------------------------------------------------- a few pairs, in floats


def _resolve_few(zpos, zvel, radius, mass, a: list[int], b: list[int], cr, mode, dt_s) -> Recorded | None:
    """`_resolve_round` for a few pairs: the same steps, pair by pair, in Python numbers."""
    rows, hit = [], []
    for p, q in zip(a, b, strict=True):
        row = _pair_in_floats(zpos, zvel, radius, mass, p, q, cr, mode, dt_s)
        if row is not None:
            rows.append(row)
            hit.append((p, q))
    return _FewRecord(hit, rows) if rows else None


@dataclass
class _FewRecord:
    """The record rows of `_resolve_few`, made into `Collisions` only when read."""

    hit: list[tuple[int, int]]
    rows: list[tuple]  # overlap, reach, then normal, contact and 8 positions and velocities, as complex x + iy

    def __len__(self) -> int:
        return len(self.rows)

    def collisions(self) -> Collisions:
        ij = np.array(self.hit, dtype=np.intp)
        overlap, reach, n, contact, *states = (np.array(column) for column in zip(*self.rows, strict=True))
        n, contact, *states = (vectors.as_rows(z) for z in (n, contact, *states))
        return Collisions(ij[:, 0], ij[:, 1], n, contact, overlap, reach, *states)


# What a round or a few pairs record: `Collisions`, or what makes them when read.
Recorded = Collisions | _RoundRecord | _FewRecord


def _unit_floats(d: complex, key: int) -> tuple[complex, float]:
    """vectors.units for one vector: (d / |d|, |d|), each part divided by the length."""
    dx, dy = d.real, d.imag
    dist = math.sqrt(dx * dx + dy * dy)
    if dist != 0.0:
        return complex(dx / dist, dy / dist), dist
    n0, n1 = vectors.fallback_directions(np.array([key]))[0].tolist()
    return complex(n0, n1), dist


def _kiss_time(d: complex, vrel: complex, reach: float, dt_s: float) -> float | None:
    """`_time_since_contact` for one pair: the time back to first contact, None if the step cannot explain it."""
    vv, dv = vectors.dot_one(vrel, vrel), vectors.dot_one(d, vrel)
    disc = max(dv * dv - vv * (vectors.dot_one(d, d) - reach * reach), 0.0)
    if not vv > REST_SPEED_MPS**2:
        return None
    t_back = (dv + math.sqrt(disc)) / vv
    return t_back if 0.0 <= t_back <= dt_s * (1.0 + 1e-9) + 1e-15 else None


def _pair_in_floats(zpos, zvel, radius, mass, p, q, cr, mode, dt_s) -> tuple | None:
    """Collide and part the pair (p, q) in place, as `_gather`, the mode's round function and
    `separate` would, on the table's complex views zpos and zvel; return its record row (see
    _FewRecord), None if it did not collide."""
    x1, x2 = zpos.item(p), zpos.item(q)
    r2 = radius.item(q)
    reach = radius.item(p) + r2
    d = x1 - x2
    n, dist = _unit_floats(d, p + q)
    overlap = reach - dist
    if not overlap > 0.0:
        return None
    v1, v2 = zvel.item(p), zvel.item(q)
    m1, m2 = mass.item(p), mass.item(q)
    m_sum = m1 + m2
    share1, share2 = m2 / m_sum, m1 / m_sum
    vrel = v1 - v2
    vn = vectors.dot_one(vrel, n)
    t_b = _kiss_time(d, vrel, reach, dt_s) if mode == "perfect-kiss" else None
    if t_b is None:  # as _round_two_step (and _round_off, which does not use `move`)
        approach = vn < -REST_SPEED_MPS
        move = (1.0 + cr) * min(overlap, vn * -dt_s)
        c = x2
    else:  # as _round_perfect_kiss
        c = x2 - t_b * v2
        n, _ = _unit_floats((x1 - t_b * v1) - c, p + q)
        vn = vectors.dot_one(vrel, n)
        approach = vn < 0.0
        move = -(1.0 + cr) * vn * t_b
    jn = -(1.0 + cr) * vn if approach else 0.0  # collide_along_normal
    w1, w2 = v1 + (jn * share1) * n, v2 - (jn * share2) * n
    zvel[p], zvel[q] = w1, w2
    y1, y2 = x1, x2
    if mode != "off":
        y1, y2 = _separate_floats(x1, x2, n, move if approach else 0.0, reach, share1, share2, p + q)
        zpos[p], zpos[q] = y1, y2
    if not approach:
        return None
    return overlap, reach, n, c + r2 * n, x1, x2, y1, y2, v1, v2, w1, w2


def _separate_floats(x1, x2, n: complex, move: float, reach: float, share1: float, share2: float, key: int):
    """`separate` for one pair: move it `move` apart along n, then push apart what still overlaps."""
    y1, y2 = x1 + (move * share1) * n, x2 - (move * share2) * n
    d = y1 - y2
    if vectors.dot_one(d, d) < reach * reach:
        n_now, dist = _unit_floats(d, key)
        left = max(reach - dist, 0.0)
        y1, y2 = y1 + (left * share1) * n_now, y2 - (left * share2) * n_now
    return y1, y2


def _few_in_order(zpos, zvel, radius, il: list[int], jl: list[int], dt_s: float | None) -> list[int] | None:
    """The order in which `disjoint_rounds`' rounds would take the pairs (il, jl): round by round,
    in the given order within a round (None: the given order). With dt_s, pairs sharing a puck
    go as they met (since_contact)."""
    if len(set(il + jl)) == 2 * len(il):
        return None  # the usual case: no puck in two pairs, one round in the given order
    uses: dict[int, int] = {}
    for p in il + jl:
        uses[p] = uses.get(p, 0) + 1
    shared = [k for k in range(len(il)) if uses[il[k]] > 1 or uses[jl[k]] > 1]
    if dt_s is not None:
        since = {k: _since_floats(zpos, zvel, radius, il[k], jl[k], dt_s) for k in shared}
        shared.sort(key=lambda k: -since[k])  # stable, as np.argsort(kind="stable")
    level = [0] * len(il)
    for k, lvl in zip(shared, _chain_levels([il[k] for k in shared], [jl[k] for k in shared]), strict=True):
        level[k] = lvl
    return sorted(range(len(il)), key=level.__getitem__)


def _since_floats(zpos, zvel, radius, p: int, q: int, dt_s: float) -> float:
    """`since_contact` for one pair."""
    d, w = zpos.item(p) - zpos.item(q), zvel.item(p) - zvel.item(q)
    reach = radius.item(p) + radius.item(q)
    ww, dw = vectors.dot_one(w, w), vectors.dot_one(d, w)
    disc = max(dw * dw - ww * (vectors.dot_one(d, d) - reach * reach), 0.0)
    back = (dw + math.sqrt(disc)) / (ww if ww > 0.0 else 1.0)
    return back if ww > 0.0 and 0.0 <= back <= dt_s else dt_s
