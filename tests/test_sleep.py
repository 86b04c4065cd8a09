"""Sleeping (airtable/physics/sleep.py): pucks at rest under gravity are set aside until disturbed."""

from __future__ import annotations

import numpy as np
import pytest

from airtable.physics import sleep
from airtable.physics.state import capture, restore, same_bits
from airtable.physics.table import AirTable
from bench.hard import pile_scene

DT_S = 1 / 240
R_M = 0.25


def floor_table(xs=(5.0,), y_m: float = R_M, sleeping: bool = True) -> AirTable:
    """Pucks of r = 0.25 m at (x, y_m) under gravity, restitution 0."""
    table = AirTable()
    table.sleeping = sleeping
    table.gravity_on = True
    table.cr_wall = 0.0
    for x in xs:
        table.add_puck(pos_m=(x, y_m), radius_m=R_M)
    return table


def steps(table: AirTable, n: int, pulls=()) -> None:
    for _ in range(n):
        table.step(DT_S, pulls)


def test_a_puck_dropped_on_the_floor_falls_asleep_at_rest() -> None:
    # Dropped 0.75 m: it lands after sqrt(2 * 0.75 / 9.8) = 0.39 s (in step 94) and, at
    # restitution 0, stays there (the wall hit is resolved when it happens: no hop). Half a
    # second (120 steps) still: asleep at step 213 or 214, not before step 210 in any case.
    table = floor_table(y_m=1.0)
    steps(table, 210)
    assert not table.asleep[0]
    steps(table, 240 - 210)
    assert table.asleep[0]
    assert table.vel_mps[0, 0] == 0.0 and table.vel_mps[0, 1] == 0.0  # exactly
    assert table.pos_m[0, 1] == pytest.approx(R_M, abs=1e-12)
    steps(table, 240)  # and it stays so: not even gravity moves a sleeper
    assert table.asleep[0] and table.pos_m[0, 1] == pytest.approx(R_M, abs=1e-12)
    assert table.kinetic_energy_J() == 0.0


def test_with_sleeping_off_no_puck_sleeps() -> None:
    table = floor_table(sleeping=False)
    steps(table, 240)
    assert not table.asleep.any()


def settled_row(sleeping: bool) -> AirTable:
    """A shooter at x = 4 m and a row of three touching pucks from x = 5 m, resting on the floor
    for 0.6 s (asleep, if sleeping), then the shooter given 3 m/s to the right."""
    table = floor_table(xs=(4.0, 5.0, 5.5, 6.0), sleeping=sleeping)
    table.cr_puck = 1.0
    steps(table, 144)
    assert table.asleep.all() == sleeping
    table.pucks[0].vel_mps = (3.0, 0.0)
    return table


def test_a_fast_shot_wakes_a_sleeping_row_and_hits_as_if_it_were_awake() -> None:
    # Equal masses, elastic, head on: the shooter stops and the far end of
    # the row leaves at 3 m/s (the cradle), sleeping or not. The shooter
    # reaches the row after 0.5 m / 3 m/s = 0.17 s: look at 0.4 s.
    awake, dozing = settled_row(False), settled_row(True)
    for _ in range(int(0.4 / DT_S)):
        awake.step(DT_S)
        dozing.step(DT_S)
    np.testing.assert_allclose(dozing.vel_mps, awake.vel_mps, atol=1e-9)
    np.testing.assert_allclose(dozing.pos_m, awake.pos_m, atol=1e-9)
    assert dozing.vel_mps[3, 0] == pytest.approx(3.0, abs=1e-6)
    assert dozing.momentum_Ns()[0] == pytest.approx(3.0 * dozing.mass_kg[0], rel=1e-9)
    assert not dozing.asleep[3]


def test_a_velocity_or_position_written_into_a_sleeper_wakes_it() -> None:
    table = floor_table(xs=(3.0, 7.0))
    steps(table, 144)
    assert table.asleep.all()
    a, b = table.pucks
    a.vel_mps = (1.0, 0.0)
    b.pos_m = (7.5, R_M)
    table.step(DT_S)
    assert not table.asleep.any()
    assert a.pos_m[0] == pytest.approx(3.0 + DT_S, abs=1e-12)  # 1 m/s for one step
    assert b.pos_m[0] == 7.5


def test_a_handle_setter_wakes_its_sleeper_even_with_the_same_value() -> None:
    # The setter marks the puck (as Box2D's b2Body_SetLinearVelocity wakes the body); an array
    # written directly is found by comparing it with where the puck sleeps, so only a change shows.
    table = floor_table(xs=(3.0, 7.0))
    steps(table, 144)
    a, b = table.pucks
    a.pos_m = a.pos_m
    table.vel_mps[1] = 0.0
    table.step(DT_S)
    assert list(table.asleep) == [False, True]


