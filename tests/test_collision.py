"""The collision formulas (collision.py): each is right by hand, and gives the same bits for one
pair in Python numbers (the hits in time order) as for many in numpy arrays (the pair stage)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from airtable import AirTable
from airtable.physics.collision import bounce, collide_1d, collide_along, contact_time

settings_ = settings(max_examples=300, deadline=None, derandomize=True)
speeds = st.floats(-10.0, 10.0)
masses = st.floats(1e-3, 1e3)
restitutions = st.sampled_from([0.0, 0.5, 1.0]) | st.floats(0.0, 1.0)
coords = st.floats(-2.0, 2.0)


@pytest.mark.parametrize("cr", [1.0, 0.5, 0.0])
def test_collide_1d_keeps_momentum_and_reverses_the_relative_speed_times_cr(cr: float) -> None:
    m1, m2, u1, u2 = 2.0, 0.5, 3.0, -1.0
    v1, v2 = collide_1d(u1, u2, m1, m2, cr)
    assert m1 * v1 + m2 * v2 == pytest.approx(m1 * u1 + m2 * u2, rel=1e-15)
    assert v1 - v2 == pytest.approx(-cr * (u1 - u2), abs=1e-15)


@settings_
@given(speeds, masses, restitutions)
def test_a_wall_bounce_is_the_1d_collision_with_an_infinitely_heavy_body_at_rest(u: float, m: float, cr: float):
    v1, v2 = collide_1d(u, 0.0, m, m * 1e15, cr)
    assert bounce(u, cr) == pytest.approx(v1, rel=1e-12, abs=1e-12)
    assert abs(v2) < 1e-12


def _pairs(draw_coords: list[float]) -> tuple[np.ndarray, np.ndarray]:
    z = np.array(draw_coords, dtype=float).view(np.complex128)
    return np.ascontiguousarray(z[0::2]), np.ascontiguousarray(z[1::2])


@settings_
@given(st.lists(coords, min_size=8, max_size=40).filter(lambda v: len(v) % 4 == 0), st.floats(0.05, 1.0))
def test_contact_time_gives_one_pair_the_bits_it_gives_many(values: list[float], reach: float) -> None:
    d, w = _pairs(values)
    t_many, u_many = contact_time(d, w, reach)
    for k in range(len(d)):
        t_one, u_one = contact_time(complex(d[k]), complex(w[k]), reach)
        assert (t_one, u_one) == (t_many[k], u_many[k])


@settings_
@given(st.lists(coords, min_size=8, max_size=40).filter(lambda v: len(v) % 4 == 0), masses, masses, restitutions)
@example(values=[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 5e-324], m1=1.0, m2=1.0, cr=0.0)
def test_collide_along_gives_one_pair_the_bits_it_gives_many(values: list[float], m1: float, m2: float, cr: float):
    v1, v2 = _pairs(values)
    # some unit normal per pair, by its angle: d / |d| of a d of 5e-324 is not one (a wide run's: NaN both ways)
    n = np.where(v1 != v2, np.exp(1j * np.angle(v1 - v2)), 1.0)
    many = collide_along(n, v1, v2, np.full(len(n), m1), np.full(len(n), m2), cr)
    for k in range(len(n)):
        one = collide_along(complex(n[k]), complex(v1[k]), complex(v2[k]), m1, m2, cr)
        assert one == (many[0][k], many[1][k])


def test_contact_time_by_hand() -> None:
    # 3 m apart centre to centre, reach 1, closing at 2 m/s head on: they touch in 1 s, at 2 m/s.
    assert contact_time(3 + 0j, -2 + 0j, 1.0) == (1.0, 2.0)
    # 0.9 apart (0.1 of overlap), closing at 2 m/s: they touched 0.05 s ago.
    t, u = contact_time(0.9 + 0j, -2 + 0j, 1.0)
    assert t == pytest.approx(-0.05, rel=1e-12) and u == pytest.approx(2.0, rel=1e-12)
    # Parting, or passing by more than the reach apart, or still: they never meet.
    for d, w in ((3 + 0j, 2 + 0j), (3 + 1.5j, -2 + 0j), (0.9 + 0j, 0j)):
        assert contact_time(d, w, 1.0) == (math.inf, 0.0)
    # 0.5 off the line of centres: they touch when |(3 - 2t, 0.5)| = 1, t = (3 - sqrt(0.75)) / 2.
    t, u = contact_time(3 + 0.5j, -2 + 0j, 1.0)
    assert t == pytest.approx((3 - math.sqrt(0.75)) / 2, rel=1e-14)
    assert u == pytest.approx(2 * math.sqrt(0.75), rel=1e-14)  # the approach along the line of centres


def _head_on(cr: float, mode: str, gap_m: float) -> tuple:
    """Two 1 kg pucks of r = 0.5 m closing head on at 2 m/s, overlapping by 0.05 m - gap_m after one 1/20 s step."""
    table = AirTable()
    table.cr_puck = cr
    table.puck_correction = mode
    density = 1.0 / (math.pi * 0.25)
    p1 = table.add_puck(pos_m=(0.95, 4.0), radius_m=0.5, density_kgpm2=density, vel_mps=(1.0, 0.0))
    p2 = table.add_puck(pos_m=(2.0 - gap_m + 0.05, 4.0), radius_m=0.5, density_kgpm2=density, vel_mps=(-1.0, 0.0))
    table.step(1 / 20)
    assert table.collision_count == 1
    return p1, p2, table


def test_two_step_ends_as_far_apart_as_it_overlapped() -> None:
    # Caught 0.05 m overlapping, closing at 2 m/s: t_p = 0.025 s, back and forward again.
    p1, p2, _ = _head_on(1.0, "two-step", 0.05)
    np.testing.assert_allclose(p1.vel_mps, (-1.0, 0.0), rtol=1e-12)
    np.testing.assert_allclose(p2.vel_mps, (1.0, 0.0), rtol=1e-12)
    np.testing.assert_allclose(p1.pos_m[0], 0.95, rtol=1e-12)
    np.testing.assert_allclose(p2.pos_m[0], 2.0, rtol=1e-12)  # 1.05 apart: a 0.05 m gap


def test_two_step_at_restitution_0_leaves_the_pair_touching() -> None:
    # 0.04 m of overlap closing at 2 m/s, e = 0: both stop; back up t_p = 0.02 s (each
    # 0.02 m back), then forward 0.02 s at 0 m/s: centres 1.0 apart, exactly touching.
    p1, p2, _ = _head_on(0.0, "two-step", 0.04)
    np.testing.assert_allclose(p1.vel_mps, (0.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(p2.vel_mps, (0.0, 0.0), atol=1e-12)
    np.testing.assert_allclose([p1.pos_m[0], p2.pos_m[0]], [0.98, 1.98], rtol=1e-12)


@pytest.mark.parametrize("mode", ["two-step", "perfect-kiss", "off"])
def test_the_record_says_what_the_collision_did(mode: str) -> None:
    p1, p2, table = _head_on(1.0, mode, 0.05)
    c = table.last_collisions
    assert len(c) == 1 and (c.i[0], c.j[0]) == (p1.index, p2.index)
    np.testing.assert_allclose(c.normal[0], (-1.0, 0.0), atol=1e-12)  # from j to i
    np.testing.assert_allclose(c.vel_i_before[0], (1.0, 0.0))
    np.testing.assert_allclose(c.vel_i_after[0], p1.vel_mps)
    if mode == "perfect-kiss":  # a hit found at its time: where they touched, 0.025 s into the step
        assert c.overlap_m[0] == 0.0 and c.separation_m[0] == pytest.approx(0.0, abs=1e-12)
    else:  # seen overlapping at the step's end: where the correction left them
        assert c.overlap_m[0] == pytest.approx(0.05, rel=1e-12)
        np.testing.assert_allclose(c.pos_j_after[0], p2.pos_m)
    assert c.reach_m[0] == 1.0
    np.testing.assert_allclose(c.contact_m[0], c.pos_j_before[0] - (0.5, 0.0), rtol=1e-12)  # on j's edge
