"""Collision detection and response for round pucks in a walled box.

Everything here works on the table's numpy arrays in place (rows gathered and
scattered through rows.py) and knows nothing of pygame. Three parts:

* `resolve_walls`: push pucks back inside the box, bounce them off the walls.
* `find_overlapping_pairs`: the broadphase. A uniform grid in numpy finds the
  candidate pairs in O(N) work, pucks too big for the grid are checked against
  everyone by vectorised brute force, and small tables use brute force alone.
  `NeighbourList` keeps the grid's pairs (widened by a skin) for several steps.
* `resolve_pairs`: collide the overlapping pairs one pair at a time (Gauss-Seidel
  order), with one of three position corrections: "off", "two-step" and
  "perfect-kiss" (see DESIGN.md section 3 and the course's A10 notes).

Sequential resolution matters: each pair sees the velocities left by the pairs
before it, which conserves momentum and (restitution 1) energy to round-off.
To keep that and still vectorise, the pairs are split into rounds in which no
puck appears twice; pairs in one round cannot affect each other, so resolving a
round at once gives exactly the result of resolving its pairs one by one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from airtable.physics import rows

CORRECTION_MODES = ("off", "two-step", "perfect-kiss")

# Below this many pucks, checking every pair with one numpy expression is
# cheaper than building a grid.
BRUTE_FORCE_MAX_PUCKS = 48
# The neighbour list's skin, in mean radii: a wider skin is rebuilt less often
# but holds more pairs. In the benchmark gas (1 m/s, dt = 1/120 s, fastest
# pucks near 3 m/s) 1.5 radii lasts about four steps and was the fastest of
# 0.5, 1, 1.5 and 2.
SKIN_RADII = 1.5
# A relative normal speed smaller than this (m/s) counts as "not moving": such
# an overlap cannot be explained by the last step's motion.
REST_SPEED_MPS = 1e-9
_FALLBACK_NORMAL = np.array([1.0, 0.0])


# ---------------------------------------------------------------- walls


def resolve_walls(
    pos: np.ndarray,
    vel: np.ndarray,
    radius: np.ndarray,
    size_m: np.ndarray,
    cr_wall: float,
    correction: bool,
    only: np.ndarray | None = None,
) -> int:
    """Keep every puck inside the box [0, size_m]; return how many bounced.

    `only`, if given, limits the check to those rows (the pucks that moved).
    A puck past a wall is moved back: mirrored by its penetration when
    `correction` is on (where it would be had it bounced at the surface), else
    just placed on the surface. Its normal velocity reverses, times `cr_wall`,
    only if it was moving into that wall.
    """
    if len(pos) == 0:
        return 0
    p, r = (pos, radius) if only is None else (rows.take(pos, only), radius.take(only))
    # Room between each puck's edge and the nearest wall, column by column:
    # numpy broadcasts an (N, 1) radius against (N, 2) rows several times slower.
    x, y = p[:, 0], p[:, 1]
    width, height = size_m
    room = np.minimum(np.minimum(x, y), np.minimum(width - x, height - y)) - r
    if room.min() >= 0.0:
        return 0  # the usual case: nobody is past a wall
    out = np.flatnonzero(~(room >= 0.0))  # NaN counts as outside
    if only is not None:
        out = only.take(out)
    p, v = rows.take(pos, out), rows.take(vel, out)
    lo = radius.take(out)[:, None]
    hi = size_m - lo
    below, above = p < lo, p > hi
    into = (below & (v < 0.0)) | (above & (v > 0.0))
    rows.put(vel, out, np.where(into, -cr_wall * v, v))
    # Mirrored by the penetration, or else left for the clamp below to put on the surface.
    target = np.where(below, 2.0 * lo - p, np.where(above, 2.0 * hi - p, p)) if correction else p
    # Clamp into [lo, hi]: a mirror of a huge penetration can land past the
    # opposite wall. A puck wider than the table (lo > hi) sits in the middle.
    half = 0.5 * size_m
    rows.put(pos, out, np.minimum(np.maximum(target, np.minimum(lo, half)), np.maximum(hi, half)))
    return int(np.count_nonzero(into))


# ---------------------------------------------------------------- broadphase


def brute_force_pairs(pos: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All overlapping pairs (i < j) by checking every pair; sorted by (i, j)."""
    i, j = np.triu_indices(len(pos), k=1)
    return overlapping_pairs(pos, i, j, pair_reach(radius, i, j))


