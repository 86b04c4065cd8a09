"""Collisions: pair physics (90 degree rule, 1D formulas, the corrections), walls, broadphase.

Every expected number is worked out by hand in the test from the textbook
formulas; the engine is only ever compared with those, never with itself.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from airtable.demos.demo_0p_gas import gas_scene
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable import AirTable
from airtable.physics import broadphase, pairs

MODES = pairs.CORRECTION_MODES


def mass_of(radius_m: float, density_kgpm2: float = 0.3) -> float:
    return density_kgpm2 * math.pi * radius_m**2


def step_until_collision(table: AirTable, dt_s: float, max_steps: int = 100) -> pairs.Collisions:
    """Step until a step reports a collision; return that step's collisions."""
    for _ in range(max_steps):
        table.step(dt_s)
        if len(table.last_collisions):
            return table.last_collisions
    raise AssertionError("no collision happened")


def assert_inside_walls(table: AirTable) -> None:
    r = table.radius_m[:, None]
    p = table.pos_m
    assert np.all(np.isfinite(p)) and np.all(np.isfinite(table.vel_mps))
    assert np.all(p >= r) and np.all(p <= table.size_m - r), "a puck ended the step outside the walls"


# ---------------------------------------------------------------- pair physics


@pytest.mark.parametrize("mode", MODES)
def test_equal_masses_off_centre_leave_at_90_degrees(mode: str) -> None:
    table = AirTable()
    table.puck_correction = mode
    shooter = table.add_puck(pos_m=(2.0, 4.0), radius_m=0.25, vel_mps=(3.0, 0.0))
    target = table.add_puck(pos_m=(5.0, 4.2), radius_m=0.25)  # impact parameter 0.2 m
    p0, ke0 = table.momentum_Ns(), table.kinetic_energy_J()
    v0 = shooter.vel_mps

    hits = step_until_collision(table, 1 / 100)

    assert len(hits) == 1
    n = hits.normal[0]  # unit, along the line of centres
    tangent = np.array([-n[1], n[0]])
    v1, v2 = shooter.vel_mps, target.vel_mps
    cos_angle = np.dot(v1, v2) / (np.linalg.norm(v1) * np.linalg.norm(v2))
    assert math.degrees(math.acos(cos_angle)) == pytest.approx(90.0, abs=0.01)
    # The shooter keeps its tangential velocity; the target gets only normal velocity.
    assert np.dot(v1, tangent) == pytest.approx(np.dot(v0, tangent), rel=1e-12)
    assert np.dot(v2, tangent) == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(table.momentum_Ns(), p0, rtol=1e-12, atol=1e-12 * np.linalg.norm(p0))
    assert table.kinetic_energy_J() == pytest.approx(ke0, rel=1e-12)


@pytest.mark.parametrize("cr", [1.0, 0.5])
@pytest.mark.parametrize("mode", MODES)
def test_head_on_unequal_masses_match_the_1d_formulas(cr: float, mode: str) -> None:
    table = AirTable()
    table.cr_puck = cr
    table.puck_correction = mode
    r1, r2, u1, u2 = 0.3, 0.2, 2.0, -1.0
    m1, m2 = mass_of(r1), mass_of(r2)
    a = table.add_puck(pos_m=(3.0, 4.0), radius_m=r1, vel_mps=(u1, 0.0))
    b = table.add_puck(pos_m=(4.0, 4.0), radius_m=r2, vel_mps=(u2, 0.0))

    step_until_collision(table, 1 / 100)

    # 1D collision with restitution e: momentum kept, relative speed times -e.
    v1 = (m1 * u1 + m2 * u2 - m2 * cr * (u1 - u2)) / (m1 + m2)
    v2 = (m1 * u1 + m2 * u2 + m1 * cr * (u1 - u2)) / (m1 + m2)
    assert a.vel_mps[0] == pytest.approx(v1, rel=1e-12)
    assert b.vel_mps[0] == pytest.approx(v2, rel=1e-12)
    assert a.vel_mps[1] == 0.0 and b.vel_mps[1] == 0.0


