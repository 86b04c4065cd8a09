"""The vectorised pair resolution (pairs.py) agrees with the one-pair reference (reference.py) to round-off."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable.physics import broadphase, pairs
from airtable.physics.reference import Disc, collide_1d, collide_pair


def _disc(pos: np.ndarray, vel: np.ndarray, radius: np.ndarray, mass: np.ndarray, k: int) -> Disc:
    return Disc((float(pos[k, 0]), float(pos[k, 1])), (float(vel[k, 0]), float(vel[k, 1])), radius[k], mass[k])


def _reference(pos, vel, radius, mass, i, j, cr: float, mode: str, dt_s: float):
    """The pairs (i, j) collided one by one, in order, by the scalar reference."""
    pos, vel = pos.copy(), vel.copy()
    for a, b in zip(i.tolist(), j.tolist(), strict=True):
        d1, d2 = collide_pair(
            _disc(pos, vel, radius, mass, a), _disc(pos, vel, radius, mass, b), cr, mode, dt_s, key=a + b
        )
        pos[a], vel[a], pos[b], vel[b] = d1.pos, d1.vel, d2.pos, d2.vel
    return pos, vel


def _check(pos, vel, radius, mass, cr: float, mode: str, dt_s: float) -> int:
    """Resolve every overlapping pair both ways and compare; return how many pairs there were."""
    i, j = broadphase.brute_force_pairs(pos, radius)
    want_pos, want_vel = _reference(pos, vel, radius, mass, i, j, cr, mode, dt_s)
    pairs.resolve_pairs(pos, vel, radius, mass, i, j, cr, mode, dt_s)
    np.testing.assert_allclose(pos, want_pos, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(vel, want_vel, rtol=1e-9, atol=1e-12)
    return len(i)


settings_ = settings(max_examples=300, deadline=None, derandomize=True)
modes = st.sampled_from(pairs.CORRECTION_MODES)
restitutions = st.sampled_from([0.0, 0.5, 0.9, 1.0]) | st.floats(0.0, 1.0)
steps = st.sampled_from([1 / 240, 1 / 120, 1 / 60, 1 / 20])


@settings_
@given(st.integers(0, 2**32 - 1), st.integers(1, 8), modes, restitutions, steps)
def test_separate_pairs_match_the_reference(seed: int, n_pairs: int, mode: str, cr: float, dt_s: float) -> None:
    # Pairs far apart from each other, each overlapping by up to its whole
    # reach, moving at up to 5 m/s in any direction (approaching or not).
    rng = np.random.default_rng(seed)
    radius = rng.uniform(0.05, 0.5, 2 * n_pairs)
    mass = rng.uniform(0.1, 3.0, 2 * n_pairs) * math.pi * radius**2
    reach = radius[0::2] + radius[1::2]
    angle = rng.uniform(0.0, 2.0 * math.pi, n_pairs)
    dist = rng.uniform(0.0, 1.0, n_pairs) * reach
    pos = np.zeros((2 * n_pairs, 2))
    pos[0::2, 0] = 3.0 * np.arange(n_pairs)
    pos[1::2] = pos[0::2] + dist[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    vel = rng.uniform(-5.0, 5.0, (2 * n_pairs, 2))
    assert _check(pos, vel, radius, mass, cr, mode, dt_s) == n_pairs


@settings_
@given(st.integers(0, 2**32 - 1), st.integers(3, 7), modes, restitutions, steps)
def test_pairs_sharing_pucks_match_the_reference_one_by_one(
    seed: int, n: int, mode: str, cr: float, dt_s: float
) -> None:
    # A handful of pucks heaped in a small square: pairs share pucks, and
    # each pair sees the velocities the pairs before it left.
    rng = np.random.default_rng(seed)
    radius = rng.uniform(0.1, 0.3, n)
    mass = rng.uniform(0.1, 3.0, n) * math.pi * radius**2
    pos = rng.uniform(0.0, 0.6, (n, 2))
    vel = rng.uniform(-3.0, 3.0, (n, 2))
    _check(pos, vel, radius, mass, cr, mode, dt_s)


@pytest.mark.parametrize("cr", [1.0, 0.5, 0.0])
def test_collide_1d_keeps_momentum_and_reverses_the_relative_speed_times_cr(cr: float) -> None:
    m1, m2, u1, u2 = 2.0, 0.5, 3.0, -1.0
    v1, v2 = collide_1d(u1, u2, m1, m2, cr)
    assert m1 * v1 + m2 * v2 == pytest.approx(m1 * u1 + m2 * u2, rel=1e-15)
    assert v1 - v2 == pytest.approx(-cr * (u1 - u2), abs=1e-15)


def test_two_step_reference_ends_as_far_apart_as_it_overlapped() -> None:
    # Head on, equal masses, 0.05 m of overlap closing at 2 m/s: t_p = 0.025 s.
    p1 = Disc((1.0, 0.0), (1.0, 0.0), 0.5, 1.0)
    p2 = Disc((1.95, 0.0), (-1.0, 0.0), 0.5, 1.0)
    q1, q2 = collide_pair(p1, p2, cr=1.0, mode="two-step", dt_s=1 / 20)
    assert q1.vel == pytest.approx((-1.0, 0.0)) and q2.vel == pytest.approx((1.0, 0.0))
    assert q1.pos == pytest.approx((0.95, 0.0)) and q2.pos == pytest.approx((2.0, 0.0))  # 1.05 apart: 0.05 gap
