"""The benchmark's gas scene (no timing assertions: this machine is noisy)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from airtable.demos.demo_0p_gas import gas_scene

from airtable import AirTable
from airtable.physics import broadphase
from bench.main import main


def test_gas_scene_covers_30_percent_without_overlaps() -> None:
    table = gas_scene(100)
    assert len(table.pucks) == 100
    coverage = np.sum(math.pi * table.radius_m**2) / (table.width_m * table.height_m)
    assert coverage == pytest.approx(0.30, rel=1e-9)
    assert table.width_m / table.height_m == pytest.approx(8 / 7)
    i, _ = broadphase.brute_force_pairs(table.pos_m, table.radius_m)
    assert len(i) == 0, "pucks start overlapping"
    r = table.radius_m[:, None]
    assert np.all(table.pos_m > r) and np.all(table.pos_m < table.size_m - r)
    np.testing.assert_allclose(np.hypot(*table.vel_mps.T), 1.0)
    assert np.linalg.norm(table.vel_mps.mean(axis=0)) < 0.3  # random directions
    assert (table.cr_puck, table.cr_wall, table.gravity_on, table.puck_correction) == (1.0, 1.0, False, "two-step")


def test_gas_scene_is_seeded() -> None:
    a, b, c = gas_scene(100, seed=3), gas_scene(100, seed=3), gas_scene(100, seed=4)
    assert np.array_equal(a.pos_m, b.pos_m) and np.array_equal(a.vel_mps, b.vel_mps)
    assert not np.array_equal(a.pos_m, c.pos_m)


def test_gas_scene_fills_a_given_table() -> None:
    table = AirTable(width_m=4.0, height_m=3.5)
    table.add_puck()
    assert gas_scene(table) is table
    assert len(table.pucks) == round(0.3 * 4.0 * 3.5 / (math.pi * 0.1**2))
    i, _ = broadphase.brute_force_pairs(table.pos_m, table.radius_m)
    assert len(i) == 0


def test_bench_quick_run_prints_a_table(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--quick", "--no-pymunk", "--only", "physics"]) == 0
    out = capsys.readouterr().out
    assert "ours ms" in out and "1000" in out


def test_bench_help(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["--help"])
    assert exit_info.value.code == 0
    assert "--quick" in capsys.readouterr().out


def test_the_hard_cases_time_the_engines_in_turns() -> None:
    from bench import hard as bench_hard

    calls = []

    class Fake:
        def __init__(self, name: str) -> None:
            self.name = name

        def step(self, dt_s: float) -> None:
            calls.append(self.name)

    ms = bench_hard.step_ms([Fake("ours"), Fake("pymunk")], blocks=3, steps=2)
    assert len(ms) == 2 and all(m >= 0.0 for m in ms)
    assert calls == ["ours", "ours", "pymunk", "pymunk"] * 3  # block by block, in turns
