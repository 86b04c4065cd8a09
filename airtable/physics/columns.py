"""Columns: the table's storage, growable numpy arrays sharing one row count, saved and restored.

A puck is one row of every puck column (positions, velocities, radii, ...), a
spring one row of every spring column: one step is then a handful of numpy
operations whatever the number of pucks. `save` copies the live rows out as
read-only arrays, sharing those whose bits did not change with an older save,
so a history of saves costs little more than what moved (state.py).
"""

from __future__ import annotations

import numpy as np


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    """True if a and b hold the very same bits (so -0.0 differs from 0.0, and a NaN equals itself)."""
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    if a.dtype.kind in "fc":
        return bool(np.array_equal(a.view(f"u{a.dtype.itemsize}"), b.view(f"u{b.dtype.itemsize}")))
    return bool(np.array_equal(a, b))


def frozen(a: np.ndarray, like: np.ndarray | None = None) -> np.ndarray:
    """A read-only copy of `a`, or `like` itself if it holds the same bits."""
    if like is not None and same_bits(a, like):
        return like
    out = np.array(a, copy=True)
    out.flags.writeable = False
    return out


class Columns:
    """Growable numpy arrays sharing one row count (amortised O(1) append)."""

    def __init__(self, **specs: tuple[tuple[int, ...], type]) -> None:
        self._specs = specs
        self.n = 0
        self._cap = 0
        self._data = {name: np.zeros((0, *shape), dtype) for name, (shape, dtype) in specs.items()}
        self._views: dict[str, np.ndarray] = {}  # the live rows of each column, until the row count changes

    def view(self, name: str) -> np.ndarray:
        v = self._views.get(name)
        if v is None:
            v = self._views[name] = self._data[name][: self.n]
        return v

    def append(self, **values) -> int:
        if self.n == self._cap:
            self._grow(max(16, 2 * self._cap))
        row = self.n
        for name, value in values.items():
            self._data[name][row] = value
        self.n += 1
        self._views = {}
        return row

    def _grow(self, cap: int) -> None:
        for name, (shape, dtype) in self._specs.items():
            grown = np.zeros((cap, *shape), dtype)
            grown[: self.n] = self._data[name][: self.n]
            self._data[name] = grown
        self._cap = cap

    def delete(self, rows: np.ndarray) -> np.ndarray:
        """Remove `rows`; return the old-row -> new-row map (-1 for removed)."""
        keep = np.ones(self.n, dtype=bool)
        keep[rows] = False
        remap = np.full(self.n, -1, dtype=np.intp)
        remap[keep] = np.arange(int(keep.sum()))
        for name in self._data:
            kept = self._data[name][: self.n][keep]
            self._data[name][: len(kept)] = kept
        self.n = int(keep.sum())
        self._views = {}
        return remap

    def clear(self) -> None:
        self.n = 0
        self._views = {}

    def save(self, like: dict[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
        """Every column's live rows, read-only; `like` itself if every one of them has its bits."""
        out = {name: frozen(self.view(name), (like or {}).get(name)) for name in self._data}
        if like is not None and out.keys() == like.keys() and all(out[k] is like[k] for k in out):
            return like
        return out

    def restore(self, saved: dict[str, np.ndarray]) -> None:
        """Set the columns to `saved` (from save: one row per entry in every column)."""
        n = len(next(iter(saved.values())))
        if n > self._cap:
            self.n = 0  # nothing to keep: every column is written below
            self._grow(max(16, n))
        for name, a in saved.items():
            self._data[name][:n] = a
        if n != self.n:
            self.n = n
            self._views = {}
