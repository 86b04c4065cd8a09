"""Collision detection and response for round pucks in a walled box.

Everything here works on the table's numpy arrays in place and knows nothing of
pygame. Three parts:

* `resolve_walls`: push pucks back inside the box, bounce them off the walls.
* `find_overlapping_pairs`: the broadphase. A uniform grid in numpy finds the
  candidate pairs in O(N) work, pucks too big for the grid are checked against
  everyone by vectorised brute force, and small tables use brute force alone.
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

CORRECTION_MODES = ("off", "two-step", "perfect-kiss")

# Below this many pucks, checking every pair with one numpy expression is
# cheaper than building a grid.
BRUTE_FORCE_MAX_PUCKS = 48
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
    p, r = (pos, radius) if only is None else (pos[only], radius[only])
    r = r[:, None]
    outside = (p < r) | (p > size_m - r)
    rows = np.flatnonzero(outside[:, 0] | outside[:, 1])
    if only is not None:
        rows = only[rows]
    if len(rows) == 0:
        return 0
    p, v = pos[rows], vel[rows]
    lo = radius[rows][:, None]
    hi = size_m - lo
    below, above = p < lo, p > hi
    if correction:
        target = np.where(below, 2.0 * lo - p, np.where(above, 2.0 * hi - p, p))
    else:
        target = np.where(below, lo, np.where(above, hi, p))
    into = (below & (v < 0.0)) | (above & (v > 0.0))
    vel[rows] = np.where(into, -cr_wall * v, v)
    # A mirror of a huge penetration can land past the opposite wall; a puck
    # wider than the table sits in the middle.
    clipped = np.clip(target, lo, np.maximum(hi, lo))
    pos[rows] = np.where(hi < lo, 0.5 * size_m, clipped)
    return int(np.count_nonzero(into))


# ---------------------------------------------------------------- broadphase


def brute_force_pairs(pos: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All overlapping pairs (i < j) by checking every pair; sorted by (i, j)."""
    return overlapping_pairs(pos, radius, *np.triu_indices(len(pos), k=1))