def test_a_slow_drag_wakes_the_sleepers_it_pushes() -> None:
    # A cursor string of 1 N with 20 N s/m of drag moves a puck at most
    # 1 / 20 = 0.05 m/s, slower than WAKE_MPS: it still wakes the puck it
    # reaches 5 mm away (after about 0.1 s) and pushes it along, where a
    # sleeper would otherwise be a wall. In 0.5 s they move about 2 cm.
    from airtable.physics.forces import Pull

    table = floor_table(xs=(3.0, 3.505))
    steps(table, 144)
    assert table.asleep.all()
    pull = [Pull(row=0, anchor_m=(4.0, R_M), k_Npm=1.0, drag_Nspm=20.0)]
    table.step(DT_S, pull)
    assert list(table.asleep) == [False, True]
    steps(table, 120, pull)
    assert not table.asleep.any()
    assert table.vel_mps[0, 0] < sleep.WAKE_MPS
    assert 3.505 + 0.005 < table.pos_m[1, 0] < 3.505 + 0.03


@pytest.mark.parametrize("change", ["off", "stronger", "wider", "added", "correction", "radius", "spring"])
def test_a_change_of_the_world_wakes_every_puck(change) -> None:
    table = floor_table(xs=(3.0, 7.0))
    steps(table, 144)
    assert table.asleep.all()
    if change == "off":
        table.gravity_on = False
    elif change == "stronger":
        table.gravity_mps2 = 20.0
    elif change == "wider":
        table.width_m = 12.0
    elif change == "correction":
        table.puck_correction = "two-step"
    elif change == "radius":
        table.pucks[0].radius_m = 0.3
    elif change == "spring":
        table.add_spring(*table.pucks, length_m=4.0)
    else:
        table.add_puck(pos_m=(5.0, 4.0), radius_m=R_M)
    table.step(DT_S)
    assert not table.asleep.any()


@pytest.fixture(scope="module")
def box_pile():
    """120 pucks dropped into a 2.5 m box (as in tests/test_engine.py), stepped until all sleep
    (at most 6 s); also a state captured while part of the pile slept."""
    table = AirTable(width_m=2.5, height_m=4.0)
    pile_scene(table, n=120)
    partly = None
    for _ in range(6 * 240):
        table.step(DT_S)
        if partly is None and 30 <= table.asleep.sum() <= 90:
            partly = capture(table)
        if table.asleep.all():
            break
    return table, partly


def test_a_pile_in_a_box_comes_to_rest_exactly(box_pile) -> None:
    # At rest means asleep: every velocity exactly 0, within 6 s (about 2.2).
    table, _ = box_pile
    assert table.asleep.all() and table.time_s <= 6.0
    assert table.kinetic_energy_J() == 0.0
    d = table.pos_m[:, None, :] - table.pos_m[None, :, :]
    gap = np.hypot(d[..., 0], d[..., 1]) + np.eye(120)
    assert gap.min() > 0.2 - 2e-3  # no two pucks overlap by more than 2 mm
    assert np.all(table.pos_m >= 0.1) and np.all(table.pos_m <= table.size_m - 0.1)


def test_a_partly_sleeping_pile_replays_bit_identically(box_pile) -> None:
    _, state = box_pile
    table = AirTable(width_m=2.5, height_m=4.0)
    restore(table, state)
    assert 0 < table.asleep.sum() < 120
    first = []
    for _ in range(40):
        table.step(DT_S)
        first.append((table.pos_m.copy(), table.vel_mps.copy(), table.asleep.copy()))
    restore(table, state)
    for p, v, a in first:
        table.step(DT_S)
        assert same_bits(table.pos_m, p) and same_bits(table.vel_mps, v) and same_bits(table.asleep, a)


def test_the_asleep_mask_is_read_only() -> None:
    table = floor_table()
    with pytest.raises(ValueError):
        table.asleep[0] = True


def test_waking_a_puck_wakes_the_sleepers_it_touches_and_no_others() -> None:
    # Two pucks stacked on the floor at x = 5 m and one alone at x = 8 m, all
    # asleep. A velocity written into the top one wakes the stack (the bottom
    # one must hold it up: Box2D wakes the whole island), not the lone one.
    # Half a second later the stack sleeps again, where it was.
    table = floor_table(xs=(5.0, 8.0))
    table.add_puck(pos_m=(5.0, 3 * R_M), radius_m=R_M)
    steps(table, 144)
    assert table.asleep.all()
    table.pucks[2].vel_mps = (0.0, -1e-3)
    table.step(DT_S)
    assert list(table.asleep) == [False, True, False]
    steps(table, int(sleep.SLEEP_S / DT_S) + 2)
    assert table.asleep.all()
    assert table.pos_m[2, 1] == pytest.approx(3 * R_M, abs=1e-3)


def test_moving_pucks_leave_the_sleep_columns_alone_so_a_history_shares_them() -> None:
    # Three pucks thrown at 1 m/s sideways under gravity are never slower
    # than SLEEP_MPS: their still time stays 0 and their anchor where it was.
    table = floor_table(xs=(2.0, 5.0, 8.0), y_m=4.0)
    table.vel_mps[:] = (1.0, 0.0)
    table.step(DT_S)
    first = capture(table)
    table.step(DT_S)
    second = capture(table, like=first)
    assert second.pucks["still"] is first.pucks["still"]
    assert second.pucks["rest_pos"] is first.pucks["rest_pos"]
    assert second.pucks["pos"] is not first.pucks["pos"]
