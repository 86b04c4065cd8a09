"""Capturing and restoring a table's state: run on from a restored state and get the very same bits."""

from __future__ import annotations

import numpy as np
import pytest
from airtable.demos.demo_0p_gas import gas_scene

from airtable.physics.forces import Pull
from airtable.physics.state import capture, restore, same_bits
from airtable.physics.storage import PLAIN_TYPES
from airtable.physics.table import AirTable

RESTITUTIONS = (1.0, 0.7, 0.3, 0.0)


def run(table: AirTable, steps: int, dt_s: float, pulls=()) -> list[tuple[np.ndarray, np.ndarray]]:
    """Step `table`; the positions and velocities after each step (copies)."""
    out = []
    for _ in range(steps):
        table.step(dt_s, pulls)
        out.append((table.pos_m.copy(), table.vel_mps.copy()))
    return out


def assert_replays(table: AirTable, k: int, m: int, dt_s: float, pulls=()) -> None:
    """k steps, capture, m steps, restore, m steps again: every step's positions and velocities bit-identical."""
    run(table, k, dt_s, pulls)
    state = capture(table)
    first = run(table, m, dt_s, pulls)
    counters = (table.time_s, table.steps, table.collision_count)
    restore(table, state)
    again = run(table, m, dt_s, pulls)
    for (p1, v1), (p2, v2) in zip(first, again, strict=True):
        assert same_bits(p1, p2) and same_bits(v1, v2)
    assert (table.time_s, table.steps, table.collision_count) == counters


def build(demos, key: str, variation: int, cr: float) -> AirTable:
    table = AirTable()
    demos[key].build(table, variation)
    table.cr_puck = table.cr_wall = cr
    return table


@pytest.mark.parametrize("cr", RESTITUTIONS)
def test_the_cradle_replays_through_its_timed_throw(demos, cr):
    table = build(demos, "7", 0, cr)
    # Captured before the throw at 1 s: the event (the demo's own function) must still fire, on the same cue.
    assert_replays(table, k=100, m=400, dt_s=demos["7"].dt_s)
    assert table.collision_count > 0
    assert np.linalg.norm(table.pucks[0].vel_mps) < 4.0  # the cue was thrown, then hit


@pytest.mark.parametrize("cr", RESTITUTIONS)
def test_a_jelly_on_stiff_springs_replays_while_dragged(demos, cr):
    table = build(demos, "6p", 2, cr)  # k 1500 N/m: taken in substeps (substeps.py), kept nowhere
    table.spring_k_Npm[:] *= 1000.0  # k 1.5e6 N/m: beyond what substeps take, so solved implicitly
    table.gravity_on = True
    pull = Pull(row=0, anchor_m=(3.0, 6.0), k_Npm=60.0, drag_Nspm=2.0)
    assert_replays(table, k=60, m=240, dt_s=demos["6p"].dt_s, pulls=[pull])
    assert table.notices  # the implicit springs were noticed, and stay noticed once


# Every mode and every restitution at least once (the full cross of twelve took 6 s of the suite).
@pytest.mark.parametrize(("mode", "cr"), [("two-step", 1.0), ("perfect-kiss", 0.7), ("off", 0.3), ("two-step", 0.0)])
def test_a_gas_under_gravity_replays(cr, mode):
    table = gas_scene(300, seed=3)  # beyond brute force: the neighbour list is in play
    table.gravity_on = True
    table.cr_puck = table.cr_wall = cr
    table.puck_correction = mode
    assert_replays(table, k=37, m=50, dt_s=1 / 120)
    # At restitution 0 a hit of pucks pressed by gravity is a resting contact (contacts.rest_for_restitution):
    # the contact stage stops it, and the pair stage counts only the few of pucks it did not press.
    assert table.collision_count > 50 or (cr == 0.0 and table.contact_solver.count > 50)


def test_pucks_added_and_removed_after_the_capture_come_and_go_with_their_handles():
    table = AirTable()
    a = table.add_puck((2.0, 2.0), vel_mps=(1.0, 0.0))
    b = table.add_puck((5.0, 2.0), vel_mps=(-1.0, 0.0))
    spring = table.add_spring(a, b, length_m=2.0)
    table.schedule(0.5, lambda t: setattr(b, "vel_mps", (0.0, 2.0)))
    table.step(1 / 240)
    state = capture(table)
    table.remove_puck(a)  # and its spring
    c = table.add_puck((8.0, 8.0))
    table.cr_puck, table.gravity_on = 0.2, True
    run(table, 200, 1 / 240)
    assert not a.alive and not spring.alive
    restore(table, state)
    assert table.pucks == (a, b) and table.springs == (spring,)
    assert (a.index, b.index, spring.index) == (0, 1, 0) and not c.alive
    assert (table.cr_puck, table.gravity_on) == (1.0, False)
    assert same_bits(a.pos_m, state.pucks["pos"][0]) and spring.p1 is a
    run(table, 200, 1 / 240)  # the throw at 0.5 s still moves b, through its old handle
    assert b.vel_mps[1] != 0.0


def test_a_state_shares_what_did_not_change_and_counts_it_once():
    table = gas_scene(1000, seed=1)
    first = capture(table)
    table.step(1 / 120)
    second = capture(table, like=first)
    assert second.pucks["radius"] is first.pucks["radius"] and second.pucks["mass"] is first.pucks["mass"]
    assert second.pucks["pos"] is not first.pucks["pos"]
    assert not second.pucks["pos"].flags.writeable  # a state never changes
    n = len(table.pucks)
    # Positions, velocities, forces, radii, masses (8 bytes each) and colours; the list's radii are the pucks'.
    assert first.nbytes >= n * (2 + 2 + 2 + 1 + 1) * 8 + 3 * n
    assert second.neighbours[1] is second.pucks["radius"]


def test_every_table_attribute_is_captured():
    """A new cache or setting in AirTable must be a plain value or a part that saves itself."""
    table = gas_scene(100)
    table.step(1 / 120)
    for name, value in vars(table).items():
        part = name in table.PARTS and hasattr(value, "save") and hasattr(value, "restore")
        assert part or name in table.NOT_SAVED or isinstance(value, PLAIN_TYPES), name
    state = capture(table)
    values = dict(zip(state.names, state.values, strict=True))
    for name in ("_gravity_on", "_gravity_mps2", "_cr_puck", "_cr_wall", "wall_correction", "_puck_correction"):
        assert name in values
    for name in ("time_s", "steps", "collision_count", "spring_dt_s", "_puck_collisions", "_width_m", "changed"):
        assert name in values
    restore(table, state)  # what the last step's collisions did is not state: a restored table reports none
    assert len(table.last_collisions.i) == 0


def test_same_bits_tells_minus_zero_from_zero():
    assert not same_bits(np.array([0.0]), np.array([-0.0]))
    assert same_bits(np.array([np.nan]), np.array([np.nan]))
    assert not same_bits(np.zeros(2), np.zeros(3))


def test_a_resting_pile_replays_with_its_warm_started_contacts():
    table = gas_scene(200, seed=3)
    table.gravity_on = True
    table.cr_puck = table.cr_wall = 0.0
    table.sleeping = False  # at restitution 0 it lands dead and would be mostly asleep: keep its contacts busy
    run(table, 300, 1 / 120)  # settled into a pile: the contact stage holds it up
    state = capture(table)
    keys, impulses = state.contacts[:2]
    assert len(keys) > 100 and impulses[:, 0].max() > 0.0  # last step's impulses, kept for the warm start
    assert_replays(table, k=0, m=60, dt_s=1 / 120)