# (r1, r2, v1, v2, y offset of puck 2, restitution): approaching pairs of unequal mass.
TWO_STEP_CASES = [
    (0.30, 0.20, (2.0, 0.0), (-1.0, 0.0), 0.0, 1.0),
    (0.40, 0.15, (1.5, 0.0), (0.0, 0.0), 0.0, 1.0),
    (0.25, 0.35, (3.0, 0.5), (-0.5, 0.0), 0.1, 1.0),
    (0.20, 0.45, (2.0, -0.3), (-2.0, 0.2), -0.05, 0.5),
    (0.30, 0.30, (2.0, 0.0), (-1.0, 0.0), 0.0, 0.0),
]


@pytest.mark.parametrize(("r1", "r2", "v1", "v2", "dy", "cr"), TWO_STEP_CASES)
def test_two_step_separation_is_e_times_the_overlap(r1, r2, v1, v2, dy, cr) -> None:
    table = AirTable()
    table.puck_correction = "two-step"
    table.rest_speed_mps = 0.0  # every approach is a collision here
    table.cr_puck = cr
    m1, m2 = mass_of(r1), mass_of(r2)
    a = table.add_puck(pos_m=(3.0, 4.0), radius_m=r1, vel_mps=v1)
    b = table.add_puck(pos_m=(3.0 + r1 + r2 + 0.013, 4.0 + dy), radius_m=r2, vel_mps=v2)
    dt = 1 / 60
    for _ in range(100):
        x1, x2 = a.pos_m, b.pos_m
        table.step(dt)
        if len(table.last_collisions):
            break
    hits = table.last_collisions
    assert len(hits) == 1
    # By hand: where the Euler step put them, the overlap there, and the normal.
    x1, x2 = x1 + np.array(v1) * dt, x2 + np.array(v2) * dt
    d = x1 - x2
    overlap = r1 + r2 - np.linalg.norm(d)
    n = d / np.linalg.norm(d)
    vn = np.dot(np.subtract(v1, v2), n)
    assert overlap < -vn * dt  # the step's approach explains the overlap: no cap
    assert hits.overlap_m[0] == pytest.approx(overlap, rel=1e-9)
    assert hits.separation_m[0] == pytest.approx(cr * overlap, rel=1e-9, abs=1e-12)
    # Back up t_p (the pair parts by the overlap), forward t_p with the
    # normal velocities after the collision (by cr times the overlap more):
    # each puck moves (1 + cr) times its mass share of the overlap.
    part = (1.0 + cr) * overlap
    np.testing.assert_allclose(a.pos_m, x1 + part * m2 / (m1 + m2) * n, rtol=0, atol=1e-12)
    np.testing.assert_allclose(b.pos_m, x2 - part * m1 / (m1 + m2) * n, rtol=0, atol=1e-12)
    assert np.linalg.norm(a.pos_m - b.pos_m) - (r1 + r2) == pytest.approx(cr * overlap, rel=1e-9, abs=1e-12)


def _kiss_run(mode: str, offset_m: float, b_m: float) -> tuple[float, float, float, float]:
    """Shoot a 25 m/s puck at an equal still one; return the target's angle (deg), speed, detected overlap and where
    the shooter was, along the line of travel relative to the target, when the overlap was detected (m)."""
    r, v, dt = 0.45, 25.0, 1 / 20
    table = AirTable(width_m=200.0, height_m=200.0)  # walls far away
    table.puck_correction = mode
    target = table.add_puck(pos_m=(100.0, 100.0), radius_m=r)
    shooter = table.add_puck(pos_m=(97.0 - offset_m, 100.0 - b_m), radius_m=r, vel_mps=(v, 0.0))
    overlap = along = math.nan
    for _ in range(8):  # 6 m of travel: well past the target
        x_before = shooter.pos_m[0]
        table.step(dt)
        if len(table.last_collisions):
            overlap = float(table.last_collisions.overlap_m[0])
            along = x_before + v * dt - 100.0
    vx, vy = target.vel_mps
    return math.degrees(math.atan2(vy, vx)), math.hypot(vx, vy), overlap, along


