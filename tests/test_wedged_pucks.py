"""A puck as big as the table along an axis: wedged between that axis' two walls, free along the other;
and one that fits it but for a hair, which rattles between them.

add_puck puts a puck too big for an axis at the table's centre along it (a demo's narrow table, a big
puck). Found by a fuzz of random scenes: such a puck moving across that axis hit one wall, was past the
other at once, and bounced between them at one moment until the step's bound on hits (events.MAX_EVENTS):
1.5 to 2 s a step, every step (50 s in a scene cut into pieces), the app frozen.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable.physics.events import CAPPED_NOTICE, RATTLE_MAX, RATTLE_NOTICE
from airtable.physics.table import AirTable
from airtable.physics.walls import WEDGED_NOTICE


def unfolded(x0: float, v: float, t: float, lo: float, hi: float) -> float:
    """Where a point between lo and hi, bouncing elastically off both, is after t (by hand: the path unfolded)."""
    span = hi - lo
    s = (x0 - lo + v * t) % (2.0 * span)
    return lo + (s if s <= span else 2.0 * span - s)


@settings(max_examples=40, deadline=None)
@given(
    axis=st.sampled_from([0, 1]),
    oversize=st.floats(1.0, 3.0),
    speed=st.tuples(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0)),
    gravity=st.booleans(),
    mode=st.sampled_from(["off", "two-step", "perfect-kiss"]),
    dt_s=st.sampled_from([1 / 240, 1 / 60, 1 / 30]),
)
def test_a_wedged_puck_stays_at_the_centre_across_and_bounces_along(axis, oversize, speed, gravity, mode, dt_s):
    t = AirTable(width_m=8.0, height_m=2.0) if axis == 1 else AirTable(width_m=2.0, height_m=8.0)
    t.gravity_on, t.puck_correction, t.cr_wall = gravity and axis == 1, mode, 1.0  # (gravity across the wedge)
    t.sleeping = False  # (under gravity a puck drifting 0.06 mm/s falls asleep, as it should: not this test's)
    size = float(t.size_m[axis])
    r = 0.5 * size * oversize
    free = 1 - axis
    start = [0.0, 0.0]
    start[axis], start[free] = 0.5 * size, 4.0
    t.add_puck(pos_m=start, radius_m=r, vel_mps=speed)
    steps = 60
    for _ in range(steps):
        t.step(dt_s)
        assert CAPPED_NOTICE not in t.notices  # (each step had 100000 hits, 1.5 to 2 s)
    assert t.vel_mps[0, axis] == 0.0 and t.pos_m[0, axis] == 0.5 * size
    assert list(t.notices).count(WEDGED_NOTICE) == 1  # said once: why it moves along the table only
    lo, hi, v, time_s = r, float(t.size_m[free]) - r, speed[free], steps * dt_s
    assert t.pos_m[0, free] == pytest.approx(unfolded(4.0, v, time_s, lo, hi), abs=1e-9)
    assert abs(t.vel_mps[0, free]) == pytest.approx(abs(v), rel=1e-12)
    run_up = 4.0 - lo if v < 0.0 else hi - 4.0  # to the first wall it meets, then a span to each next one
    travel = abs(v) * time_s - run_up
    # (A wall reached at the very end of the run is hit then or at the next step's start: either count.)
    assert max(0, math.ceil(travel / (hi - lo) - 1e-9)) <= t.wall_collision_count
    assert t.wall_collision_count <= max(0, math.floor(travel / (hi - lo) + 1e-9) + 1)


@pytest.mark.parametrize("mode", ["two-step", "perfect-kiss"])
def test_a_puck_hits_a_wedged_one_along_its_free_axis_as_by_hand(mode):
    t = AirTable(width_m=10.0, height_m=1.0)
    t.puck_correction, t.cr_puck = mode, 1.0
    big = t.add_puck(pos_m=(6.0, 0.5), radius_m=0.6)  # 1.2 m across, in a table 1 m tall
    small = t.add_puck(pos_m=(2.0, 0.5), radius_m=0.2, vel_mps=(1.5, 0.0))
    m1, m2 = small.mass_kg, big.mass_kg
    for _ in range(3 * 240):  # (it meets the big one after 2.13 s)
        t.step(1 / 240)
    assert t.collision_count == 1 and CAPPED_NOTICE not in t.notices
    assert t.vel_mps[1, 0] == pytest.approx((m1 - m2) / (m1 + m2) * 1.5, rel=1e-12)
    assert t.vel_mps[0, 0] == pytest.approx(2.0 * m1 / (m1 + m2) * 1.5, rel=1e-12)
    assert t.vel_mps[:, 1].tolist() == [0.0, 0.0] and t.pos_m[0, 1] == 0.5


@settings(max_examples=40, deadline=None)
@given(
    axis=st.sampled_from([0, 1]),
    room_m=st.one_of(st.floats(1e-16, 1e-12), st.floats(1e-12, 1e-6)),
    speed=st.tuples(st.floats(-3.0, 3.0), st.floats(0.05, 3.0)),
    mode=st.sampled_from(["off", "two-step", "perfect-kiss"]),
    dt_s=st.sampled_from([1 / 240, 1 / 60, 1 / 30]),
)
def test_a_puck_that_fits_the_table_but_for_a_hair_stops_rattling_across_it(axis, room_m, speed, mode, dt_s):
    """Radius half the height less 1e-16 m (round-off): the exact motion bounces across the room millions of
    times a step; each step took a second (100000 hits, capped). It stops across, and moves on along."""
    t = AirTable(width_m=6.0, height_m=0.7) if axis == 1 else AirTable(width_m=0.7, height_m=6.0)
    t.puck_correction, t.cr_wall, t.sleeping = mode, 1.0, False
    size, free = float(t.size_m[axis]), 1 - axis
    r = 0.5 * (size - room_m)
    start, vel = [0.0, 0.0], [0.0, 0.0]
    start[axis], start[free] = 0.5 * size, 3.0
    vel[free], vel[axis] = speed
    t.add_puck(pos_m=start, radius_m=r, vel_mps=vel)
    crossings = speed[1] * dt_s / (size - 2.0 * r)  # how many times the exact motion crosses the room a step
    steps = 30
    for _ in range(steps):
        t.step(dt_s)
        assert CAPPED_NOTICE not in t.notices
        assert r - 1e-12 <= t.pos_m[0, axis] <= size - r + 1e-12  # inside, up to round-off
    if crossings > 2 * RATTLE_MAX:  # (in between, it may or may not have stopped within its first step)
        assert t.vel_mps[0, axis] == 0.0 and RATTLE_NOTICE in t.notices
        assert t.wall_collision_count <= RATTLE_MAX + 2 * steps  # (not millions: along, it bounces a few times)
    lo, hi, v = r, float(t.size_m[free]) - r, speed[0]
    assert t.pos_m[0, free] == pytest.approx(unfolded(3.0, v, steps * dt_s, lo, hi), abs=1e-9)
    assert abs(t.vel_mps[0, free]) == pytest.approx(abs(v), rel=1e-12)
    # (A light puck squeezed between a heavy one and a wall hits the heavy one between its wall hits: no
    # rattle. The pi counts of test_engine.py and test_event_oracle.py, 31415 hits at 10^8:1, say so.)
