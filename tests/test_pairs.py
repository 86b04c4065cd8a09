"""The pair stage (pairs.py) and what the step does around it: rounds give what one pair at a time
gives; the wall pass after it and the neighbour list it reads."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable.physics import broadphase, pairs, walls
from airtable.physics.collision import Collisions
from airtable.physics.columns import same_bits
from airtable.physics.table import AirTable


def _scene(seed: int, n: int):
    """A handful of pucks heaped in a small square, some exactly on top of each other."""
    rng = np.random.default_rng(seed)
    radius = rng.uniform(0.1, 0.3, n)
    mass = rng.uniform(0.1, 3.0, n) * math.pi * radius**2
    pos = rng.uniform(0.0, 0.8, (n, 2))
    pos[n - 1] = pos[0]
    vel = rng.uniform(-3.0, 3.0, (n, 2))
    return pos, vel, radius, mass


@settings(max_examples=200, deadline=None, derandomize=True)
@given(
    st.integers(0, 2**32 - 1),
    st.integers(2, 12),
    st.sampled_from(pairs.CORRECTION_MODES),
    st.sampled_from([0.0, 0.5, 1.0]) | st.floats(0.0, 1.0),
    st.sampled_from([1 / 240, 1 / 60, 1 / 20]),
    st.sampled_from([0, pairs.FEW_PAIRS, 100]),
)
def test_rounds_give_what_one_pair_at_a_time_gives(seed: int, n: int, mode: str, cr: float, dt_s: float, few: int):
    # A heap: pairs share pucks, so each pair must see the velocities the pairs before it left.
    # Rounds of up to `few` pairs go pair by pair in Python numbers (0: every round in numpy, 100:
    # none); the singles go in numpy: the two must give the same bits.
    pos, vel, radius, mass = _scene(seed, n)
    i, j = broadphase.brute_force_pairs(pos, radius)
    one_pos, one_vel = pos.copy(), vel.copy()
    rounds = pairs.resolve_pairs(pos, vel, radius, mass, i, j, cr, mode, dt_s, few_pairs=few)
    singles = [
        pairs.resolve_pairs(one_pos, one_vel, radius, mass, i[k : k + 1], j[k : k + 1], cr, mode, dt_s, few_pairs=0)
        for k in range(len(i))
    ]
    np.testing.assert_array_equal(pos, one_pos)
    np.testing.assert_array_equal(vel, one_vel)
    assert same_bits(pos, one_pos) and same_bits(vel, one_vel)  # (-0.0 too)
    # The same collisions, recorded alike (the rounds group them by round, not in the pairs' order).
    got, want = (Collisions.of_records(r) for r in (rounds, [c for s in singles for c in s]))
    got, want = (c.take(np.lexsort((c.j, c.i))) for c in (got, want))
    for field in Collisions.__dataclass_fields__:
        np.testing.assert_array_equal(getattr(got, field), getattr(want, field))
        assert same_bits(getattr(got, field), getattr(want, field)), field


def _crowd_changed_by_hand() -> tuple[np.ndarray, np.ndarray, int]:
    """_crowd, then the table shrunk under the pucks, a puck grown and one moved by hand."""
    rng = np.random.default_rng(5)
    table = AirTable(width_m=2.0, height_m=2.0)
    table.gravity_on = False
    for _ in range(70):
        table.add_puck(rng.uniform(0.1, 1.9, 2), radius_m=rng.uniform(0.05, 0.12), vel_mps=rng.uniform(-4, 4, 2))
    for k in range(240):
        if k == 60:
            table.width_m = 1.7  # the right-hand pucks are now past the wall
        if k == 120:
            table.radius_m[3] = 0.3
        if k == 180:
            table.pos_m[7] = (0.01, 0.01)  # into the corner, past both walls
        table.step(1 / 120)
    return table.pos_m.copy(), table.vel_mps.copy(), table.wall_collision_count


def test_a_table_shrunk_under_a_crowd_puts_everyone_back_inside() -> None:
    pos, _, bounces = _crowd_changed_by_hand()
    assert bounces > 100
    x, y = pos[:, 0], pos[:, 1]
    assert x.max() < 1.7 and y.min() > 0.0  # everyone back inside the shrunk table


def test_a_row_said_to_have_moved_past_half_the_skin_rebuilds_the_list() -> None:
    r = 0.1
    pos = np.array([[0.5, 0.5], [1.0, 0.5], [1.4, 0.5]])  # 0.4 m apart: more than reach + skin (0.35 m)
    radius = np.full(3, r)
    nl = broadphase.NeighbourList()
    i, _, _ = nl.pairs(pos, radius)
    assert len(i) == 0
    half_skin = 0.5 * broadphase.SKIN_RADII * r
    pos[2, 0] -= 0.9 * half_skin
    nl.pairs(pos, radius, moved=np.array([2]))
    assert nl.builds == 1  # still within half a skin: the list holds
    pos[2, 0] -= 0.2 * half_skin
    i, j, _ = nl.pairs(pos, radius, moved=np.array([2]))
    assert nl.builds == 2
    assert (1, 2) in zip(i.tolist(), j.tolist(), strict=True)  # now 0.32 m apart: within reach + skin


def test_a_row_named_twice_bounces_once() -> None:
    # The wall pass after the pairs gets the rows they moved, and a row may be in two pairs.
    pos, vel, radius = np.array([[-0.02, 1.0], [1.0, 1.0]]), np.array([[-2.0, 0.5], [0.0, 0.0]]), np.full(2, 0.1)
    count, past = walls.resolve_walls(pos, vel, radius, np.array([2.0, 2.0]), 0.5, True, only=np.array([0, 1, 0]))
    assert count == 1 and past.tolist() == [0, 0]
    # Backed up its 0.12 m penetration and on at the bounce's 0.5 of its speed: x = 0.1 + 0.5 * 0.12 = 0.16 m
    # (mirrored by the whole penetration, 0.22 m, before restitution below 1 counted), moving out at 0.5 * 2 m/s.
    np.testing.assert_allclose(pos[0], [0.16, 1.0])
    np.testing.assert_allclose(vel[0], [1.0, 0.5])


def test_the_squared_reach_is_one_number_when_every_radius_is_equal() -> None:
    pos = np.array([[0.5, 0.5], [0.8, 0.5], [2.0, 2.0]])
    nl = broadphase.NeighbourList()
    nl.pairs(pos, np.full(3, 0.1))
    assert nl.reach_squared(0.05) == pytest.approx(0.15**2)  # (0.1 + 0.1 - 0.05)^2, one number
    assert isinstance(nl.reach_squared(), float)
    i, j, _ = nl.pairs(pos, np.array([0.1, 0.2, 0.1]))  # a radius changed: the list is built again
    assert (i.tolist(), j.tolist()) == ([0], [1])
    np.testing.assert_allclose(nl.reach_squared(0.05), [0.25**2])  # (0.1 + 0.2 - 0.05)^2, per pair


@pytest.mark.parametrize("mode", ["two-step", "perfect-kiss"])
def test_the_collisions_a_step_keeps_raw_are_those_it_counted(mode: str) -> None:
    # The records stay raw (PairRecords) until last_collisions is read: reading them or not
    # changes nothing, and they hold exactly the collisions collision_count counted.
    from airtable.demos.demo_0p_gas import gas_scene

    read, unread = gas_scene(300, seed=2), gas_scene(300, seed=2)
    for table in (read, unread):
        table.puck_correction = mode
    seen = 0
    for _ in range(60):
        read.step(1 / 60)
        unread.step(1 / 60)
        c = read.last_collisions
        seen += len(c)
        assert len(c.i) == len(c.normal) == len(c.vel_j_after) and c.normal.shape == (len(c), 2)
        if len(c):
            np.testing.assert_allclose(np.hypot(*c.normal.T), 1.0, rtol=1e-12)  # unit normals, as rows
    assert type(read.collision_count) is int and read.collision_count == seen > 100
    assert same_bits(read.pos_m, unread.pos_m) and same_bits(read.vel_mps, unread.vel_mps)
