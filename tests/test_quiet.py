"""A quiet table (quiet.py): once a step changed nothing, the next ones only advance the time, and give what the
whole step gives, bit for bit, on scenes hypothesis makes (still pucks, touching, overlapping, on and past the
walls), through every kind of write that ends the quiet."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import event, given, settings
from hypothesis import strategies as st

from airtable.physics.forces import Pull
from airtable.physics.table import AirTable

DT = 1 / 240


scenes = st.fixed_dictionaries(
    {
        "mode": st.sampled_from(["perfect-kiss", "two-step"]),
        "cr": st.sampled_from([0.0, 0.5, 1.0]),
        "pucks": st.lists(
            st.tuples(st.floats(0.05, 0.4), st.floats(0.0, 4.0), st.floats(0.0, 3.0), st.floats(0.1, 10.0)),
            min_size=1,
            max_size=12,
        ),
        "touching": st.booleans(),
    }
)


def still_scene(scene: dict) -> AirTable:
    """Still pucks anywhere on a 4 x 3 m table: apart, overlapping, pressed to a wall, two touching exactly."""
    table = AirTable(width_m=4.0, height_m=3.0)
    table.puck_correction, table.cr_puck = scene["mode"], scene["cr"]
    for r, x, y, density in scene["pucks"]:
        table.add_puck((x, y), radius_m=r, density_kgpm2=density)
    if scene["touching"] and len(table.pucks) > 1:
        a, b = table.pucks[0], table.pucks[1]
        b.pos_m = (a.pos_m[0] + a.radius_m + b.radius_m, a.pos_m[1])
    return table


def same(a: AirTable, b: AirTable) -> bool:
    return (
        np.array_equal(a.pos_m, b.pos_m)
        and np.array_equal(a.vel_mps, b.vel_mps)
        and a.time_s == b.time_s
        and a.steps == b.steps
        and a.collision_count == b.collision_count
        and a.wall_collision_count == b.wall_collision_count
    )


def whole_step(table: AirTable, dt: float = DT, pulls=()) -> None:
    """A step with the quiet memo forgotten: every stage runs."""
    table.quiet = None
    table.step(dt, pulls)


# What may happen to a quiet table between two steps; each must give what the whole step gives.
WRITES = {
    "nothing": lambda t: None,
    "velocity written into the array": lambda t: t.vel_mps.__setitem__((0, 0), 0.3),
    "a puck moved through its handle": lambda t: setattr(t.pucks[0], "pos_m", (1.0, 1.0)),
    "a puck added on top of another": lambda t: t.add_puck(tuple(t.pos_m[0]), radius_m=0.1),
    "gravity on": lambda t: setattr(t, "gravity_on", True),
    "a force": lambda t: t.force_N.__setitem__((0, 1), 2.0),
    "a bigger radius": lambda t: setattr(t.pucks[0], "radius_m", 0.9),
    "the table narrowed": lambda t: setattr(t, "width_m", 1.0),
    "a spring": lambda t: t.add_spring(t.pucks[0], t.pucks[-1], k_Npm=5.0, length_m=0.1) if len(t.pos_m) > 1 else None,
}


@settings(max_examples=40, deadline=None)
@given(scene=scenes, write=st.sampled_from(sorted(WRITES)))
def test_a_quiet_table_steps_as_the_whole_step_does(scene, write):
    quick, whole = still_scene(scene), still_scene(scene)
    assert same(quick, whole)
    for _ in range(30):  # overlaps parted and walls pushed off first; then quiet
        began, hits = whole.pos_m.copy(), whole.collision_count + whole.wall_collision_count
        quick.step(DT)
        whole_step(whole)
    assert same(quick, whole)
    hit = whole.collision_count + whole.wall_collision_count > hits
    if np.array_equal(began, whole.pos_m) and not (hit or whole.vel_mps.any() or whole.contact_solver.pressing()):
        assert quick.quiet is not None, "at rest, and the last step changed nothing: quiet"
    event("quiet" if quick.quiet is not None else "not quiet")
    for table in (quick, whole):
        WRITES[write](table)
    for _ in range(30):
        quick.step(DT)
        whole_step(whole)
        assert same(quick, whole), write


def test_a_still_grid_goes_quiet_after_one_step_and_a_throw_or_a_string_ends_it():
    table = AirTable()
    for k in range(54):
        table.add_puck((1.0 + 0.9 * (k % 9), 1.0 + 0.9 * (k // 9)), radius_m=0.3)
    table.step(DT)
    assert table.quiet is not None and table.quiet.holds(table, ())
    before = table.pos_m.copy()
    for _ in range(240):
        table.step(DT)
    assert np.array_equal(table.pos_m, before) and table.time_s == pytest.approx(241 * DT) and table.steps == 241
    pull = Pull(row=0, anchor_m=(0.5, 0.5), k_Npm=20.0, drag_Nspm=1.0)
    table.step(DT, [pull])  # a cursor string pulls: the whole step runs
    assert table.quiet is None and table.vel_mps[0].any()
    table.vel_mps[:] = 0.0
    table.pucks[1].vel_mps = (2.0, 0.0)  # a throw: it hits its neighbour
    for _ in range(120):
        table.step(DT)
    assert table.collision_count >= 1 and table.quiet is None