def test_perfect_kiss_outcome_does_not_depend_on_overlap_depth() -> None:
    r, v, b = 0.45, 25.0, 0.3
    ideal_angle = math.asin(b / (2 * r))  # the target leaves along the normal at first contact
    ideal_speed = v * math.cos(ideal_angle)
    offsets = [v * (1 / 20) * k / 20 for k in range(20)]  # across one step of travel

    kiss = [_kiss_run("perfect-kiss", off, b) for off in offsets]
    for angle, speed, _, _ in kiss:
        assert angle == pytest.approx(math.degrees(ideal_angle), abs=0.01)
        assert speed == pytest.approx(ideal_speed, rel=1e-6)
    # The shooter moves 1.25 m a step, far more than a radius: it is swept
    # over its step and every hit is found at first contact, overlap 0.
    assert all(o == 0.0 for _, _, o, _ in kiss)

    # Two-step keeps the course's model where the overlap is found while the
    # pair still approaches: the detected normal is too steep, so angle and
    # speed depend on where in the step the hit fell (what demo 2p shows).
    # Hits it would have found past the closest approach are swept: exact.
    two_step = [_kiss_run("two-step", off, b) for off in offsets]
    speeds = [s for _, s, _, _ in two_step]
    angles = [a for a, s, _, _ in two_step if s > 0]
    assert min(speeds) > 0.0  # every shot hits
    assert max(speeds) - min(speeds) > 10.0
    assert max(angles) - min(angles) > 20.0
    swept = [a for a, _, o, _ in two_step if o == 0.0]
    assert swept and all(a == pytest.approx(math.degrees(ideal_angle), abs=0.01) for a in swept)


# ---------------------------------------------------------------- walls


def test_wall_restitution_applies_only_when_moving_into_the_wall() -> None:
    table = AirTable()
    table.cr_wall = 0.5
    r, dt = 0.25, 1 / 100
    into = table.add_puck(pos_m=(r + 0.01, 2.0), radius_m=r, vel_mps=(-2.0, 0.0))  # 0.01 m past after the step
    away = table.add_puck(pos_m=(6.0, r - 0.05), radius_m=r, vel_mps=(0.0, 1.0))  # overlapping, leaving
    top = table.add_puck(pos_m=(8.0, table.height_m - r - 0.01), radius_m=r, vel_mps=(0.3, 3.0))

    table.step(dt)

    np.testing.assert_allclose(into.vel_mps, (1.0, 0.0), rtol=1e-12)
    # It reaches the wall halfway through the step (0.01 m at 2 m/s) and leaves at 1 m/s for the
    # other 0.005 s: e times the penetration out (the course's mirror, exact at e = 1).
    assert into.pos_m[0] == pytest.approx(r + 0.005, rel=1e-12)
    np.testing.assert_allclose(away.vel_mps, (0.0, 1.0), rtol=1e-12)
    assert away.pos_m[1] >= r
    np.testing.assert_allclose(top.vel_mps, (0.3, -1.5), rtol=1e-12)  # tangential part kept
    assert_inside_walls(table)


@pytest.mark.parametrize("correction", [True, False])
def test_pile_under_gravity_stays_inside_the_walls(correction: bool) -> None:
    # Pairs pushed apart against a floor and corner push pucks into walls; the
    # last wall pass must still leave every puck inside after every step.
    table = AirTable(width_m=2.0, height_m=3.0)
    table.gravity_on = True
    table.cr_wall = table.cr_puck = 0.3
    table.wall_correction = correction
    rng = np.random.default_rng(3)
    for k in range(60):
        table.add_puck(pos_m=(rng.uniform(0.2, 1.8), 0.2 + 0.04 * k), radius_m=rng.uniform(0.08, 0.15))
    for _ in range(400):
        table.step(1 / 60)
        assert_inside_walls(table)


# ---------------------------------------------------------------- a gas


