"""The engine under real use (issue 14): the small ones, resting contact, fast shots, pi.

Every expected number is worked out by hand here; every loop is bounded in steps.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from airtable.demos import demo_pi_collisions as pi_demo
from airtable.demos.demo_0p_gas import gas_scene

from airtable import AirTable
from airtable.physics import integrate

# ---------------------------------------------------------------- the small ones


def test_pucks_created_at_one_point_spread_in_2d() -> None:
    table = AirTable()
    for _ in range(50):
        table.add_puck(pos_m=(5.0, 4.0), radius_m=0.1)
    for _ in range(240):
        table.step(1 / 240)
    spread = table.pos_m - table.pos_m.mean(axis=0)
    # Along a line, one of the two spreads would be zero.
    assert spread[:, 0].std() > 0.2 and spread[:, 1].std() > 0.2
    d = table.pos_m[:, None, :] - table.pos_m[None, :, :]
    gap = np.hypot(d[..., 0], d[..., 1]) + 0.21 * np.eye(50)
    assert gap.min() > 0.2 - 1e-3  # nobody overlaps by more than a millimetre


@pytest.mark.parametrize(
    ("asked", "placed"),
    [((-100.0, -100.0), (0.25, 0.25)), ((3.0, 50.0), (3.0, 8.7556 - 0.25)), ((10.1, 4.0), (9.75, 4.0))],
)
def test_a_puck_created_outside_the_walls_is_placed_at_the_nearest_point_inside(asked, placed) -> None:
    table = AirTable()
    p = table.add_puck(pos_m=asked, radius_m=0.25)
    np.testing.assert_allclose(p.pos_m, placed, rtol=0, atol=1e-12)


def test_the_default_correction_is_the_accurate_one() -> None:
    assert AirTable().puck_correction == "perfect-kiss"


# ---------------------------------------------------------------- resting contact


@pytest.mark.parametrize("restitution", [0.0, 0.9])
def test_a_column_of_20_comes_to_rest_on_the_floor(restitution: float) -> None:
    # 20 pucks of r = 0.2 m stacked on the floor, each touching the next: at
    # rest the centres are at 0.2 + 0.4 k m. Under gravity each step adds
    # g dt = 4 cm/s, which the contacts must take out again without a bounce.
    table = AirTable()
    table.gravity_on = True
    table.cr_puck = table.cr_wall = restitution
    for k in range(20):
        table.add_puck(pos_m=(5.0, 0.2 + 0.4 * k), radius_m=0.2)
    for _ in range(3 * 240):  # 3 s
        table.step(1 / 240)
    assert np.abs(table.vel_mps).max() < 1e-3  # every speed under 1 mm/s
    heights = table.pos_m[:, 1]
    np.testing.assert_allclose(heights, 0.2 + 0.4 * np.arange(20), rtol=0, atol=1e-3)
    assert 7.8 - heights.max() < 0.02  # the top sunk less than 20 mm
    np.testing.assert_allclose(table.pos_m[:, 0], 5.0, rtol=0, atol=1e-12)  # not thrown sideways
    assert table.collision_count == 0  # resting contacts, never collisions


def test_fast_collisions_under_gravity_keep_the_course_model() -> None:
    # Gravity on, a 3 m/s head-on hit of equal pucks (far above the rest
    # speed 2 g dt = 8 cm/s): the velocities swap exactly, as without gravity.
    table = AirTable()
    table.gravity_on = True
    a = table.add_puck(pos_m=(3.0, 6.0), radius_m=0.25, vel_mps=(3.0, 0.0))
    b = table.add_puck(pos_m=(4.0, 6.0), radius_m=0.25)
    for _ in range(60):
        table.step(1 / 240)
        if table.collision_count:
            break
    assert table.collision_count == 1
    assert a.vel_mps[0] == pytest.approx(0.0, abs=1e-12) and b.vel_mps[0] == pytest.approx(3.0, rel=1e-12)
    assert a.vel_mps[1] == pytest.approx(b.vel_mps[1], rel=1e-12)  # both fell alike


# ---------------------------------------------------------------- fast pucks


@pytest.mark.parametrize("dt_s", [1 / 60, 1 / 240])
@pytest.mark.parametrize("mode", ["off", "two-step", "perfect-kiss"])
@pytest.mark.parametrize("speed", [10.0, 50.0, 200.0])
def test_a_fast_shot_hits_the_puck_in_its_path(speed: float, mode: str, dt_s: float) -> None:
    # A 5 cm puck aimed dead centre at an equal still one 2 m away: the hit
    # is head on, so the shooter stops and the target leaves at `speed`,
    # however far the shooter moves in one step (up to 3.3 m: 33 diameters).
    table = AirTable(width_m=60.0, height_m=10.0)
    table.puck_correction = mode
    shooter = table.add_puck(pos_m=(27.0 + 0.37 * speed * dt_s, 5.0), radius_m=0.05, vel_mps=(speed, 0.0))
    target = table.add_puck(pos_m=(30.0, 5.0), radius_m=0.05)
    for _ in range(int(3.0 / (speed * dt_s)) + 2):  # 3 m of travel
        table.step(dt_s)
    assert table.collision_count == 1
    np.testing.assert_allclose(shooter.vel_mps, (0.0, 0.0), atol=1e-9 * speed)
    np.testing.assert_allclose(target.vel_mps, (speed, 0.0), rtol=1e-12)
    assert shooter.pos_m[0] < target.pos_m[0]


def test_reverse_time_retraces_three_pucks_that_meet_in_one_step() -> None:
    # dt = 0.1 s. A (1 kg-ish) at x = 1.0 moves at 2 m/s; B (twice as dense)
    # at 1.35 and C at 1.58 are still; all r = 0.1. A hits B at t = 0.075 s,
    # then B hits C at t = 0.075 + 0.03 / vB, still inside the step. Negating
    # every velocity and stepping again must bring all three back.
    table = AirTable()
    a = table.add_puck(pos_m=(1.0, 4.0), radius_m=0.1, vel_mps=(2.0, 0.0))
    b = table.add_puck(pos_m=(1.35, 4.0), radius_m=0.1, density_kgpm2=0.6)
    c = table.add_puck(pos_m=(1.58, 4.0), radius_m=0.1)
    start_pos, start_vel = table.pos_m.copy(), table.vel_mps.copy()
    table.step(0.1)
    assert table.collision_count == 2
    table.vel_mps[:] *= -1.0
    table.step(0.1)
    assert table.collision_count == 4
    np.testing.assert_allclose(table.pos_m, start_pos, rtol=0, atol=1e-12)
    np.testing.assert_allclose(table.vel_mps, -start_vel, rtol=0, atol=1e-12)
    del a, b, c


# ---------------------------------------------------------------- pi from collisions


@pytest.mark.parametrize(("n", "due"), [(0, 3), (1, 31), (2, 314), (3, 3141), (4, 31415)])
def test_pi_from_collisions(n: int, due: int) -> None:
    # A light puck at rest between the left wall and a puck 100^n times
    # heavier coming at 1 m/s: floor(pi 10^n) collisions in all (Galperin),
    # and the final velocities of the exact event-by-event 1D solution.
    from bench.hard import pi_exact, pi_scene

    table = AirTable(width_m=10.0, height_m=4.0)
    light, heavy = pi_scene(table, n)
    count, v_light, v_heavy = pi_exact(100.0**n)
    assert count == due
    for _ in range(4000):  # the heavy puck is back at x = 8 m by 2256 steps
        table.step(1 / 240)
        v1, v2 = light.vel_mps[0], heavy.vel_mps[0]
        if 0.0 <= v1 <= v2:  # both going right, the heavy one faster: nothing more can happen
            break
    assert table.collision_count + table.wall_collision_count == due
    # Round-off grows with the count; the light puck reaches 100^n / 10^n times its final speed.
    assert light.vel_mps[0] == pytest.approx(v_light, rel=1e-10 * 10**n)
    assert heavy.vel_mps[0] == pytest.approx(v_heavy, rel=1e-11)
    np.testing.assert_allclose(table.vel_mps[:, 1], 0.0, atol=1e-12)


def test_the_pi_demo_counts_the_digits_of_pi_and_stops_the_pucks(demos) -> None:
    demo = demos["t"]
    assert len(demo.variations) == 5
    for n, due in enumerate((3, 31, 314, 3141)):
        table = AirTable()
        demo.build(table, n)
        last_hit = said = None
        for k in range(20 * 240):  # 20 s: done within 12
            before = table.collision_count + table.wall_collision_count
            table.step(demo.dt_s)
            last_hit = k if table.collision_count + table.wall_collision_count != before else last_hit
            said = k if said is None and table.notices else said
        # The count is said as soon as it is final (the demo looks every CHECK_EVERY_S), not when the pucks stop.
        assert 0 <= said - last_hit <= math.ceil(pi_demo.CHECK_EVERY_S / demo.dt_s)
        assert table.collision_count + table.wall_collision_count == due
        np.testing.assert_allclose(table.vel_mps, 0.0)  # stopped before the far wall
        # ... and says why, with the count the lesson is about (the window shows it, as each notice)
        pairs, walls = table.collision_count, table.wall_collision_count
        assert list(table.notices) == [
            f"{due} hits in all: {pairs} between the pucks, {walls} on the wall. No more can come."
        ]


# The 120-puck pile in a 2.5 m box: tests/test_sleep.py (it comes to rest exactly, asleep).


def test_an_inelastic_cluster_does_not_collapse_into_endless_swept_hits():
    # A 300-puck gas under gravity at restitution 0: once, near step 83, a fast
    # puck in a cluster met its neighbours again and again at ever smaller
    # speeds, 200000 swept hits in one step. Slow hits are the contact stage's.
    table = gas_scene(300, seed=3)
    table.gravity_on = True
    table.cr_puck = table.cr_wall = 0.0
    table.puck_correction = "two-step"
    for _ in range(90):
        before = table.collision_count
        table.step(1 / 120)
        assert table.collision_count - before < 1000


@pytest.mark.parametrize("mode", ["two-step", "perfect-kiss", "off"])
@pytest.mark.parametrize("gravity", [False, True])
def test_a_step_of_no_time_moves_nothing(mode: str, gravity: bool) -> None:
    """step(0) on a table of moving pucks, apart, in any mode: nothing moves, nothing changes speed. (A user
    test's: with more than 10 pucks, two-step and "off" divided by the step's length, ZeroDivisionError.)"""
    table = AirTable()
    table.puck_correction, table.gravity_on = mode, gravity
    for k in range(30):
        table.add_puck(pos_m=(0.5 + 0.3 * k, 2.0 + 0.1 * (k % 3)), radius_m=0.1, vel_mps=(5.0, -1.0 + 0.1 * k))
    pos, vel = table.pos_m.copy(), table.vel_mps.copy()
    table.step(0.0)
    np.testing.assert_array_equal(table.pos_m, pos)
    np.testing.assert_array_equal(table.vel_mps, vel)


@pytest.mark.parametrize("mode", ["two-step", "perfect-kiss", "off"])
@pytest.mark.parametrize("speed", [2e5, 1e9, 1e300])
def test_a_puck_thrown_faster_than_anything_on_a_table_is_slowed_and_told(mode: str, speed: float) -> None:
    """A puck thrown at `speed` into a crowd of 40: its step hit each puck and wall one by one, tens of thousands
    of times (at 1 Gm/s a step took minutes). It is slowed to integrate.MAX_SPEED_MPS, and the table says so
    once; nothing leaves the table."""
    table = AirTable()
    table.puck_correction = mode
    table.add_puck(pos_m=(1.0, 1.0), radius_m=0.1, vel_mps=(speed, 0.7 * speed))
    for k in range(40):
        table.add_puck(pos_m=(3.0 + 0.5 * (k % 8), 2.0 + 0.5 * (k // 8)), radius_m=0.2)
    for _ in range(2):
        table.step(1 / 60)
    assert float(np.hypot(*table.vel_mps.T).max()) <= integrate.MAX_SPEED_MPS * (1.0 + 1e-12)
    assert [n for n in table.notices if n == integrate.SPEED_NOTICE] == [integrate.SPEED_NOTICE]
    inside = (table.pos_m >= table.radius_m[:, None]) & (table.pos_m <= table.size_m - table.radius_m[:, None])
    assert inside.all()