def find_overlapping_pairs(pos: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All overlapping pairs (i < j), sorted by (i, j): the same as brute force."""
    return overlapping_pairs(pos, radius, *find_candidate_pairs(pos, radius))


def find_candidate_pairs(pos: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (i < j) that may overlap: a superset of the overlapping pairs, each once.

    Uses a uniform grid with cells as wide as the largest ordinary puck. Each
    puck is compared with the pucks in its own cell and in four of its eight
    neighbours (the other four see it from their side), so each candidate pair
    is produced once. Pucks more than twice the mean radius are paired with
    every puck, so one giant puck cannot bloat the grid. Small tables pair
    everyone with everyone. Pucks that move a little (less than a cell) keep
    their overlaps within these candidates, which the step uses to look again
    after the corrections.
    """
    n = len(pos)
    if n <= BRUTE_FORCE_MAX_PUCKS:
        return np.triu_indices(n, k=1)
    r_max = float(radius.max())
    # No puck can be twice the mean while the largest is within twice the smallest.
    big = radius > 2.0 * radius.mean() if r_max > 2.0 * float(radius.min()) else None
    if big is not None and big.any():
        small_idx = np.flatnonzero(~big)
        gi, gj = _grid_candidates(pos[small_idx], 2.0 * float(radius[small_idx].max()))
        i_parts, j_parts = [small_idx[gi]], [small_idx[gj]]
        for b in np.flatnonzero(big):
            others = np.arange(n)
            others = others[(others != b) & (~big | (others > b))]  # each big-big pair once
            i_parts.append(np.full(len(others), b))
            j_parts.append(others)
        i, j = np.concatenate(i_parts), np.concatenate(j_parts)
    else:
        i, j = _grid_candidates(pos, 2.0 * r_max)
    return np.minimum(i, j), np.maximum(i, j)


def overlapping_pairs(
    pos: np.ndarray, radius: np.ndarray, i: np.ndarray, j: np.ndarray, min_overlap_m: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """The candidate pairs (i, j) that overlap by more than min_overlap_m, sorted by (i, j)."""
    d = pos[i] - pos[j]
    reach = radius[i] + radius[j] - min_overlap_m
    hit = np.einsum("ij,ij->i", d, d) < reach * reach
    i, j = i[hit], j[hit]
    if len(i) > 1:
        order = np.argsort(i * len(pos) + j)
        i, j = i[order], j[order]
    return i, j


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
    key = (cx + 1) * ny + (cy + 1)
    order = _argsort_cells(key, nx * ny)
    skey = key[order]
    count = np.bincount(skey, minlength=nx * ny)
    start = np.cumsum(count) - count
    # Own cell, then four of the eight neighbours (the other four see this
    # cell from their side): (0,0), (+1,-1), (+1,0), (+1,+1), (0,+1).
    cells = skey + np.array([0, ny - 1, ny, ny + 1, 1])[:, None]
    first = start[cells]
    size = count[cells]
    # In its own cell a puck pairs only with the pucks after it in sorted order.
    idx = np.arange(n)
    size[0] -= idx + 1 - first[0]
    first[0] = idx + 1
    busy = np.flatnonzero(size.ravel() != 0)  # most (puck, cell) slots are empty
    a, b = _expand_ranges(busy % n, first.ravel()[busy], size.ravel()[busy])
    return order[a], order[b]


def _argsort_cells(key: np.ndarray, n_cells: int) -> np.ndarray:
    """argsort of cell numbers, as a radix sort: numpy's stable sort of 16-bit
    integers is a radix sort, ten times faster than a comparison sort here."""
    if n_cells <= 1 << 16:
        return np.argsort(key.astype(np.uint16), kind="stable")
    if n_cells <= 1 << 32:  # two 16-bit passes, low half first
        low = np.argsort((key & 0xFFFF).astype(np.uint16), kind="stable")
        return low[np.argsort((key[low] >> 16).astype(np.uint16), kind="stable")]
    return np.argsort(key, kind="stable")


def _expand_ranges(owner: np.ndarray, start: np.ndarray, count: np.ndarray):
    """For each k, pair owner[k] with start[k], start[k]+1, ..., start[k]+count[k]-1."""
    total = int(count.sum())
    if total == 0:
        empty = np.empty(0, dtype=np.intp)
        return empty, empty
    offset = np.cumsum(count) - count
    a = np.repeat(owner, count)
    b = np.repeat(start - offset, count) + np.arange(total)
    return a, b


# ---------------------------------------------------------------- pair response


@dataclass
class Collisions:
    """What the pair resolution of one step did, for diagnostics and drawing.

    One row per collision (an approaching pair whose velocities were changed):
    puck rows i and j, the contact normal (unit, from j to i), the contact
    point, the overlap when detected and the gap (separation) left after the
    position correction, both in metres (a negative gap: still overlapping),
    and both pucks' positions and velocities before and after this collision.
    """

    i: np.ndarray
    j: np.ndarray
    normal: np.ndarray
    contact_m: np.ndarray
    overlap_m: np.ndarray
    separation_m: np.ndarray
    pos_i_before: np.ndarray
    pos_j_before: np.ndarray
    pos_i_after: np.ndarray
    pos_j_after: np.ndarray
    vel_i_before: np.ndarray
    vel_j_before: np.ndarray
    vel_i_after: np.ndarray
    vel_j_after: np.ndarray

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


def disjoint_rounds(i: np.ndarray, j: np.ndarray, n: int) -> list[np.ndarray]:
    """Split pairs into rounds in which no puck appears twice.

    Keeps the pairs' order: a pair goes into the first round after every
    earlier pair that shares a puck with it. Resolving the rounds in turn is
    therefore the same as resolving the pairs one by one in the given order.
    """
    m = len(i)
    if m == 0:
        return []
    if np.bincount(np.concatenate([i, j]), minlength=n).max() == 1:
        return [np.arange(m)]  # the common case: no puck in two pairs
    # level[k] = how many earlier pairs form a chain into pair k. One pass in
    # Python: the pairs of one step are a few per cent of the pucks.
    busy_until = [0] * n  # per puck: first level at which it is free again
    level = [0] * m
    for k, (a, b) in enumerate(zip(i.tolist(), j.tolist(), strict=True)):
        lvl = max(busy_until[a], busy_until[b])
        level[k] = lvl
        busy_until[a] = busy_until[b] = lvl + 1
    level = np.asarray(level)
    order = np.argsort(level, kind="stable")
    bounds = np.searchsorted(level[order], np.arange(int(level.max()) + 2))
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
) -> Collisions:
    """Collide the overlapping pairs (i, j) in order, in place; see module doc."""
    if mode not in CORRECTION_MODES:
        raise ValueError(f"puck_correction must be one of {CORRECTION_MODES}, not {mode!r}")
    parts = []
    for r in disjoint_rounds(i, j, len(pos)):
        c = _resolve_round(pos, vel, radius, mass, i[r], j[r], cr_puck, mode, dt_s)
        if len(c):
            parts.append(c)
    return Collisions.concatenate(parts)


def push_apart(pos: np.ndarray, radius: np.ndarray, mass: np.ndarray, i: np.ndarray, j: np.ndarray) -> None:
    """Move each overlapping pair (i, j) apart along its line of centres, in place.

    Positions only: each puck moves its mass-weighted share of the overlap
    (the lighter one more), so the centre of mass stays put. Pairs that share
    a puck add their pushes. Used for the small overlaps a correction leaves
    behind; velocities (and so energy and momentum) are untouched.
    """
    n, dist = unit_vectors(pos[i] - pos[j])
    left = np.maximum(radius[i] + radius[j] - dist, 0.0)
    m_i, m_j = mass[i], mass[j]
    push = (left / (m_i + m_j))[:, None] * n
    np.add.at(pos, i, push * m_j[:, None])
    np.add.at(pos, j, -push * m_i[:, None])


def unit_vectors(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors along the rows of d and their lengths; zero rows get a fixed normal."""
    dist = np.hypot(d[:, 0], d[:, 1])
    safe = dist > 0.0
    n = np.where(safe[:, None], d / np.where(safe, dist, 1.0)[:, None], _FALLBACK_NORMAL)
    return n, dist


def dot_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]


def _resolve_round(pos, vel, radius, mass, a, b, cr, mode, dt_s) -> Collisions:
    """Resolve pairs that share no puck, all at once (see `disjoint_rounds`)."""
    x1, x2 = pos[a], pos[b]
    reach = radius[a] + radius[b]
    x1_in, x2_in = x1, x2
    n, dist = unit_vectors(x1 - x2)
    overlap = reach - dist
    touching = overlap > 0.0
    if not touching.all():  # an earlier round already parted some pairs
        keep = np.flatnonzero(touching)
        if len(keep) == 0:
            return Collisions.empty()
        a, b, x1, x2, reach, n, overlap = a[keep], b[keep], x1[keep], x2[keep], reach[keep], n[keep], overlap[keep]
        x1_in, x2_in = x1, x2
    v1, v2 = vel[a], vel[b]
    v1_in, v2_in = v1, v2
    m1, m2 = mass[a], mass[b]
    share1 = m2 / (m1 + m2)  # puck 1's part of a change in relative motion
    share2 = m1 / (m1 + m2)
    vrel = v1 - v2
    vn = dot_rows(vrel, n)
    contact_from = x2

    # Each pair gets: a normal, the relative normal speed along it, and `move`,
    # how far the correction separates the pair along that normal.
    approach = vn < -REST_SPEED_MPS
    if mode == "off":
        move = np.zeros(len(a))
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
        vv = dot_rows(vrel, vrel)
        dv = dot_rows(d, vrel)
        disc = np.maximum(dv * dv - vv * (dot_rows(d, d) - reach * reach), 0.0)
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

    jn = np.where(approach, -(1.0 + cr) * vn, 0.0)  # change of relative normal speed
    v1 = v1 + (jn * share1)[:, None] * n
    v2 = v2 - (jn * share2)[:, None] * n
    vel[a] = v1
    vel[b] = v2
    if mode != "off":
        move = np.where(approach, move, 0.0)
        x1 = x1 + (move * share1)[:, None] * n
        x2 = x2 - (move * share2)[:, None] * n
        # Whatever still overlaps (separating, resting, created on top of each
        # other, or capped above) is pushed apart by mass-weighted shares.
        n_now, dist_now = unit_vectors(x1 - x2)
        left = reach - dist_now
        if (left > 0.0).any():
            left = np.maximum(left, 0.0)
            x1 = x1 + (left * share1)[:, None] * n_now
            x2 = x2 - (left * share2)[:, None] * n_now
        pos[a] = x1
        pos[b] = x2

    if approach.all():
        k = slice(None)  # the usual case: no index array needed
    elif approach.any():
        k = np.flatnonzero(approach)
    else:
        return Collisions.empty()
    gap = np.hypot(*(x1[k] - x2[k]).T) - reach[k]
    contact = contact_from[k] + n[k] * radius[b[k]][:, None]
    return Collisions(
        a[k],
        b[k],
        n[k],
        contact,
        overlap[k],
        gap,
        x1_in[k],
        x2_in[k],
        x1[k],
        x2[k],
        v1_in[k],
        v2_in[k],
        v1[k],
        v2[k],
    )