@pytest.mark.parametrize(("mode", "tight"), [("two-step", True), ("perfect-kiss", True), ("off", False)])
def test_gas_conserves_energy_and_keeps_pucks_apart(mode: str, tight: bool) -> None:
    # r = 0.1 m at 1 m/s and dt = 1/120 s: two pucks close in by up to
    # 17 mm (17 % of a radius) per step, deep enough that without a position
    # correction they visibly sink into each other.
    table = gas_scene(300, seed=1)
    table.puck_correction = mode
    r = 0.1
    ke0 = table.kinetic_energy_J()
    deepest = []
    for k in range(1, 2001):
        table.step(1 / 120)
        assert_inside_walls(table)
        if k % 10 == 0:
            i, j = broadphase.brute_force_pairs(table.pos_m, table.radius_m)
            d = np.hypot(*(table.pos_m[i] - table.pos_m[j]).T)
            deepest.append(float(np.max(2 * r - d)) / r if len(i) else 0.0)
    assert table.collision_count > 5000
    assert abs(table.kinetic_energy_J() - ke0) / ke0 < 1e-9
    deepest = np.array(deepest)
    ok = deepest.mean() < 0.02 and np.mean(deepest > 0.10) < 0.05
    assert ok == tight, f"{mode}: mean deepest overlap {deepest.mean():.1%} of r, >10% in {np.mean(deepest > 0.1):.0%}"


# ---------------------------------------------------------------- broadphase