def find_overlapping_pairs(pos: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All overlapping pairs (i < j), sorted by (i, j): the same as brute force."""
    i, j = find_candidate_pairs(pos, radius)
    return overlapping_pairs(pos, i, j, pair_reach(radius, i, j))


def find_candidate_pairs(pos: np.ndarray, radius: np.ndarray, margin_m: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (i < j) that may be closer than their reach plus margin_m, each once.

    Uses a uniform grid with cells as wide as the largest ordinary pair's
    reach plus the margin. Each puck is compared with the pucks in its own
    cell and in four of its eight neighbours (the other four see it from their
    side), so each candidate pair is produced once. Pucks more than twice the
    mean radius are paired with every puck, so one giant puck cannot bloat the
    grid. Small tables pair everyone with everyone.
    """
    n = len(pos)
    if n <= BRUTE_FORCE_MAX_PUCKS:
        return np.triu_indices(n, k=1)
    r_max = float(radius.max())
    # No puck can be twice the mean while the largest is within twice the smallest.
    big = radius > 2.0 * radius.mean() if r_max > 2.0 * float(radius.min()) else None
    if big is not None and big.any():
        small_idx = np.flatnonzero(~big)
        cell = 2.0 * float(radius.take(small_idx).max()) + margin_m
        gi, gj = _grid_candidates(rows.take(pos, small_idx), cell)
        i_parts, j_parts = [small_idx.take(gi)], [small_idx.take(gj)]
        for b in np.flatnonzero(big):
            others = np.arange(n)
            others = others[(others != b) & (~big | (others > b))]  # each big-big pair once
            i_parts.append(np.full(len(others), b))
            j_parts.append(others)
        i, j = np.concatenate(i_parts), np.concatenate(j_parts)
    else:
        i, j = _grid_candidates(pos, 2.0 * r_max + margin_m)
    return np.minimum(i, j), np.maximum(i, j)


def pair_reach(radius: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Sum of the radii of each pair: closer centres than this overlap."""
    return radius.take(i) + radius.take(j)


def overlapping_pairs(
    pos: np.ndarray, i: np.ndarray, j: np.ndarray, reach: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The candidate pairs (i, j) closer than `reach`, sorted by (i, j)."""
    hit = _closer_than(pos, i, j, reach)
    i, j = i.take(hit), j.take(hit)
    if len(i) > 1:
        order = np.lexsort((j, i))
        i, j = i.take(order), j.take(order)
    return i, j


def _closer_than(pos: np.ndarray, i: np.ndarray, j: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """Indices k of the pairs whose centres are less than reach[k] apart."""
    return np.flatnonzero(squared_lengths(rows.take(pos, i) - rows.take(pos, j)) < reach * reach)


class NeighbourList:
    """The candidate pairs of a step, kept for as long as they stay valid (a Verlet list).

    Built with the grid with cells widened by a skin (SKIN_RADII times the mean
    radius), it keeps every pair closer than its reach plus the skin. While no
    puck has moved more than half the skin since, no pair left out can have
    closed that gap, so the list still holds every pair that may overlap.
    Checking that costs a few operations a step; the grid is rebuilt only
    every few steps. The list is about rows, not pucks: a puck added or
    removed changes the row count, and a row moved or resized by hand fails
    the checks, so nothing needs to tell it.
    """

    def __init__(self) -> None:
        self.builds = 0  # how many times the list was built (for tests)
        self._built_pos: np.ndarray | None = None

    def pairs(self, pos: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(i, j, reach) for every pair that may overlap now: i < j, reach = sum of the radii."""
        if not self._still_valid(pos, radius):
            self._build(pos, radius)
        return self._i, self._j, self._reach

    def _still_valid(self, pos: np.ndarray, radius: np.ndarray) -> bool:
        if self._built_pos is None or len(pos) != len(self._built_pos) or len(pos) == 0:
            return False
        if np.count_nonzero(radius != self._built_radius):
            return False  # a radius was changed by hand
        moved_sq = squared_lengths(pos - self._built_pos)
        return bool(moved_sq.max() < self._half_skin_sq)  # NaN: not valid

    def _build(self, pos: np.ndarray, radius: np.ndarray) -> None:
        skin = SKIN_RADII * float(radius.mean()) if len(radius) else 0.0
        i, j = find_candidate_pairs(pos, radius, margin_m=skin)
        reach = pair_reach(radius, i, j)
        near = _closer_than(pos, i, j, reach + skin)
        self._i, self._j, self._reach = i.take(near), j.take(near), reach.take(near)
        self._built_pos, self._built_radius = pos.copy(), radius.copy()
        self._half_skin_sq = (0.5 * skin) ** 2
        self.builds += 1


def _grid_candidates(pos: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """Candidate pairs of pucks whose cells touch (indices into `pos`)."""
    n = len(pos)
    if n < 2:
        empty = np.empty(0, dtype=np.intp)
        return empty, empty
    # Per-column reductions: numpy reduces 1-D arrays much faster than axis=0 of (N, 2).
    x, y = pos[:, 0], pos[:, 1]
    x0, y0 = float(x.min()), float(y.min())
    span_x, span_y = float(x.max()) - x0, float(y.max()) - y0
    # Far more cells than pucks only costs memory: widen the cells instead.
    cell = max(cell, (span_x * span_y / (4.0 * n)) ** 0.5)
    # A hair wider than the largest reach: two pucks exactly one reach apart
    # can count as overlapping after rounding, and their cell indices must
    # then not round two cells apart.
    inv = 1.0 / (cell * (1.0 + 1e-9))
    cx = ((x - x0) * inv).astype(np.intp)
    cy = ((y - y0) * inv).astype(np.intp)
    # Size the grid from the cells actually used, not span / cell: the two can
    # round differently (0.6 * (1 / 0.2) is 3.0 but 0.6 / 0.2 is 2.999...), and
    # a grid one cell short sends the neighbour look-ups out of bounds.
    # One margin cell on each side for the neighbours.
    nx, ny = int(cx.max()) + 3, int(cy.max()) + 3
    n_cells = nx * ny
    key = cx * ny + cy + (ny + 1)  # column-major cell number, shifted past the margin
    order = _argsort_cells(key, n_cells)
    skey = key.take(order)
    # start[c]: where cell c begins in sorted order; one extra cell as the end.
    count = np.bincount(skey, minlength=n_cells + 1)
    start = np.cumsum(count) - count
    # Each puck (at sorted position p, in cell c) looks at two runs of the
    # sorted order: the pucks after it in its own cell together with cell
    # c + 1 (the next one up), and the three cells of the next column
    # c + ny - 1 .. c + ny + 1. The other four neighbours see it from their side.
    idx = np.arange(n)
    first = start[skey + np.array([[0], [ny - 1]])]
    first[0] = idx + 1
    stop = start[skey + np.array([[2], [ny + 2]])]
    a, b = _expand_ranges(np.tile(idx, 2), first.ravel(), (stop - first).ravel())
    return order.take(a), order.take(b)


def _expand_ranges(owner: np.ndarray, first: np.ndarray, count: np.ndarray):
    """For each k, pair owner[k] with first[k], first[k]+1, ..., first[k]+count[k]-1."""
    total = int(count.sum())
    if total == 0:
        empty = np.empty(0, dtype=np.intp)
        return empty, empty
    offset = np.cumsum(count) - count
    a = np.repeat(owner, count)
    b = np.repeat(first - offset, count) + np.arange(total)
    return a, b


def _argsort_cells(key: np.ndarray, n_cells: int) -> np.ndarray:
    """argsort of cell numbers, as a radix sort: numpy's stable sort of 16-bit
    integers is a radix sort, ten times faster than a comparison sort here."""
    if n_cells <= 1 << 16:
        return np.argsort(key.astype(np.uint16), kind="stable")
    if n_cells <= 1 << 32:  # two 16-bit passes, low half first
        low = np.argsort((key & 0xFFFF).astype(np.uint16), kind="stable")
        return low[np.argsort((key[low] >> 16).astype(np.uint16), kind="stable")]
    return np.argsort(key, kind="stable")


# ---------------------------------------------------------------- pair response


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
        return lengths(self.pos_i_after - self.pos_j_after) - self.reach_m

    @classmethod
    def empty(cls) -> Collisions:
        z = np.empty(0)
        zi = np.empty(0, dtype=np.intp)
        z2 = np.empty((0, 2))
        return cls(zi, zi, z2, z2, z, z, *([z2] * 8))

    def __len__(self) -> int:
        return len(self.i)

    @classmethod
    def concatenate(cls, parts: list[Collisions]) -> Collisions:
        if not parts:
            return cls.empty()
        if len(parts) == 1:
            return parts[0]
        return cls(*(np.concatenate([getattr(p, f) for p in parts]) for f in cls.__dataclass_fields__))

    def take(self, k: np.ndarray) -> Collisions:
        """Only the collisions k (indices into this record)."""
        return Collisions(*(getattr(self, f).take(k, axis=0) for f in self.__dataclass_fields__))


def disjoint_rounds(i: np.ndarray, j: np.ndarray, n: int) -> list[np.ndarray]:
    """Split pairs into rounds in which no puck appears twice.

    Keeps the pairs' order: a pair goes into the first round after every
    earlier pair that shares a puck with it. Resolving the rounds in turn is
    therefore the same as resolving the pairs one by one in the given order.
    """
    m = len(i)
    if m == 0:
        return []
    uses = np.bincount(np.concatenate([i, j]), minlength=n)
    if uses.max() == 1:
        return [np.arange(m)]  # the common case: no puck in two pairs
    # A pair whose pucks are in no other pair can go in any round: the first.
    # For the others, level[k] = how many earlier pairs form a chain into
    # pair k. One pass in Python over just those, a handful per step.
    shared = np.flatnonzero((uses.take(i) > 1) | (uses.take(j) > 1))
    busy_until: dict[int, int] = {}  # per puck: first level at which it is free again
    levels = []
    for a, b in zip(i.take(shared).tolist(), j.take(shared).tolist(), strict=True):
        lvl = max(busy_until.get(a, 0), busy_until.get(b, 0))
        levels.append(lvl)
        busy_until[a] = busy_until[b] = lvl + 1
    level = np.zeros(m, dtype=np.intp)
    level[shared] = levels
    order = np.argsort(level, kind="stable")
    bounds = np.searchsorted(level.take(order), np.arange(max(levels) + 2))
    return [order[bounds[r] : bounds[r + 1]] for r in range(len(bounds) - 1)]


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
) -> list[Collisions]:
    """Collide the overlapping pairs (i, j) in order, in place; see module doc.

    Returns one record per round that collided anything; `Collisions.concatenate`
    joins them, which is left to whoever reads them.
    """
    if mode not in CORRECTION_MODES:
        raise ValueError(f"puck_correction must be one of {CORRECTION_MODES}, not {mode!r}")
    records = []
    for r in disjoint_rounds(i, j, len(pos)):
        c = _resolve_round(pos, vel, radius, mass, i.take(r), j.take(r), cr_puck, mode, dt_s)
        if c is not None:
            records.append(c)
    return records


def push_apart(pos: np.ndarray, radius: np.ndarray, mass: np.ndarray, i: np.ndarray, j: np.ndarray) -> None:
    """Move each overlapping pair (i, j) apart along its line of centres, in place.

    Positions only: each puck moves its mass-weighted share of the overlap
    (the lighter one more), so the centre of mass stays put. Pairs that share
    a puck add their pushes. Used for the small overlaps a correction leaves
    behind; velocities (and so energy and momentum) are untouched.
    """
    n, dist = unit_vectors(rows.take(pos, i) - rows.take(pos, j))
    left = np.maximum(pair_reach(radius, i, j) - dist, 0.0)
    m_i, m_j = mass.take(i), mass.take(j)
    push = (left / (m_i + m_j))[:, None] * n
    rows.add_at(pos, i, push * m_j[:, None])
    rows.add_at(pos, j, -push * m_i[:, None])


def squared_lengths(d: np.ndarray) -> np.ndarray:
    """Squared length of each row of d (two numpy operations on the whole array)."""
    dd = d * d
    return dd[:, 0] + dd[:, 1]


def lengths(d: np.ndarray) -> np.ndarray:
    """Length of each row of d."""
    return np.sqrt(squared_lengths(d))


def unit_vectors(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors along the rows of d and their lengths; zero rows get a fixed normal."""
    dist = lengths(d)
    # np.count_nonzero, here and below, costs a quarter of .all() or .any(),
    # whose Python-level wrappers dominate on a few dozen pairs.
    if np.count_nonzero(dist) == len(dist):
        return d / dist[:, None], dist
    safe = dist > 0.0
    n = np.where(safe[:, None], d / np.where(safe, dist, 1.0)[:, None], _FALLBACK_NORMAL)
    return n, dist


def dot_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]


def _resolve_round(pos, vel, radius, mass, a, b, cr, mode, dt_s) -> Collisions | None:
    """Resolve pairs that share no puck, all at once (see `disjoint_rounds`).

    Returns the record of the pairs that collided, None if none did.
    """
    x1, x2 = rows.take(pos, a), rows.take(pos, b)
    r2 = radius.take(b)
    reach = radius.take(a) + r2
    n, dist = unit_vectors(x1 - x2)
    overlap = reach - dist
    if np.count_nonzero(overlap > 0.0) < len(overlap):  # an earlier round already parted some pairs
        keep = np.flatnonzero(overlap > 0.0)
        if len(keep) == 0:
            return None
        a, b, x1, x2, r2, reach, n, overlap = (v.take(keep, axis=0) for v in (a, b, x1, x2, r2, reach, n, overlap))
    v1, v2 = rows.take(vel, a), rows.take(vel, b)
    m1, m2 = mass.take(a), mass.take(b)
    m_sum = m1 + m2
    share1 = m2 / m_sum  # puck 1's part of a change in relative motion
    share2 = m1 / m_sum
    vrel = v1 - v2
    vn = dot_rows(vrel, n)
    contact_from = x2

    # Each pair gets: a normal, the relative normal speed along it, and `move`,
    # how far the correction separates the pair along that normal.
    approach = vn < -REST_SPEED_MPS
    if mode == "off":
        move = None
    else:
        # Two-step: back up t_p = overlap / |vn|, then forward t_p with the
        # restitution-1 velocities, so each puck moves twice its share of the
        # overlap. An overlap deeper than one step of approach can explain is
        # capped there; the push-apart below takes the rest.
        move = 2.0 * np.minimum(overlap, -vn * dt_s)
    if mode == "perfect-kiss":
        # Back up along the full relative motion to first contact,
        # |d - vrel t| = reach with t > 0 (the larger root), and collide there.
        d = x1 - x2
        vv = squared_lengths(vrel)
        dv = dot_rows(d, vrel)
        disc = np.maximum(dv * dv - vv * (squared_lengths(d) - reach * reach), 0.0)
        moving = vv > REST_SPEED_MPS**2
        t_back = (dv + np.sqrt(disc)) / np.where(moving, vv, 1.0)
        # Only an overlap that this step's motion explains can be backed up.
        kiss = moving & (t_back >= 0.0) & (t_back <= dt_s * (1.0 + 1e-9) + 1e-15)
        if kiss.any():
            t_b = np.where(kiss, t_back, 0.0)[:, None]
            c2 = x2 - v2 * t_b
            nk, _ = unit_vectors(x1 - v1 * t_b - c2)
            vnk = dot_rows(vrel, nk)
            kiss2 = kiss[:, None]
            n = np.where(kiss2, nk, n)
            vn = np.where(kiss, vnk, vn)
            contact_from = np.where(kiss2, c2, x2)
            # Approaching is judged at the contact time; moving forward t_b
            # with the new velocities separates them by (1 + cr) |vn| t_b.
            approach = np.where(kiss, vnk < 0.0, approach)
            move = np.where(kiss, -(1.0 + cr) * vnk * t_b[:, 0], move)

    all_approach = np.count_nonzero(approach) == len(approach)
    jn = -(1.0 + cr) * vn  # change of relative normal speed
    if not all_approach:
        jn = np.where(approach, jn, 0.0)
    v1_out = v1 + (jn * share1)[:, None] * n
    v2_out = v2 - (jn * share2)[:, None] * n
    rows.put(vel, a, v1_out)
    rows.put(vel, b, v2_out)
    x1_out, x2_out = x1, x2
    if move is not None:
        if not all_approach:
            move = np.where(approach, move, 0.0)
        x1_out = x1 + (move * share1)[:, None] * n
        x2_out = x2 - (move * share2)[:, None] * n
        # Whatever still overlaps (separating, resting, created on top of each
        # other, or capped above) is pushed apart by mass-weighted shares.
        d = x1_out - x2_out
        if np.count_nonzero(squared_lengths(d) < reach * reach):
            n_now, dist_now = unit_vectors(d)
            left = np.maximum(reach - dist_now, 0.0)
            x1_out = x1_out + (left * share1)[:, None] * n_now
            x2_out = x2_out - (left * share2)[:, None] * n_now
        rows.put(pos, a, x1_out)
        rows.put(pos, b, x2_out)

    contact = contact_from + n * r2[:, None]
    record = Collisions(a, b, n, contact, overlap, reach, x1, x2, x1_out, x2_out, v1, v2, v1_out, v2_out)
    if all_approach:
        return record
    hit = np.flatnonzero(approach)
    return record.take(hit) if len(hit) else None
