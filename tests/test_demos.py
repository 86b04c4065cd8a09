"""The built-in demos: discovered from their files, buildable, stable, and doing what their notes say.

Headless and deterministic: every check counts steps of simulated time, never the clock.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from airtable.demos import _correction_comparison as correction_scene

from airtable import AirTable
from airtable.app.demo_loader import BUILTIN_DIR, discover

DEMOS, ERRORS = discover([BUILTIN_DIR])
ORANGE = (255, 165, 0)


def fresh(key: str, variation: int = 0) -> AirTable:
    """A table built the way the app builds a demo."""
    table = AirTable()
    table.clear()
    table.reset_settings()
    DEMOS[key].build(table, variation)
    return table


def run(table: AirTable, key: str, steps: int) -> None:
    for _ in range(steps):
        table.step(DEMOS[key].dt_s)


def run_until(table: AirTable, key: str, t_s: float) -> None:
    """Step until simulated time `t_s` (bounded: it fails rather than hangs if time stops)."""
    dt_s = DEMOS[key].dt_s
    for _ in range(int((t_s - table.time_s) / dt_s) + 2):
        if table.time_s >= t_s - 1e-9:
            return
        table.step(dt_s)
    assert table.time_s >= t_s - 1e-9, f"time stopped at {table.time_s} s before {t_s} s"


def orange_puck(table: AirTable):
    (cue,) = [p for p in table.pucks if p.color == ORANGE]
    return cue


def assert_sane(table: AirTable) -> None:
    """Everything finite and every puck inside the walls."""
    pos, vel, r = table.pos_m, table.vel_mps, table.radius_m
    assert np.isfinite(pos).all() and np.isfinite(vel).all()
    eps = 1e-9
    assert (pos[:, 0] >= r - eps).all() and (pos[:, 0] <= table.width_m - r + eps).all()
    assert (pos[:, 1] >= r - eps).all() and (pos[:, 1] <= table.height_m - r + eps).all()


def spring_lengths(table: AirTable) -> np.ndarray:
    pairs = table.spring_pairs
    d = table.pos_m[pairs[:, 0]] - table.pos_m[pairs[:, 1]]
    return np.hypot(d[:, 0], d[:, 1])


def mechanical_energy(table: AirTable) -> float:
    return table.kinetic_energy_J() + table.spring_energy_J() + table.gravity_energy_J()


# ---------------------------------------------------------------- discovery


def test_the_keys_are_exactly_the_builtin_set_and_all_load():
    assert ERRORS == []
    assert list(DEMOS) == ["1", "2", "3", "4", "5", "6", "7", "8", "9", "0", "0p", "1p", "2p", "3p", "6p", "t"]


@pytest.mark.parametrize("key", list(DEMOS))
def test_every_demo_has_a_title_and_notes_of_two_to_four_sentences(key):
    demo = DEMOS[key]
    assert demo.title.strip()
    sentences = re.split(r"(?<=[.!?])\s+", demo.notes.strip())
    assert 2 <= len(sentences) <= 4, sentences
    assert all(s[-1] in ".!?" for s in sentences)


# ---------------------------------------------------------------- every demo runs


CASES = [(key, v) for key, demo in DEMOS.items() for v in range(max(1, len(demo.variations)))]


@pytest.mark.parametrize(("key", "variation"), CASES, ids=[f"{k}-{v}" for k, v in CASES])
def test_every_demo_and_variation_builds_and_runs_finite_and_inside(key, variation):
    table = fresh(key, variation)
    assert table.pucks
    assert_sane(table)
    # The biggest bursts step fewer times: they only check the build and the first moves.
    run(table, key, 50 if len(table.pucks) >= 5000 else 500)
    assert_sane(table)


def test_demo_4_with_gravity_stays_finite_and_inside():
    table = fresh("4")
    table.gravity_on = True
    energy = mechanical_energy(table)
    run(table, "4", 2000)
    assert_sane(table)
    # Restitution 1 everywhere: the pile keeps bouncing, but no energy may appear from nowhere.
    assert mechanical_energy(table) == pytest.approx(energy, rel=0.02)


def test_burst_pucks_bounce_off_the_walls_keeping_their_energy():
    table = fresh("0", DEMOS["0"].variations.index("n = 1000"))
    assert table.puck_collisions is False  # they start on top of each other
    speeds = np.hypot(*table.vel_mps.T)
    assert speeds == pytest.approx(np.full(1000, 1.4))
    assert table.momentum_Ns() == pytest.approx([0.0, 0.0], abs=1e-12)  # evenly spaced angles
    energy = table.kinetic_energy_J()
    run_until(table, "0", 8.0)  # long enough for every puck to reach a wall
    assert_sane(table)
    assert table.kinetic_energy_J() == pytest.approx(energy, rel=1e-12)


@pytest.mark.parametrize("variation", range(len(DEMOS["0p"].variations)))
def test_gas_has_the_number_of_pucks_its_label_says_covering_30_percent(variation):
    table = fresh("0p", variation)
    n = int(DEMOS["0p"].variations[variation].split()[0])
    assert len(table.pucks) == n
    covered = np.pi * (table.radius_m**2).sum() / (table.width_m * table.height_m)
    assert covered == pytest.approx(0.3, rel=1e-3)
    assert [p.color for p in table.pucks].count(ORANGE) == 1


def test_gas_speeds_spread_from_one_speed_into_the_2d_maxwell_distribution():
    # In two dimensions the equilibrium speeds follow f(v) = (v / s^2) exp(-v^2 / 2 s^2), with
    # s^2 = kT / m and the mean kinetic energy m v0^2 / 2 = kT (two degrees of freedom), so
    # s = v0 / sqrt(2): P(v < v0) = 1 - 1/e, P(v < v0 / 2) = 1 - e^(-1/4), mean speed v0 sqrt(pi) / 2.
    table = fresh("0p", DEMOS["0p"].variations.index("500 pucks"))
    speeds = np.hypot(*table.vel_mps.T)
    assert speeds == pytest.approx(np.ones(500))  # all start at v0 = 1 m/s
    energy = table.kinetic_energy_J()
    run_until(table, "0p", 8.0)  # some ten collisions per puck
    assert_sane(table)
    speeds = np.hypot(*table.vel_mps.T)
    # 500 samples: a binomial fraction's standard deviation is about 0.022; allow three of them.
    assert (speeds < 1.0).mean() == pytest.approx(1.0 - np.exp(-1.0), abs=0.065)
    assert (speeds < 0.5).mean() == pytest.approx(1.0 - np.exp(-0.25), abs=0.055)
    assert speeds.mean() == pytest.approx(np.sqrt(np.pi) / 2.0, abs=0.06)
    assert table.kinetic_energy_J() == pytest.approx(energy, rel=1e-9)  # elastic: only shared out


# ---------------------------------------------------------------- springs keep their shape


def test_demo_5_spring_pair_oscillates_and_stays_together():
    table = fresh("5")
    (spring,) = table.springs
    energy = mechanical_energy(table)
    run(table, "5", 500)
    (d,) = spring_lengths(table)
    assert 0.5 < d < 3.0
    assert spring.length_m == 1.5
    assert mechanical_energy(table) <= energy  # the damper only takes energy out


def test_demo_6_triangle_keeps_its_shape():
    table = fresh("6")
    assert table.cr_puck == 0.7
    assert len(table.springs) == 3
    np.testing.assert_allclose(spring_lengths(table), 2.5, rtol=1e-12)  # at rest: nothing stored to jolt it
    assert table.spring_energy_J() < 1e-20
    energy = mechanical_energy(table)
    run(table, "6", 500)
    assert np.all(np.abs(spring_lengths(table) - 2.5) < 0.2 * 2.5)
    assert mechanical_energy(table) <= energy


# ---------------------------------------------------------------- timed throws


def test_demo_7_cue_waits_one_second_then_the_cradle_passes_it_on():
    table = fresh("7")
    cue = orange_puck(table)
    run_until(table, "7", 1.0)
    assert np.all(table.vel_mps == 0.0)  # nothing moves before the throw
    run(table, "7", 1)
    assert np.hypot(*cue.vel_mps) == pytest.approx(4.0)
    diagonal = np.array([table.width_m, table.height_m]) / math.hypot(table.width_m, table.height_m)
    assert cue.vel_mps / 4.0 == pytest.approx(diagonal)
    run_until(table, "7", 2.5)  # after the hits, before the last puck reaches the corner
    first, middle, last = (np.hypot(*p.vel_mps) for p in table.pucks)
    assert first < 1e-6 and middle < 1e-6
    assert last == pytest.approx(4.0)


@pytest.mark.parametrize("variation", range(len(DEMOS["8"].variations)))
def test_demo_8_cue_starts_off_the_line_by_its_label(variation):
    table = fresh("8", variation)
    cue = orange_puck(table)
    line_y = table.height_m / 2.0
    pct = int(re.search(r"(\d+) %", DEMOS["8"].variations[variation]).group(1))
    assert pct == (0, 10, 20, 40, 50)[variation]
    assert cue.pos_m[1] - line_y == pytest.approx(pct / 100.0 * cue.radius_m, abs=1e-12)
    row = [p for p in table.pucks if p is not cue]
    assert len(row) == 20 and all(p.pos_m[1] == line_y and p.radius_m == 0.1 for p in row)
    run_until(table, "8", 1.0)
    assert np.all(cue.vel_mps == 0.0)
    run(table, "8", 1)
    assert cue.vel_mps[0] > 0.0 and cue.vel_mps[1] == 0.0


def test_demo_9_cut_shot_sends_the_top_puck_down_and_the_cue_off_at_90_degrees():
    table = fresh("9")
    cue = orange_puck(table)
    top = max(table.pucks[:-1], key=lambda p: p.pos_m[1])
    run_until(table, "9", 1.0)
    assert np.all(table.vel_mps == 0.0)
    for _ in range(int(2.0 / DEMOS["9"].dt_s)):  # the hit comes well within 2 s of the throw
        table.step(DEMOS["9"].dt_s)
        if len(table.last_collisions):
            break
    assert len(table.last_collisions), "the cue never hit the ring"
    (i, j) = (int(table.last_collisions.i[0]), int(table.last_collisions.j[0]))
    assert {i, j} == {top.index, cue.index}
    down = math.degrees(math.atan2(-top.vel_mps[0], -top.vel_mps[1]))  # 0 = straight down
    assert abs(down) < 3.0
    assert np.dot(top.vel_mps, cue.vel_mps) == pytest.approx(0.0, abs=1e-9)  # the 90-degree rule


# ---------------------------------------------------------------- 1p, 2p, 3p: the three corrections


def first_hit(key: str):
    """Run the correction scene to the step that finds the hit; return (table, target, cue)."""
    table = fresh(key)
    cue = orange_puck(table)
    (target,) = [p for p in table.pucks if p is not cue]
    for _ in range(200):
        table.step(DEMOS[key].dt_s)
        if len(table.last_collisions):
            return table, target, cue
    raise AssertionError("the cue never hit the target")


def outgoing_angle_deg(puck) -> float:
    """Angle of the puck's velocity below the cue's line (+x), in degrees."""
    vx, vy = puck.vel_mps
    return -math.degrees(math.atan2(vy, vx))


@pytest.mark.parametrize("key", ["1p", "2p", "3p"])
def test_correction_demos_use_a_coarse_step_with_trails(key):
    demo = DEMOS[key]
    assert demo.dt_s == pytest.approx(1 / 20)
    assert demo.trails is True
    table = fresh(key)
    assert table.puck_correction == {"1p": "off", "2p": "two-step", "3p": "perfect-kiss"}[key]


def test_correction_demos_show_three_outcomes():
    hits = {key: first_hit(key) for key in ("1p", "2p", "3p")}
    angles = {key: outgoing_angle_deg(target) for key, (_, target, _) in hits.items()}
    ideal = math.degrees(math.asin(correction_scene.IMPACT_PARAMETER_M / (2.0 * correction_scene.RADIUS_M)))
    assert ideal == pytest.approx(14.4775, abs=1e-4)

    # Perfect kiss: the normal at first contact, so the ideal angle.
    assert angles["3p"] == pytest.approx(ideal, abs=0.1)
    # Off and two-step both take the normal from the overlapping pucks: far steeper.
    assert angles["1p"] > ideal + 10.0
    assert angles["2p"] > ideal + 10.0
    assert round(angles["1p"]) == 29  # the angle the notes of 1p and 2p quote
    # They share that direction; what differs is where the pucks are left:
    # overlapping with no correction, apart by the same distance with two-step.
    assert angles["1p"] == pytest.approx(angles["2p"], abs=1e-9)
    off, two_step = hits["1p"][0].last_collisions, hits["2p"][0].last_collisions
    assert off.overlap_m[0] > correction_scene.RADIUS_M * 0.5  # a visible overlap
    assert off.separation_m[0] == pytest.approx(-off.overlap_m[0])
    assert two_step.separation_m[0] / two_step.overlap_m[0] == pytest.approx(1.0, abs=1e-4)

    for table, target, cue in hits.values():
        assert np.dot(target.vel_mps, cue.vel_mps) == pytest.approx(0.0, abs=1e-9)  # the 90-degree rule
        assert table.momentum_Ns() == pytest.approx([cue.mass_kg * correction_scene.SPEED_MPS, 0.0])


def test_correction_demos_hit_in_view_and_the_trails_differ():
    """The three target paths after the hit are visibly apart on the table."""
    paths = {}
    for key in ("1p", "2p", "3p"):
        table, target, _ = first_hit(key)
        run(table, key, 3)
        paths[key] = target.pos_m
        assert_sane(table)
    assert np.linalg.norm(paths["1p"] - paths["2p"]) > 0.2
    assert np.linalg.norm(paths["2p"] - paths["3p"]) > 0.2


@pytest.mark.parametrize("default, ok", [("1", True), ("2", False), ("-1", False), ("'1'", False)])
def test_a_default_variation_must_count_one_of_the_variations(tmp_path, default, ok) -> None:
    from airtable.app.demo_loader import discover

    (tmp_path / "demo_t9.py").write_text(
        f"KEY = 't9'\nTITLE = 'x'\nVARIATIONS = ('a', 'b')\nDEFAULT_VARIATION = {default}\n\n"
        "def build(table, variation=0):\n    table.add_puck((1, 1), 0.1 + variation)\n"
    )
    found, errors = discover([tmp_path])
    if ok:
        assert not errors and found["t9"].default_variation == 1
    else:
        assert [str(e) for e in errors] == [
            f"demo_t9.py: DEFAULT_VARIATION must count one of VARIATIONS from 0, not {default}"
        ]