@st.composite
def puck_sets(draw, most: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """Positions and radii: mixed radii, maybe one giant, sparse to piled up, on a lattice or on the walls;
    up to `most` pucks."""
    n = draw(
        st.one_of(
            st.integers(0, broadphase.BRUTE_FORCE_MAX_PUCKS),
            st.integers(broadphase.BRUTE_FORCE_MAX_PUCKS + 1, most),
        )
    )
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    r_small = draw(st.floats(0.01, 0.3))
    radius = np.full(n, r_small) if draw(st.booleans()) else rng.uniform(0.2, 1.0, n) * r_small
    giant = n > 0 and draw(st.booleans())
    if giant:
        radius[rng.integers(n)] = 10 * r_small
    # From a sparse gas to crowded (more than 100 % "covered" means piles).
    area = max(n, 1) * math.pi * r_small**2 / draw(st.floats(0.05, 2.0))
    aspect = draw(st.floats(0.1, 10.0))
    w, h = math.sqrt(area * aspect), math.sqrt(area / aspect)
    pos = rng.uniform(0.0, 1.0, (n, 2)) * (w, h)
    layout = draw(st.sampled_from(["random", "lattice", "walls"]))
    if layout == "lattice" and n:
        # Multiples of the grid's cell (the largest ordinary diameter): exact
        # touches, and spans a whole number of cells, where rounding bites.
        cell = 2.0 * float(np.max(radius[radius <= 2.0 * radius.mean()]))
        pos = np.round(pos / cell) * cell
    elif layout == "walls":
        on_wall = rng.random(n) < 0.3
        axis = rng.integers(0, 2, n)
        far = rng.random(n) < 0.5
        size = np.array([w, h])
        for k in np.flatnonzero(on_wall):
            pos[k, axis[k]] = size[axis[k]] - radius[k] if far[k] else radius[k]
    return pos, radius


@settings(max_examples=300, deadline=None, derandomize=True)
@given(puck_sets())
def test_broadphase_finds_exactly_the_brute_force_pairs(pucks: tuple[np.ndarray, np.ndarray]) -> None:
    pos, radius = pucks
    i, j = broadphase.find_overlapping_pairs(pos, radius)
    bi, bj = broadphase.brute_force_pairs(pos, radius)
    assert np.array_equal(i, bi) and np.array_equal(j, bj)


def test_broadphase_grid_span_an_exact_multiple_of_the_cell() -> None:
    # 0.6 / 0.2 rounds to 2.9999999999999996 but 0.6 * (1 / 0.2) to 3.0: the
    # grid must have room for the cell the last puck really falls in.
    rng = np.random.default_rng(1)
    n = 60
    pos = np.column_stack([rng.uniform(0.0, 0.6, n), rng.uniform(0.0, 5.0, n)])
    pos[0, 0], pos[1, 0] = 0.0, 0.6
    radius = np.full(n, 0.1)
    i, j = broadphase.find_overlapping_pairs(pos, radius)
    bi, bj = broadphase.brute_force_pairs(pos, radius)
    assert np.array_equal(i, bi) and np.array_equal(j, bj)


@pytest.mark.parametrize("along", [0, 1])
def test_pucks_along_a_long_line_keep_the_grid_small(along: int, monkeypatch) -> None:
    # 60 pucks spread along a 1000 km line cover no area: the grid may not
    # grow with the line's length (cells of 0.2 m would be 5 million columns).
    cells = []
    argsort_cells = broadphase._argsort_cells
    monkeypatch.setattr(broadphase, "_argsort_cells", lambda key, n: cells.append(n) or argsort_cells(key, n))
    rng = np.random.default_rng(4)
    pos = np.zeros((60, 2))
    pos[:, along] = np.sort(rng.uniform(0.0, 1e6, 60))
    pos[1, along] = pos[0, along] + 0.15  # one overlapping pair
    radius = np.full(60, 0.1)
    i, j = broadphase.find_overlapping_pairs(pos, radius)
    assert list(zip(i.tolist(), j.tolist(), strict=True)) == [(0, 1)]
    assert cells and max(cells) <= 4 * 60 * broadphase.ROWS_PER_CELL * 3


@pytest.mark.parametrize("r", np.linspace(0.01, 0.3, 59))
def test_broadphase_lattice_of_touching_pucks(r: float) -> None:
    # Neighbours exactly one diameter (= one grid cell) apart: rounding makes
    # some of them overlap by 1e-17 m, and the grid must still find those.
    k = np.arange(12) * (2.0 * r)
    pos = np.stack(np.meshgrid(k, k), axis=-1).reshape(-1, 2)
    radius = np.full(len(pos), r)
    i, j = broadphase.find_overlapping_pairs(pos, radius)
    bi, bj = broadphase.brute_force_pairs(pos, radius)
    assert np.array_equal(i, bi) and np.array_equal(j, bj)


@pytest.mark.parametrize("r", np.linspace(0.01, 0.3, 30))
def test_grid_finds_pairs_exactly_one_reach_apart_across_cell_edges(r: float) -> None:
    # Columns are one reach (2 r + skin) wide and cells a quarter of that tall.
    # Lattices in steps of a fifth and a quarter of the reach put pucks on the
    # cell edges and pairs exactly one reach apart: side by side, one above the
    # other, and across corners (3, 4, 5). After rounding some are a hair
    # closer: the grid must find those, and nothing else.
    skin = broadphase.SKIN_RADII * r
    reach = 2.0 * r + skin
    fifths = np.stack(np.meshgrid(np.arange(11), np.arange(11)), axis=-1).reshape(-1, 2) * (0.2 * reach)
    quarters = np.stack(np.meshgrid(np.arange(9), np.arange(9)), axis=-1).reshape(-1, 2) * (0.25 * reach)
    pos = np.concatenate([fifths, quarters + 0.1 * reach])
    radius = np.full(len(pos), r)
    i, j = broadphase.find_candidate_pairs(pos, radius, margin_m=skin, closer=True)
    bi, bj = np.triu_indices(len(pos), k=1)
    near = broadphase._closer_than(pos, bi, bj, reach)
    assert np.all(i < j)
    assert sorted(zip(i.tolist(), j.tolist(), strict=True)) == list(zip(bi[near].tolist(), bj[near].tolist()))


def test_expand_ranges_pairs_each_row_with_its_ranges_in_order() -> None:
    first = np.array([[1, 2, 5], [3, 9, 7]])
    stop = np.array([[3, 2, 6], [3, 11, 9]])  # two empty ranges: [2, 2) and [3, 3)
    a, b = broadphase._expand_ranges(first, stop)
    assert a.dtype == b.dtype == np.intp
    assert list(zip(a.tolist(), b.tolist(), strict=True)) == [(0, 1), (0, 2), (2, 5), (1, 9), (1, 10), (2, 7), (2, 8)]


def pairs_closer_than(pos: np.ndarray, radius: np.ndarray, margin_m: float) -> set[tuple[int, int]]:
    """Every pair (i < j) closer than its reach plus margin_m: all n^2 distances, no grid."""
    d = np.hypot(*(pos[:, None, :] - pos[None, :, :]).transpose(2, 0, 1))
    a, b = np.nonzero(np.triu(d < radius[:, None] + radius[None, :] + margin_m, k=1))
    return set(zip(a.tolist(), b.tolist(), strict=True))


@settings(max_examples=100, deadline=None, derandomize=True)
@given(puck_sets(), st.floats(0.0, 1.0))
def test_broadphase_with_a_margin_finds_every_pair_within_it(pucks: tuple[np.ndarray, np.ndarray], margin: float):
    pos, radius = pucks
    i, j = broadphase.find_candidate_pairs(pos, radius, margin_m=margin)
    assert np.all(i < j) and len(set(zip(i.tolist(), j.tolist(), strict=True))) == len(i)  # each pair once
    assert pairs_closer_than(pos, radius, margin) <= set(zip(i.tolist(), j.tolist(), strict=True))


@settings(max_examples=60, deadline=None, derandomize=True)
@given(puck_sets(), st.floats(0.0, 1.0))
def test_closer_candidates_are_the_candidates_closer_than_the_largest_reach(pucks, margin: float):
    # The grid checks distances in its own sorted order; the pairs and their order are those of checking after.
    pos, radius = pucks
    i, j = broadphase.find_candidate_pairs(pos, radius, margin_m=margin)
    near = broadphase._closer_than(pos, i, j, 2.0 * float(radius.max(initial=0.0)) + margin)
    ci, cj = broadphase.find_candidate_pairs(pos, radius, margin_m=margin, closer=True)
    assert np.array_equal(ci, i.take(near)) and np.array_equal(cj, j.take(near))


@settings(max_examples=150, deadline=None, derandomize=True)
@given(puck_sets(most=1200), st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.integers(0, 2**32 - 1))
def test_pairs_near_some_rows_are_exactly_those_of_looking_at_every_pair(pucks, margin: float, share: float, seed):
    # The fast pucks' partners (events.py): a few rows look at every puck; more (over
    # NEAR_BRUTE_FORCE_LOOKS rows times pucks: a tenth of 1000 pucks) search the grid around them.
    pos, radius = pucks
    n = len(pos)
    rows = np.random.default_rng(seed).choice(n, size=int(share * n), replace=False)
    i, j = broadphase.pairs_near(pos, radius, rows, margin)
    a, b = np.triu_indices(n, k=1)
    d = pos[a] - pos[b]
    reach = radius[a] + radius[b] + margin
    keep = (np.isin(a, rows) | np.isin(b, rows)) & (d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] < reach * reach)
    assert np.array_equal(i, a[keep]) and np.array_equal(j, b[keep])  # each once, in (i, j) order


