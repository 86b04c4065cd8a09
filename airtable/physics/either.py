"""Either many pairs in numpy arrays or one pair in Python numbers, by the same lines.

The pair rounds (pairs.py) and the hit predictions (events.py) run the same
lines on a numpy array of pairs at once, or on one pair in Python numbers,
where a numpy call would cost a microsecond for a single number and the
arithmetic of a whole pair costs a few. Arithmetic works on both as it is;
the few operations that differ are these, and they give the same bits
either way (numpy's rules, -0.0 and NaN included).
"""

from __future__ import annotations

import numpy as np


def take(a: np.ndarray, rows):
    """a[rows]: an array for an array of rows, a Python number for one row (an int)."""
    return a.take(rows) if isinstance(rows, np.ndarray) else a.item(rows)


def count(mask) -> int:
    """How many are true: of a mask, or of one bool."""
    return np.count_nonzero(mask) if isinstance(mask, np.ndarray) else int(mask)


def size(rows) -> int:
    """How many pairs: of an array of rows, or 1 for one row."""
    return len(rows) if isinstance(rows, np.ndarray) else 1


def where(c, x, y):
    """np.where(c, x, y), or for one pair: x if c, else y."""
    return np.where(c, x, y) if isinstance(c, np.ndarray) else (x if c else y)


def minimum(x, y):
    """np.minimum(x, y); for one pair as numpy does it (NaN wins; of two equal ones, y: -0.0 or 0.0)."""
    if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
        return np.minimum(x, y)
    return x if x < y or x != x else y


def maximum(x, y):
    """np.maximum(x, y); for one pair as numpy does it (see minimum)."""
    if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
        return np.maximum(x, y)
    return x if x > y or x != x else y
