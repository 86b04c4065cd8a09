"""Fast gather and scatter of rows of (N, 2) arrays of vectors.

`pos[idx]`, `pos[idx] = v` and `np.add.at(pos, idx, v)` on a 2-D array go
through numpy's general N-dimensional indexing, which costs about ten times
more per row than the same operation on a 1-D array. The physics step does
little else with its index arrays, so it uses these helpers instead: `take`
gathers with `ndarray.take`, and `put` and `add_at` see each row of two float64
numbers as one complex number, which turns the array into a 1-D one without
copying (so the target must be C-contiguous float64, as the table's columns
are). The results are exactly those of plain indexing.
"""

from __future__ import annotations

import numpy as np


def take(a: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """a[idx] (a new array of the rows idx)."""
    return a.take(idx, axis=0)


def _as_complex(a: np.ndarray) -> np.ndarray:
    """The (N,) complex128 view of a C-contiguous (N, 2) float64 array."""
    return a.view(np.complex128).reshape(-1)


def put(a: np.ndarray, idx: np.ndarray, values: np.ndarray) -> None:
    """a[idx] = values for an (N, 2) float64 array, in place (the last write wins where idx repeats)."""
    _as_complex(a)[idx] = _as_complex(np.ascontiguousarray(values, dtype=np.float64))


def add_at(a: np.ndarray, idx: np.ndarray, values: np.ndarray) -> None:
    """np.add.at(a, idx, values) for an (N, 2) float64 array, in place: repeated rows add up."""
    np.add.at(_as_complex(a), idx, _as_complex(np.ascontiguousarray(values, dtype=np.float64)))
