"""Broad phase: which pairs of pucks overlap, found without checking every pair.

A uniform grid finds the candidate pairs in O(N) work: each puck is binned
into a column as wide as the largest pair's reach, cut into cells a quarter
as tall; the cell numbers are sorted (a radix sort), and each puck is paired
with the pucks of the cells within one reach of its own. Pucks too big for
the grid are checked against everyone, and small tables use brute force
alone. `NeighbourList` keeps the grid's pairs, widened by a skin, for as many
steps as they stay valid (a Verlet list), so the grid is rebuilt only every
few steps. `overlapping_pairs` then keeps the candidates that really overlap,
sorted by (i, j).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from airtable.physics import vectors
from airtable.physics.columns import frozen, same_bits

# Below this many pucks, checking every pair with one numpy expression is
# cheaper than building a grid.
BRUTE_FORCE_MAX_PUCKS = 48
# The neighbour list's skin, in mean radii: a wider skin is rebuilt less often
# but holds more pairs. In the benchmark gas (1 m/s, dt = 1/120 s, fastest
# pucks near 3 m/s) 1.5 radii lasts about four steps and was the fastest of
# 0.5, 1, 1.5 and 2.
SKIN_RADII = 1.5
# Grid cells per reach, up a column. Each puck searches its own column up to a
# reach above it and the next column a reach above and below: 4.5 square
# reaches with square cells, 3.4 with cells a quarter as tall, against the half
# disc of 1.57 that it needs. More rows are more cells to count; 4 was the
# fastest of 1 to 6 for the benchmark gas at N = 10000 (3 within 1 %).
ROWS_PER_CELL = 4


def brute_force_pairs(pos: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All overlapping pairs (i < j) by checking every pair; sorted by (i, j)."""
    i, j = np.triu_indices(len(pos), k=1)
    return overlapping_pairs(pos, i, j, pair_reach(radius, i, j))


