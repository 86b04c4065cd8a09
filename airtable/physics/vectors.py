"""Rows of 2D vectors: (N, 2) float arrays, one vector per puck, pair or spring.

Lengths, unit vectors and dot products multiply whole rows, then add the
two columns (`dd = d * d; dd[:, 0] + dd[:, 1]`): numpy's axis reductions and
`einsum` cost several times more on arrays this narrow.

Gather and scatter: `pos[idx]`, `pos[idx] = v` and `np.add.at(pos, idx, v)`
on a 2-D array go through numpy's general N-dimensional indexing, which costs
about ten times more per row than the same operation on a 1-D array. The step
does little else with its index arrays, so it uses `take`, `put` and `add_at`
instead: `take` gathers with `ndarray.take`, and `put` and `add_at` see each
row of two float64 numbers as one complex number, which turns the array into a
1-D one without copying (so the target must be C-contiguous float64, as the
table's columns are). The results are exactly those of plain indexing.

Likewise the step finds the true entries of a 1-D mask with
`mask.nonzero()[0]`, not `np.flatnonzero(mask)`: the same indices, without
the wrapper that costs twice the work on a few thousand pairs.
"""

from __future__ import annotations

import math

import numpy as np

# Two pucks exactly on top of each other have no line of centres. Each such
# pair gets a direction of its own, turned by the golden angle per key, so
# that a heap of pucks created at one point spreads in 2D, not along a line.
GOLDEN_ANGLE_RAD = np.pi * (3.0 - np.sqrt(5.0))


def fallback_directions(keys: np.ndarray) -> np.ndarray:
    """(len(keys), 2) unit vectors at keys * the golden angle: deterministic, evenly spread."""
    angle = GOLDEN_ANGLE_RAD * np.asarray(keys, dtype=float)
    return np.column_stack([np.cos(angle), np.sin(angle)])


def per_row(s: np.ndarray) -> np.ndarray:
    """s, one number per row, repeated along each row: (N, 2), to scale rows by.

    `d / per_row(s)` gives exactly `d / s[:, None]`, for less: numpy
    broadcasts along a length-2 axis a row at a time, while repeating s
    first makes it a same-shape operation (a fifth to two fifths faster from
    a few dozen rows to a hundred thousand).
    """
    return s.repeat(2).reshape(-1, 2)


def squared_lengths(d: np.ndarray) -> np.ndarray:
    """Squared length of each row of d."""
    dd = d * d
    return dd[:, 0] + dd[:, 1]


def lengths(d: np.ndarray) -> np.ndarray:
    """Length of each row of d."""
    return np.sqrt(squared_lengths(d))


def unit_vectors(d: np.ndarray, keys: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors along the rows of d and their lengths.

    A zero row gets `fallback_directions` of its key (keys: one integer per
    row, e.g. a pair's i + j; the row number if not given). keys may also be
    a function that makes them, called only if a row is zero (rarely: making
    them costs a numpy call that most calls do not need).
    """
    dist = lengths(d)
    # np.count_nonzero, here and in the step, costs a quarter of .all() or
    # .any(), whose Python-level wrappers dominate on a few dozen pairs.
    if np.count_nonzero(dist) == len(dist):
        return d / per_row(dist), dist
    safe = dist > 0.0
    zero = np.flatnonzero(~safe)
    n = d / per_row(np.where(safe, dist, 1.0))
    if callable(keys):
        keys = keys()
    n[zero] = fallback_directions(zero if keys is None else np.asarray(keys).take(zero))
    return n, dist


def dot_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The dot product of each row of a with the same row of b."""
    ab = a * b  # one multiplication for both columns: the same products as a[:, 0] * b[:, 0] ..., in one call
    return ab[:, 0] + ab[:, 1]


def take(a: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """a[idx] (a new array of the rows idx)."""
    return a.take(idx, axis=0)


def as_complex(a: np.ndarray) -> np.ndarray:
    """The (N,) complex128 view of a C-contiguous (N, 2) float64 array: row (x, y) is x + iy."""
    return a.view(np.complex128).ravel()  # a view, as reshape(-1) gives, for half the cost


def as_rows(z: np.ndarray) -> np.ndarray:
    """The (N, 2) float64 view of a contiguous (N,) complex128 array: as_complex undone."""
    return z.view(np.float64).reshape(-1, 2)


def put(a: np.ndarray, idx: np.ndarray, values: np.ndarray) -> None:
    """a[idx] = values for an (N, 2) float64 array, in place (the last write wins where idx repeats)."""
    as_complex(a)[idx] = as_complex(np.ascontiguousarray(values, dtype=np.float64))


def add_at(a: np.ndarray, idx: np.ndarray, values: np.ndarray) -> None:
    """np.add.at(a, idx, values) for an (N, 2) float64 array, in place: repeated rows add up."""
    np.add.at(as_complex(a), idx, as_complex(np.ascontiguousarray(values, dtype=np.float64)))


# ---------------------------------------------------------------- vectors as complex numbers
#
# The pair rounds (pairs.py) hold each vector as one complex number x + iy, gathered from the
# table with as_complex: a pair's two pucks are then two 1-D arrays, and adding, subtracting,
# gathering and scattering vectors is one numpy operation each, with no (N, 2) shapes to
# broadcast. Only operations that are exact per part are used on them: adding, subtracting,
# and scaling by a real array (s * z is (s x) + i (s y), bit for bit); dot products and
# lengths below work on the x, y, x, y... floats behind them. So every result is bit for bit
# what the same formula gives in plain Python floats, part by part.


def squared_abs(z: np.ndarray) -> np.ndarray:
    """x^2 + y^2 of each complex z = x + iy: the squared length of the vector (x, y); z may be one
    Python complex number (then a float, by the same arithmetic)."""
    if isinstance(z, complex):
        return z.real * z.real + z.imag * z.imag
    xy = z.view(np.float64)
    xy = xy * xy
    return xy[0::2] + xy[1::2]


def dot(z, w):
    """The dot product of the vectors z and w, zx wx + zy wy: complex arrays (one vector per row),
    or two Python complex numbers (then a float, by the same arithmetic)."""
    if isinstance(z, complex):
        return z.real * w.real + z.imag * w.imag
    xy = z.view(np.float64) * w.view(np.float64)
    return xy[0::2] + xy[1::2]


def length(z):
    """|z| = sqrt(x^2 + y^2) of each complex z = x + iy, or of one Python complex number (then a
    float, the same bits: abs() of a complex takes hypot, which Python and numpy round differently)."""
    if isinstance(z, complex):
        return math.sqrt(squared_abs(z))
    return np.sqrt(squared_abs(z))


def units(z: np.ndarray, keys) -> tuple[np.ndarray, np.ndarray]:
    """unit_vectors for complex z: (z / |z|, |z|), each part divided by the length.

    A zero z gets `fallback_directions` of its key; keys may be a function
    that makes them, called only if some z is zero. z may be one Python
    complex number, and its key one int (then the same arithmetic in Python numbers).
    """
    dist = length(z)
    if isinstance(z, complex):
        if dist:  # (a NaN is true: it divides, as below)
            return complex(z.real / dist, z.imag / dist), dist
        x, y = fallback_directions(np.array([keys() if callable(keys) else keys]))[0].tolist()
        return complex(x, y), dist
    if np.count_nonzero(dist) == len(dist):
        return (z.view(np.float64) / dist.repeat(2)).view(np.complex128), dist
    n, _ = unit_vectors(as_rows(z), keys)
    return as_complex(n), dist
