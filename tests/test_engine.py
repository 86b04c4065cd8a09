"""The engine under real use (issue 14): the small ones, resting contact, fast shots, pi.

Every expected number is worked out by hand here; every loop is bounded in steps.
"""

from __future__ import annotations

import numpy as np
import pytest

from airtable import AirTable
from airtable.physics.reference import Disc, collide_pair

# ---------------------------------------------------------------- the small ones


def test_two_step_at_restitution_0_leaves_the_pair_touching() -> None:
    # Head on, equal masses (1 kg), 0.04 m of overlap closing at 2 m/s, e = 0:
    # both end at 0 m/s; back up t_p = 0.02 s (each moves 0.02 m back), then
    # forward 0.02 s at 0 m/s: centres 1.0 apart, exactly touching.
    p1 = Disc((1.0, 0.0), (1.0, 0.0), 0.5, 1.0)
    p2 = Disc((1.96, 0.0), (-1.0, 0.0), 0.5, 1.0)
    q1, q2 = collide_pair(p1, p2, cr=0.0, mode="two-step", dt_s=1 / 20)
    assert q1.vel == pytest.approx((0.0, 0.0)) and q2.vel == pytest.approx((0.0, 0.0))
    assert q1.pos == pytest.approx((0.98, 0.0)) and q2.pos == pytest.approx((1.98, 0.0))


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
