"""A puck as big as the table along an axis: wedged between that axis' two walls, free along the other.

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

from airtable.physics.events import CAPPED_NOTICE
from airtable.physics.table import AirTable


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
