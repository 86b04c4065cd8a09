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


def test_complex_vectors_by_hand() -> None:
    rows = np.array([[3.0, 4.0], [0.0, -2.0], [0.0, 0.0]])
    z = vectors.as_complex(rows)
    assert z.tolist() == [3 + 4j, -2j, 0j] and np.shares_memory(z, rows)  # a view: writing z writes the rows
    np.testing.assert_array_equal(vectors.squared_abs(z), [25.0, 4.0, 0.0])
    np.testing.assert_array_equal(vectors.dot(z, np.array([1 + 2j, 5 + 6j, 7 + 8j])), [11.0, -12.0, 0.0])
    n, dist = vectors.units(z, lambda: np.array([0, 0, 1]))  # the zero vector gets key 1's direction
    np.testing.assert_array_equal(dist, [5.0, 2.0, 0.0])
    assert n[:2].tolist() == [0.6 + 0.8j, -1j]
    assert n[2] == complex(*vectors.fallback_directions(np.array([1]))[0])


def test_complex_vectors_give_the_bits_of_the_rows_and_of_plain_floats() -> None:
    rng = np.random.default_rng(1)
    a, b = rng.normal(size=(1000, 2)) * 10.0 ** rng.integers(-6, 6, (1000, 1)), rng.normal(size=(1000, 2))
    s = rng.normal(size=1000) * 10.0 ** rng.integers(-6, 6, 1000)
    za, zb = vectors.as_complex(a), vectors.as_complex(b)
    assert vectors.squared_abs(za).tobytes() == vectors.squared_lengths(a).tobytes()
    assert vectors.dot(za, zb).tobytes() == vectors.dot_rows(a, b).tobytes()
    n, dist = vectors.units(za, None)
    rows_n, rows_dist = vectors.unit_vectors(a)
    assert n.view(np.float64).tobytes() == rows_n.tobytes() and dist.tobytes() == rows_dist.tobytes()
    # A real array times a complex one scales both parts, exactly as two float products would:
    # the pair rounds rely on it, and so does their twin in plain Python numbers.
    scaled = s * za
    assert scaled.view(np.float64).tobytes() == (vectors.per_row(s) * a).tobytes()
    assert [complex(v) for v in scaled[:50]] == [float(f) * complex(w) for f, w in zip(s[:50], za[:50], strict=True)]
