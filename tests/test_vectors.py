"""vectors: the row helpers give the numbers of the plain numpy forms they replace, to the last bit."""

from __future__ import annotations

import numpy as np

from airtable.physics import vectors


def test_rows_by_hand() -> None:
    d = np.array([[3.0, 4.0], [0.0, -2.0], [0.0, 0.0]])
    np.testing.assert_array_equal(vectors.per_row(np.array([2.0, 3.0])), [[2.0, 2.0], [3.0, 3.0]])
    w = np.array([[1.0, 2.0], [5.0, 6.0], [7.0, 8.0]])
    np.testing.assert_array_equal(vectors.dot_rows(d, w), [11.0, -12.0, 0.0])
    n, dist = vectors.unit_vectors(d, lambda: np.array([0, 0, 1]))  # the zero row gets key 1's direction
    np.testing.assert_array_equal(dist, [5.0, 2.0, 0.0])
    np.testing.assert_array_equal(n[:2], [[0.6, 0.8], [0.0, -1.0]])
    np.testing.assert_allclose(n[2], [np.cos(vectors.GOLDEN_ANGLE_RAD), np.sin(vectors.GOLDEN_ANGLE_RAD)])


def test_same_bits_as_the_broadcast_and_per_column_forms() -> None:
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(1000, 2)) * 1e3, rng.normal(size=(1000, 2))
    s = rng.uniform(-2.0, 2.0, 1000)
    assert (vectors.per_row(s) * a).tobytes() == (s[:, None] * a).tobytes()
    assert (a / vectors.per_row(s)).tobytes() == (a / s[:, None]).tobytes()
    assert vectors.dot_rows(a, b).tobytes() == (a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]).tobytes()