def test_neighbour_list_finds_every_overlap_as_pucks_drift_jump_and_grow() -> None:
    rng = np.random.default_rng(7)
    n, r = 400, 0.1
    pos = rng.uniform(0.0, 6.0, (n, 2))
    radius = np.full(n, r)
    neighbours = broadphase.NeighbourList()
    skin = broadphase.SKIN_RADII * r

    def check() -> None:
        i, j = broadphase.overlapping_pairs(pos, *neighbours.pairs(pos, radius))
        bi, bj = broadphase.brute_force_pairs(pos, radius)
        assert np.array_equal(i, bi) and np.array_equal(j, bj)

    check()
    for _ in range(60):  # drift: each step a tenth of the skin at most, so the list is reused
        pos += rng.uniform(-1.0, 1.0, (n, 2)) * (0.1 * skin / math.sqrt(2.0))
        check()
    # A puck needs at least five steps to move half the skin: one build, then at most one per five steps.
    assert neighbours.builds <= 1 + 60 // 5
    builds = neighbours.builds
    pos[5] = pos[17]  # one puck jumps onto another (a teacher's drag, a demo's reset)
    check()
    assert neighbours.builds == builds + 1
    radius[40] = 2.0  # a radius changed by hand
    check()
    assert neighbours.builds == builds + 2