def find_overlapping_pairs(pos: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All overlapping pairs (i < j), sorted by (i, j): the same as brute force."""
    i, j = find_candidate_pairs(pos, radius)
    return overlapping_pairs(pos, i, j, pair_reach(radius, i, j))


def find_candidate_pairs(
    pos: np.ndarray, radius: np.ndarray, margin_m: float = 0.0, closer: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (i < j) that may be closer than their reach plus margin_m, each once.

    With `closer`, only those closer than the largest reach plus margin_m.

    Uses a uniform grid with columns as wide as the largest ordinary pair's
    reach plus the margin (cells ROWS_PER_CELL times shorter). Each puck is
    compared with the pucks after it in its own column up to that reach above
    it, and with the pucks of the next column up to that reach above or below
    (the pucks below it and in the column before see it from their side), so
    each candidate pair is produced once. Pucks more than twice the
    mean radius are paired with every puck, so one giant puck cannot bloat the
    grid. Small tables pair everyone with everyone.
    """
    n = len(pos)
    if n <= BRUTE_FORCE_MAX_PUCKS:
        i, j = np.triu_indices(n, k=1)
        if closer and n:
            near = _closer_than(pos, i, j, 2.0 * float(radius.max()) + margin_m)
            i, j = i.take(near), j.take(near)
        return i, j
    r_max = float(radius.max())
    big = too_big_for_the_grid(radius)
    if big is not None and big.any():
        small_idx = np.flatnonzero(~big)
        cell = 2.0 * float(radius.take(small_idx).max()) + margin_m
        gi, gj = _grid_candidates(vectors.take(pos, small_idx), cell)
        i_parts, j_parts = [small_idx.take(gi)], [small_idx.take(gj)]
        for b in np.flatnonzero(big):
            others = np.arange(n)
            others = others[(others != b) & (~big | (others > b))]  # each big-big pair once
            i_parts.append(np.full(len(others), b))
            j_parts.append(others)
        i, j = np.concatenate(i_parts), np.concatenate(j_parts)
        if closer:
            near = _closer_than(pos, i, j, 2.0 * r_max + margin_m)
            i, j = i.take(near), j.take(near)
    else:
        i, j = _grid_candidates(pos, 2.0 * r_max + margin_m, closer)
    return np.minimum(i, j), np.maximum(i, j)


def too_big_for_the_grid(radius: np.ndarray) -> np.ndarray | None:
    """Which pucks are more than twice the mean radius (the grid pairs those with everyone); None when none
    can be: no puck is twice the mean while the largest is within twice the smallest."""
    return radius > 2.0 * radius.mean() if float(radius.max()) > 2.0 * float(radius.min()) else None


def pairs_near(pos: np.ndarray, radius: np.ndarray, rows: np.ndarray, margin_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (i < j) with a puck of `rows` in them whose centres are closer than r_i + r_j + margin_m,
    each once, sorted by (i, j).

    The grid of find_candidate_pairs, searched around each of `rows` only: a few pucks dragged fast
    through a crowd look at the pucks near them, not every pair of the crowd at that reach. Pucks
    too big for the grid (twice the mean radius) are paired with every one of `rows`, and each big
    one of `rows` with every puck. A handful of rows look at every puck (NEAR_BRUTE_FORCE_LOOKS).
    """
    n = len(pos)
    rows = np.unique(np.asarray(rows, dtype=np.intp))  # (rows, not pair keys: a small range, fast)
    if n < 2 or len(rows) == 0:
        empty = np.empty(0, dtype=np.intp)
        return empty, empty
    if len(rows) * n <= NEAR_BRUTE_FORCE_LOOKS:  # a few rows: each against every puck, no grid to build
        return each_pair_once(n, *_near_each(pos, radius, rows, margin_m))
    big = too_big_for_the_grid(radius)
    big = np.zeros(n, dtype=bool) if big is None else big
    small = (~big).nonzero()[0]
    a, b = [], []
    if len(small) > 1 and (~big.take(rows)).any():
        cell = 2.0 * float(radius.take(small).max()) + margin_m
        ga, gb = _grid_around(vectors.take(pos, small), cell, np.searchsorted(small, rows[~big.take(rows)]))
        a.append(small.take(ga))
        b.append(small.take(gb))
    for r in rows[big.take(rows)].tolist():  # a big one of rows: with every puck
        a.append(np.full(n, r))
        b.append(np.arange(n))
    for r in big.nonzero()[0].tolist():  # a big puck: with every one of rows
        a.append(rows)
        b.append(np.full(len(rows), r))
    a, b = np.concatenate(a), np.concatenate(b)
    near = _closer_than(pos, a, b, pair_reach(radius, a, b) + margin_m)
    return each_pair_once(n, a.take(near), b.take(near))


def _near_each(pos: np.ndarray, radius: np.ndarray, rows: np.ndarray, margin_m: float):
    """(a, b): each of `rows` (a) with every puck b closer than r_a + r_b + margin_m, itself too
    (the arithmetic of _closer_than, without gathering a copy of each puck for each row)."""
    z = vectors.as_complex(np.ascontiguousarray(pos, dtype=np.float64))
    reach = (radius.take(rows)[:, None] + radius[None, :]) + margin_m  # (rows, pucks): at most NEAR_BRUTE_FORCE_LOOKS
    d = z.take(rows)[:, None] - z[None, :]
    k, b = (d.real * d.real + d.imag * d.imag < reach * reach).nonzero()  # (rows_near's arithmetic, all rows at once)
    return rows.take(k), b


def rows_near(z: np.ndarray, radius: np.ndarray, centre: complex, radius_m: float, margin_m: float) -> np.ndarray:
    """The rows of the pucks at z (complex x + iy) closer to a puck of `radius_m` at `centre` than their
    reach plus margin_m: |z - centre| < (radius_m + r) + margin_m, in increasing order."""
    reach = (radius_m + radius) + margin_m
    return (vectors.squared_abs(z - centre) < reach * reach).nonzero()[0]


def pair_keys(n: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """One key per pair (a, b) of n pucks, whichever way round: i * n + j for i <= j, which sorts as (i, j) does."""
    return np.minimum(a, b) * n + np.maximum(a, b)


def each_pair_once(n: int, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pairs (a, b) of n pucks as (i < j), each once, sorted by (i, j); a puck paired with itself dropped."""
    key = np.sort(pair_keys(n, a, b)[a != b])
    first = np.ones(len(key), dtype=bool)
    first[1:] = key[1:] != key[:-1]
    key = key[first]  # each pair once (np.unique hashes such keys, 20 times slower)
    return key // n, key % n


def _grid_around(pos: np.ndarray, cell: float, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(a, b): each of `rows` (a) with every puck b in the grid's cells within `cell` of its own, itself too."""
    order, skey, ends, ny = _sort_into_cells(pos, cell)
    ends = np.concatenate([np.zeros(ny + 1, dtype=ends.dtype), ends])  # a spare column on the left
    where = np.empty(len(pos), dtype=np.intp)
    where[order] = np.arange(len(pos))  # each puck's place in the sorted order
    c = skey.take(where.take(rows)) + ny + 1  # the cell of each of rows, in the padded ends
    rise = ROWS_PER_CELL  # a cell is a reach / ROWS_PER_CELL tall
    first = np.stack([ends.take(c + k * ny - rise - 1) for k in (-1, 0, 1)])  # the columns before, own, after
    stop = np.stack([ends.take(c + k * ny + rise) for k in (-1, 0, 1)])
    at, b = _expand_ranges(first, stop)
    return rows.take(at), order.take(b)


def clusters(n: int, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Each of n pucks' cluster through the pairs (i, j): the least row it reaches along them."""
    cluster = np.arange(n)
    for _ in range(n):  # (bounded: each pass carries the least row one pair further)
        least = np.minimum(cluster.take(i), cluster.take(j))
        if not np.count_nonzero((least != cluster.take(i)) | (least != cluster.take(j))):
            break
        np.minimum.at(cluster, i, least)
        np.minimum.at(cluster, j, least)
    return cluster


def touching(pos: np.ndarray, i: np.ndarray, j: np.ndarray, reach) -> np.ndarray:
    """Which pairs (i, j) touch or overlap (within round-off of their reach)."""
    return squared_distances(pos, i, j) <= (reach * (1.0 + 1e-9)) ** 2


def pair_reach(radius: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Sum of the radii of each pair: closer centres than this overlap."""
    return radius.take(i) + radius.take(j)


# pairs_near looks from each of its rows at every puck, with no grid, up to this many looks (rows
# times pucks): sorting 10000 pucks into the grid costs as much as some 150000 looks.
NEAR_BRUTE_FORCE_LOOKS = 100_000

# Once one candidate pair in this many overlaps (a pile, not a gas), picking the overlapping
# pairs in a kept sorted order beats sorting them.
SORTED_PICK_SHARE = 8


def overlapping_pairs(
    pos: np.ndarray,
    i: np.ndarray,
    j: np.ndarray,
    reach: np.ndarray,
    sorted_order: Callable[[], np.ndarray] | None = None,
    reach_sq: np.ndarray | float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The candidate pairs (i, j) closer than `reach`, sorted by (i, j).

    `reach_sq`, if given, is reach * reach already worked out (NeighbourList.reach_squared).
    `sorted_order`: see `pairs_where`.
    """
    close = squared_distances(pos, i, j) < (reach * reach if reach_sq is None else reach_sq)
    return pairs_where(close, i, j, len(pos), sorted_order)


def pairs_where(
    close: np.ndarray, i: np.ndarray, j: np.ndarray, n: int, sorted_order: Callable[[], np.ndarray] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The pairs (i, j) (of n pucks) where `close` is True, sorted by (i, j).

    `sorted_order`, if given, returns the permutation that sorts the
    candidates by (i, j) (NeighbourList.sorted_order, worked out once per
    build): where many pairs are close (a pile), they are picked in that order
    instead of being sorted each time; the result is the same.
    """
    if sorted_order is not None and np.count_nonzero(close) * SORTED_PICK_SHARE >= len(i):
        order = sorted_order()
        hit = order.take(close.take(order).nonzero()[0])
        return i.take(hit), j.take(hit)
    hit = close.nonzero()[0]
    i, j = i.take(hit), j.take(hit)
    if len(i) > 1:  # one key i * n + j sorts as (i, j) does, twice as fast as lexsort on a few hundred
        by_pair = np.argsort(i * n + j, kind="stable")
        i, j = i.take(by_pair), j.take(by_pair)
    return i, j


def squared_distances(pos: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """|pos[i] - pos[j]|^2 for each pair: the sums of vectors.squared_lengths, in fewer passes."""
    # A puck's (x, y) as one complex number: two 1-D takes instead of 2-D ones.
    z = vectors.as_complex(np.ascontiguousarray(pos, dtype=np.float64))
    d = z.take(i)
    d -= z.take(j)
    dd = d.view(np.float64)  # back to x, y, x, y...
    dd *= dd
    return dd[0::2] + dd[1::2]


def _closer_than(pos: np.ndarray, i: np.ndarray, j: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """Indices k of the pairs whose centres are less than reach[k] apart."""
    return (squared_distances(pos, i, j) < reach * reach).nonzero()[0]


class Partners:
    """Each puck's partners in the pairs (i, j), looked up by row (a CSR index)."""

    def __init__(self, i: np.ndarray, j: np.ndarray, n: int) -> None:
        self.i, self.j = i, j
        rows = np.concatenate([i, j])
        order = _argsort_cells(rows, n)  # rows are cell numbers of a kind: the same radix sort
        self._others = np.concatenate([j, i]).take(order)
        self._starts = [0, *np.cumsum(np.bincount(rows, minlength=n)).tolist()]  # where each row's partners begin
        self._of: dict[int, list[int]] = {}  # those asked for (the pi demo asks for its two pucks' 30000 times a step)

    def of(self, k: int) -> list[int]:
        """Puck k's partners, in increasing order (however the pairs were found). Not to be changed."""
        out = self._of.get(k)
        if out is None:
            out = self._of[k] = sorted(self._others[self._starts[k] : self._starts[k + 1]].tolist())
        return out


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

    def pairs(
        self, pos: np.ndarray, radius: np.ndarray, moved: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(i, j, reach) for every pair that may overlap now: i < j, reach = sum of the radii.

        `moved`, if given, are the only rows moved since the last call (which
        checked every row): checking just those costs a few operations instead
        of a pass over every puck.
        """
        if moved is not None and self._built_pos is not None and len(pos) == len(self._built_pos):
            if len(moved) == 0 or self._still_valid(vectors.take(pos, moved), radius.take(moved), moved):
                return self._i, self._j, self._reach
        if not self._still_valid(pos, radius):
            self._build(pos, radius)
        return self._i, self._j, self._reach

    def pairs_while_moving(
        self, pos: np.ndarray, radius: np.ndarray, stray_m: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """pairs(pos, radius), if they hold every pair that can touch while each puck stays within
        stray_m of pos (the hits of a step, events.py); None if no list can: stray_m is over half
        the skin.

        Every pair left out was reach + skin apart at the build: it can touch only once the two
        have strayed a skin from where they were then, half a skin each at the most.
        """
        if self._built_pos is not None and len(pos) == len(self._built_pos) and len(pos):
            if not np.count_nonzero(radius != self._built_radius):  # (a radius changed by hand: rebuild)
                moved = float(vectors.squared_lengths(pos - self._built_pos).max())
                if math.sqrt(moved) + stray_m < 0.5 * self._skin:  # (False for NaN: rebuild)
                    return self._i, self._j, self._reach
        if stray_m >= 0.5 * SKIN_RADII * float(radius.mean()):  # the skin a build would have
            return None
        self._build(pos, radius)  # now no puck has moved
        return self._i, self._j, self._reach

    def partners(self):
        """Each puck's partners in the list (Partners), made once per build."""
        if self._partners is None:
            self._partners = Partners(self._i, self._j, len(self._built_pos))
        return self._partners

    def sorted_order(self) -> np.ndarray:
        """The permutation that sorts the pairs by (i, j), worked out the first time it is asked for."""
        if self._order is None:
            self._order = np.lexsort((self._j, self._i))
        return self._order

    def reach_squared(self, less_m: float = 0.0) -> np.ndarray | float:
        """(reach - less_m)^2 for every pair, worked out once per build for each less_m.

        One number when every pair has the same reach (all radii equal): compared with every
        pair, it spares reading a second array as long as the list (1.5 % of a 10000-puck gas step).
        """
        sq = self._squared.get(less_m)
        if sq is None:
            r = (self._reach if self._one_reach is None else self._one_reach) - less_m
            sq = self._squared[less_m] = r * r
        return sq

    def _still_valid(self, pos: np.ndarray, radius: np.ndarray, rows: np.ndarray | None = None) -> bool:
        """Whether no puck moved half a skin since the build (`rows`: pos and radius are just those rows)."""
        if self._built_pos is None or len(pos) == 0:
            return False
        built_pos, built_radius = self._built_pos, self._built_radius
        if rows is not None:
            built_pos, built_radius = vectors.take(built_pos, rows), built_radius.take(rows)
        elif len(pos) != len(built_pos):
            return False
        if np.count_nonzero(radius != built_radius):
            return False  # a radius was changed by hand
        moved = pos - built_pos
        moved *= moved  # vectors.squared_lengths, without a second array
        moved_sq = moved[:, 0] + moved[:, 1]
        return bool(moved_sq.max() < self._half_skin_sq)  # NaN: not valid

    def save(self, like: tuple | None = None, radius: np.ndarray | None = None) -> tuple | None:
        """Where the pucks were at the last build (positions, radii; None: never built), read-only.

        Which pairs a step looks at depends on that: a stale list can miss a pair a correction pushed
        into overlap where a fresh one sees it, and a build from the same positions gives the same
        list again (restore). `radius`: the saved radius column, shared if the same.
        """
        if self._built_pos is None:
            return None
        radius = radius if radius is not None and same_bits(self._built_radius, radius) else frozen(self._built_radius)
        if like is not None and like[1] is radius and same_bits(self._built_pos, like[0]):
            return like
        return frozen(self._built_pos, None if like is None else like[0]), radius

    def restore(self, saved: tuple | None) -> None:
        builds = self.builds
        if saved is None:
            self._built_pos = None
        else:
            self._build(*saved)
        self.builds = builds

    def _build(self, pos: np.ndarray, radius: np.ndarray) -> None:
        skin = SKIN_RADII * float(radius.mean()) if len(radius) else 0.0
        # The pairs closer than the largest reach plus the skin, then (unless
        # all radii are equal) those closer than their own: the grid finds
        # about 2.4 candidates for each one kept.
        i, j = find_candidate_pairs(pos, radius, margin_m=skin, closer=True)
        r_min, r_max = (float(radius.min()), float(radius.max())) if len(radius) else (0.0, 0.0)
        self._one_reach = None  # see reach_squared
        if r_min == r_max:  # pair_reach's sums, without looking them up
            self._one_reach = r_min + r_max
            reach = np.full(len(i), self._one_reach)
        else:
            reach = pair_reach(radius, i, j)
            if r_min < r_max:  # (False for a NaN radius)
                near = _closer_than(pos, i, j, reach + skin)
                i, j, reach = i.take(near), j.take(near), reach.take(near)
        self._i, self._j, self._reach = i, j, reach
        self._order: np.ndarray | None = None  # see sorted_order
        self._partners = None  # see partners
        self._squared: dict[float, np.ndarray] = {}  # see reach_squared
        self._built_pos, self._built_radius = pos.copy(), radius.copy()
        self._skin, self._half_skin_sq = skin, (0.5 * skin) ** 2
        self.builds += 1


def _grid_candidates(pos: np.ndarray, cell: float, closer: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Candidate pairs of pucks whose cells are near (indices into `pos`); with `closer`, only
    those whose centres are closer than `cell`."""
    n = len(pos)
    if n < 2:
        empty = np.empty(0, dtype=np.intp)
        return empty, empty
    order, skey, ends, ny = _sort_into_cells(pos, cell)
    # Each puck (at sorted position p, in cell c) looks at two runs of the
    # sorted order: the pucks after it in its own cell and in the ROWS_PER_CELL
    # cells above it (up to c + rows), and the cells of the next column from
    # `rows` below it to `rows` above (c + ny - rows .. c + ny + rows). The
    # pucks below it and in the column before see it from their side.
    rows = ROWS_PER_CELL
    first, stop = np.empty((2, n), dtype=np.intp), np.empty((2, n), dtype=np.intp)
    first[0] = np.arange(1, n + 1)
    ends[rows:].take(skey, out=stop[0])  # ends[c + rows], without adding rows to every c
    ends[ny - rows - 1 :].take(skey, out=first[1])  # where cell c + ny - rows begins
    ends[ny + rows :].take(skey, out=stop[1])
    a, b = _expand_ranges(first, stop)
    if closer:  # checked in sorted order, where neighbours sit close together in memory
        near = _closer_than(vectors.take(pos, order), a, b, cell)
        a, b = a.take(near), b.take(near)
    return order.take(a), order.take(b)


def _sort_into_cells(pos: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Bin the pucks into columns `cell` wide and cells 1 / ROWS_PER_CELL of that tall.

    Returns (order, skey, ends, ny): the pucks sorted by cell number (column by
    column), their cell numbers in that order, ends[c] = where cell c ends in
    the sorted order (and cell c + 1 begins), and the cells per column.
    """
    # Each coordinate as one contiguous array: numpy reduces and converts those
    # fastest (axis=0 of an (N, 2) array is slower still).
    x, y = pos.T.copy()
    x0, y0 = float(x.min()), float(y.min())
    span_x, span_y = float(x.max()) - x0, float(y.max()) - y0
    rows = ROWS_PER_CELL
    # Far more cells than pucks only costs memory: widen the cells instead, to
    # at most 4 squares of a column's width per puck (so 4 * rows cells), and
    # at most 4 columns (or squares up a column) per puck where the pucks lie
    # along a line and cover no area.
    n4 = 4.0 * len(pos)
    cell = max(cell, (span_x * span_y / n4) ** 0.5, max(span_x, span_y) / n4)
    # A hair wider than the largest reach: two pucks exactly one reach apart
    # can count as overlapping after rounding, and their column numbers must
    # then still differ by at most one, their row numbers by at most `rows`.
    inv = 1.0 / (cell * (1.0 + 1e-9))
    cx = ((x - x0) * inv).astype(np.intp)
    cy = ((y - y0) * (inv * rows)).astype(np.intp)
    # Size the grid from the cells actually used, not span / cell: the two can
    # round differently (0.6 * (1 / 0.2) is 3.0 but 0.6 / 0.2 is 2.999...), and
    # a grid one cell short sends the neighbour look-ups out of bounds. Spare
    # rows below and above and a spare column on the right keep every look-up
    # of _grid_candidates inside its column and inside the grid.
    nx, ny = int(cx.max()) + 2, int(cy.max()) + 1 + 2 * rows
    key = cx * ny + cy + rows  # column-major cell number
    order = _argsort_cells(key, nx * ny)
    skey = key.take(order)
    return order, skey, np.cumsum(np.bincount(skey, minlength=nx * ny)), ny


def _expand_ranges(first: np.ndarray, stop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(a, b): each p paired with every q in [first[k, p], stop[k, p]), for each k, in that order.

    np.repeat could do it, but it takes a branch per range that the CPU cannot
    predict: with new positions at every build that cost twice as much as
    this running sum (cumsum), which has none.
    """
    n = first.shape[1]
    count = (stop - first).reshape(-1)  # the ranges in order: those of row k = 0 for every p, then k = 1...
    ends = np.cumsum(count)
    total = int(ends[-1])
    if total == 0:
        empty = np.empty(0, dtype=np.intp)
        return empty, empty
    # b goes up by one inside a range and jumps from the last range's stop - 1
    # to this range's first (an empty range adds first - stop = 0 of its own).
    # a goes up by one where each range begins (from p to p + 1), and from
    # n - 1 back to 0 where the ranges of the next k begin. Both running sums
    # are taken at once: a in the high 32 bits, b (a row, far below 2^32) in the low ones.
    jump = np.subtract(first.reshape(-1)[1:], stop.reshape(-1)[:-1], dtype=np.int64)
    jump += 1 << 32
    jump[n - 1 :: n] -= n << 32
    step = np.ones(total + 1, dtype=np.int64)  # the spare entry: ranges that begin at the very end
    step[0] = first[0, 0]  # a = 0, b = the first range's first
    np.add.at(step, ends[:-1], jump)
    both = np.cumsum(step[:total])
    return (both >> 32).astype(np.intp, copy=False), (both & 0xFFFFFFFF).astype(np.intp, copy=False)


def _argsort_cells(key: np.ndarray, n_cells: int) -> np.ndarray:
    """argsort of cell numbers, as a radix sort: numpy's stable sort of 16-bit
    integers is a radix sort, ten times faster than a comparison sort here."""
    if n_cells <= 1 << 16:
        return np.argsort(key.astype(np.uint16), kind="stable")
    if n_cells <= 1 << 32:  # two 16-bit passes, low half first
        low = np.argsort((key & 0xFFFF).astype(np.uint16), kind="stable")
        return low[np.argsort((key[low] >> 16).astype(np.uint16), kind="stable")]
    return np.argsort(key, kind="stable")
