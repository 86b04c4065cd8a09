"""A few pairs (pairs._resolve_few) and a few pucks past a wall (walls._bounce_in_floats) are
resolved in plain floats; they give, to the last bit, what the arrays give."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable.physics import broadphase, pairs, walls
from airtable.physics import table as table_module


def _scene(seed: int, n: int):
    """A handful of pucks heaped in a small square, some exactly on top of each other."""
    rng = np.random.default_rng(seed)
    radius = rng.uniform(0.1, 0.3, n)
    mass = rng.uniform(0.1, 3.0, n) * math.pi * radius**2
    pos = rng.uniform(0.0, 0.8, (n, 2))
    pos[n - 1] = pos[0]
    vel = rng.uniform(-3.0, 3.0, (n, 2))
    return pos, vel, radius, mass


def _resolve(few: int, scene, cr: float, mode: str, dt_s: float, monkeypatch):
    pos, vel, radius, mass = (a.copy() for a in scene)
    i, j = broadphase.brute_force_pairs(pos, radius)
    monkeypatch.setattr(pairs, "FEW_PAIRS", few)
    records = pairs.resolve_pairs(pos, vel, radius, mass, i, j, cr, mode, dt_s, in_time_order=True)
    return pos, vel, pairs.Collisions.concatenate(records)


@settings(max_examples=150, deadline=None, derandomize=True)
@given(
    st.integers(0, 2**32 - 1),
    st.integers(2, 7),
    st.sampled_from(pairs.CORRECTION_MODES),
    st.sampled_from([0.0, 0.5, 1.0]) | st.floats(0.0, 1.0),
    st.sampled_from([1 / 240, 1 / 60, 1 / 20]),
)
def test_floats_give_what_the_arrays_give(seed: int, n: int, mode: str, cr: float, dt_s: float) -> None:
    scene = _scene(seed, n)
    with pytest.MonkeyPatch.context() as mp:
        arrays = _resolve(0, scene, cr, mode, dt_s, mp)  # every round with numpy
        mixed = _resolve(2, scene, cr, mode, dt_s, mp)  # the pairs sharing a puck in floats, if few
        floats = _resolve(10**6, scene, cr, mode, dt_s, mp)  # every pair in floats
    for other in (mixed, floats):
        for got, want in zip(other[:2], arrays[:2], strict=True):
            np.testing.assert_array_equal(got, want)
        # The same collisions; the mixed path records the pairs alone first.
        got, want = (c.take(np.lexsort((c.j, c.i))) for c in (other[2], arrays[2]))
        for field in pairs.Collisions.__dataclass_fields__:
            np.testing.assert_array_equal(getattr(got, field), getattr(want, field))


def _walls(few: int, pos, vel, radius, correction: bool, mp) -> tuple[np.ndarray, np.ndarray, int]:
    pos, vel = pos.copy(), vel.copy()
    mp.setattr(walls, "FEW_PUCKS", few)
    count, _ = walls.resolve_walls(pos, vel, radius, np.array([2.0, 1.5]), 0.7, correction)
    return pos, vel, count


@settings(max_examples=100, deadline=None, derandomize=True)
@given(st.integers(0, 2**32 - 1), st.integers(1, 6), st.booleans())
def test_walls_in_floats_give_what_the_arrays_give(seed: int, n: int, correction: bool) -> None:
    # Pucks anywhere around a 2 x 1.5 m table, some far outside, one wider than the table.
    rng = np.random.default_rng(seed)
    pos = rng.uniform(-1.0, 3.0, (n, 2))
    vel = rng.uniform(-3.0, 3.0, (n, 2))
    radius = rng.uniform(0.05, 0.5, n)
    radius[0] = 1.0 if seed % 3 == 0 else radius[0]
    with pytest.MonkeyPatch.context() as mp:
        arrays = _walls(0, pos, vel, radius, correction, mp)
        floats = _walls(10**6, pos, vel, radius, correction, mp)
    np.testing.assert_array_equal(floats[0], arrays[0])
    np.testing.assert_array_equal(floats[1], arrays[1])
    assert floats[2] == arrays[2]


def _crowd(gravity: bool, seed: int, steps: int = 40):
    """A crowded table, stepped: pairs parted in one pass often push into others."""
    rng = np.random.default_rng(seed)
    table = table_module.AirTable(width_m=2.0, height_m=2.0)
    table.gravity_on = gravity
    for _ in range(70):
        table.add_puck(rng.uniform(0.1, 1.9, 2), radius_m=rng.uniform(0.05, 0.12), vel_mps=rng.uniform(-4, 4, 2))
    for _ in range(steps):
        table.step(1 / 120)
    return table.pos_m.copy(), table.vel_mps.copy()


@pytest.mark.parametrize("gravity", [False, True])
def test_second_look_at_the_moved_pucks_only_finds_what_a_look_at_all_finds(gravity: bool, monkeypatch) -> None:
    monkeypatch.setattr(table_module, "LOOK_AT_MOVED_MIN_PAIRS", 0)
    moved_only = _crowd(gravity, seed=3)
    monkeypatch.setattr(table_module, "LOOK_AT_MOVED_MIN_PAIRS", 10**9)
    every = _crowd(gravity, seed=3)
    np.testing.assert_array_equal(moved_only[0], every[0])
    np.testing.assert_array_equal(moved_only[1], every[1])


def _crowd_changed_by_hand() -> tuple[np.ndarray, np.ndarray, int]:
    """_crowd, then the table shrunk under the pucks, a puck grown and one moved by hand."""
    rng = np.random.default_rng(5)
    table = table_module.AirTable(width_m=2.0, height_m=2.0)
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


def test_walls_near_the_list_find_what_a_pass_over_every_puck_finds(monkeypatch) -> None:
    bands = []
    near_walls = broadphase.NeighbourList.near_walls
    monkeypatch.setattr(
        broadphase.NeighbourList, "near_walls", lambda nl, size: bands.append(1) or near_walls(nl, size)
    )
    monkeypatch.setattr(table_module, "WALL_BAND_MIN_PUCKS", 0)
    near_only = _crowd_changed_by_hand()
    assert len(bands) == 2 * 240  # every step checked only the pucks near a wall: for its hits, then what is past
    monkeypatch.setattr(table_module, "WALL_BAND_MIN_PUCKS", 10**9)
    every = _crowd_changed_by_hand()
    assert len(bands) == 2 * 240
    np.testing.assert_array_equal(near_only[0], every[0])
    np.testing.assert_array_equal(near_only[1], every[1])
    assert near_only[2] == every[2] > 100  # the same bounces, and plenty of them
    x, y = every[0][:, 0], every[0][:, 1]
    assert x.max() < 1.7 and y.min() > 0.0  # everyone back inside the shrunk table


def test_near_walls_are_the_pucks_within_a_skin_of_a_wall() -> None:
    r = 0.1
    skin = broadphase.SKIN_RADII * r  # all radii equal: the skin is SKIN_RADII radii
    # Room (edge to nearest wall of the 2 x 2 m table): 0.9, skin + 0.01, skin - 0.01 (left),
    # skin + 0.01, skin - 0.01 (top).
    x_near, y_near = r + skin - 0.01, 2.0 - r - skin + 0.01
    pos = np.array([[1.0, 1.0], [r + skin + 0.01, 1.0], [x_near, 1.0], [1.0, y_near - 0.02], [1.0, y_near]])
    nl = broadphase.NeighbourList()
    nl.pairs(pos, np.full(len(pos), r))
    assert nl.near_walls(np.array([2.0, 2.0])).tolist() == [2, 4]
    # A table 1.2 m wide puts x = 1.0 a radius from the right-hand wall: near as well.
    assert nl.near_walls(np.array([1.2, 2.0])).tolist() == [0, 2, 3, 4]


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


@pytest.mark.parametrize("few", [0, 100])
def test_a_row_named_twice_bounces_once(few: int, monkeypatch) -> None:
    # The wall pass after the pairs gets the rows they moved, and a row may be in two pairs.
    monkeypatch.setattr(walls, "FEW_PUCKS", few)
    pos, vel, radius = np.array([[-0.02, 1.0], [1.0, 1.0]]), np.array([[-2.0, 0.5], [0.0, 0.0]]), np.full(2, 0.1)
    count, past = walls.resolve_walls(pos, vel, radius, np.array([2.0, 2.0]), 0.5, True, only=np.array([0, 1, 0]))
    assert count == 1 and past.tolist() == [0, 0]
    # Mirrored by its 0.12 m penetration to x = 0.22 m, moving out at 0.5 * 2 m/s.
    np.testing.assert_allclose(pos[0], [0.22, 1.0])
    np.testing.assert_allclose(vel[0], [1.0, 0.5])


def test_the_squared_reach_is_one_number_when_every_radius_is_equal() -> None:
    pos = np.array([[0.5, 0.5], [0.8, 0.5], [2.0, 2.0]])
    nl = broadphase.NeighbourList()
    nl.pairs(pos, np.full(3, 0.1))
    assert nl.reach_squared(0.05) == pytest.approx(0.15**2)  # (0.1 + 0.1 - 0.05)^2, one number
    assert isinstance(nl.reach_squared(), float)
    assert nl.reach_squared_of(np.array([0, 0]), 0.05) == nl.reach_squared(0.05)
    i, j, _ = nl.pairs(pos, np.array([0.1, 0.2, 0.1]))  # a radius changed: the list is built again
    assert (i.tolist(), j.tolist()) == ([0], [1])
    np.testing.assert_allclose(nl.reach_squared(0.05), [0.25**2])  # (0.1 + 0.2 - 0.05)^2, per pair
    np.testing.assert_allclose(nl.reach_squared_of(np.array([0, 0]), 0.05), [0.25**2, 0.25**2])