def test_a_puck_added_onto_another_collides_at_once() -> None:
    table = AirTable()
    for k in range(60):  # enough pucks for the grid, all at rest and apart
        table.add_puck(pos_m=(0.5 + 0.6 * (k % 15), 0.5 + 0.6 * (k // 15)), radius_m=0.2)
    table.step(1 / 120)
    table.step(1 / 120)
    hit = table.add_puck(pos_m=(0.5, 0.8), radius_m=0.2, vel_mps=(0.0, -1.0))  # 0.1 m into puck 0
    table.step(1 / 120)
    hit_pairs = set(zip(table.last_collisions.i.tolist(), table.last_collisions.j.tolist(), strict=True))
    assert (0, hit.index) in hit_pairs


@st.composite
def pair_lists(draw) -> tuple[np.ndarray, np.ndarray, int]:
    n = draw(st.integers(2, 12))
    pairs = draw(st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)).filter(lambda p: p[0] != p[1])))
    i = np.array([p[0] for p in pairs], dtype=np.intp)
    j = np.array([p[1] for p in pairs], dtype=np.intp)
    return i, j, n


@settings(max_examples=300, deadline=None, derandomize=True)
@given(pair_lists())
def test_disjoint_rounds_keep_order_and_never_repeat_a_puck(pair_list: tuple[np.ndarray, np.ndarray, int]) -> None:
    i, j, n = pair_list
    rounds = pairs.disjoint_rounds(i, j)
    round_of = np.full(len(i), -1)
    for number, members in enumerate(rounds):
        pucks = np.concatenate([i[members], j[members]])
        assert len(np.unique(pucks)) == len(pucks), "a puck appears twice in one round"
        assert np.all(round_of[members] == -1), "a pair appears in two rounds"
        round_of[members] = number
    assert np.all(round_of >= 0), "a pair is missing"
    for k in range(len(i)):
        for later in range(k + 1, len(i)):
            if {i[k], j[k]} & {i[later], j[later]}:
                assert round_of[k] < round_of[later], "pairs sharing a puck were reordered"


@pytest.mark.parametrize("n_cells", [10, 1 << 16, (1 << 16) + 1, 5_000_000])
def test_cell_sort_matches_a_stable_argsort(n_cells: int) -> None:
    keys = np.random.default_rng(n_cells).integers(0, n_cells, 5000)
    np.testing.assert_array_equal(broadphase._argsort_cells(keys, n_cells), np.argsort(keys, kind="stable"))


def test_overlapping_pairs_picked_in_the_kept_order_are_the_sorted_ones() -> None:
    # A packed box (a pile): most of the neighbour list's pairs overlap, so
    # overlapping_pairs picks them in the list's kept (i, j) order instead of
    # sorting them; the answer must be the same pairs in the same order.
    rng = np.random.default_rng(3)
    side = 20
    grid = np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2) * 0.199 + 0.1
    pos = grid + rng.uniform(-1e-3, 1e-3, grid.shape)
    radius = np.full(len(pos), 0.1)
    neighbours = broadphase.NeighbourList()
    i, j, reach = neighbours.pairs(pos, radius)
    picked = broadphase.overlapping_pairs(pos, i, j, reach, neighbours.sorted_order)
    sorted_ = broadphase.overlapping_pairs(pos, i, j, reach)
    assert len(picked[0]) * broadphase.SORTED_PICK_SHARE >= len(i)  # the kept order was used
    assert not np.array_equal(neighbours.sorted_order(), np.arange(len(i)))  # and the list is not in it already
    assert np.array_equal(picked[0], sorted_[0]) and np.array_equal(picked[1], sorted_[1])
    bi, bj = broadphase.brute_force_pairs(pos, radius)
    assert np.array_equal(picked[0], bi) and np.array_equal(picked[1], bj)
