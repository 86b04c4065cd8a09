"""Record and export: the recording's CSV pair, its memory bound, the export key and --record."""

from __future__ import annotations

import csv
from collections import defaultdict

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, press

from airtable.app.app import App
from airtable.app.recorder import ENERGY_COLUMNS, PUCK_COLUMNS, SAMPLE_OVERHEAD_BYTES, Recorder, csv_pair
from airtable.cli import main
from airtable.physics.table import AirTable


def read_csv(path) -> tuple[list[str], list[list[float]]]:
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    return rows[0], [[float(v) for v in row] for row in rows[1:]]


def check_pair_agrees(puck_path, energy_path, dt_s: float, n_pucks: int) -> list[list[float]]:
    """The energy file's kinetic energy and momentum, recomputed from the puck file, to round-off."""
    head, pucks = read_csv(puck_path)
    assert tuple(head) == PUCK_COLUMNS
    head, energy = read_csv(energy_path)
    assert tuple(head) == ENERGY_COLUMNS
    assert len(pucks) == n_pucks * len(energy)
    by_time = defaultdict(list)
    for t, _puck, m, _r, _x, _y, vx, vy in pucks:
        by_time[t].append((m, vx, vy))
    times = [row[0] for row in energy]
    assert np.allclose(np.diff(times), dt_s, rtol=0, atol=1e-12)  # one sample every step
    for t, ke, se, ge, total, px, py in energy:
        rows = np.array(by_time[t])
        m, vx, vy = rows[:, 0], rows[:, 1], rows[:, 2]
        assert 0.5 * np.sum(m * (vx * vx + vy * vy)) == pytest.approx(ke, rel=1e-12, abs=1e-15)
        assert np.sum(m * vx) == pytest.approx(px, rel=1e-12, abs=1e-15)
        assert np.sum(m * vy) == pytest.approx(py, rel=1e-12, abs=1e-15)
        assert total == pytest.approx(ke + se + ge, rel=1e-15)
    return energy


def test_the_pair_round_trips_and_kinetic_energy_and_momentum_match(demos, tmp_path):
    app = App(demos, demo_key="5", headless=True)  # a spring pair thrown: kinetic and spring energy
    app.run(seconds=1.0, frame_dt_s=FRAME_S)
    puck_path, energy_path = app.lessons.recorder.write(tmp_path / "pair")  # ".csv" added
    assert (puck_path.name, energy_path.name) == ("pair.csv", "pair_energy.csv")
    energy = check_pair_agrees(puck_path, energy_path, app.dt_s, len(app.table.pucks))
    assert len(energy) == 241  # t = 0 and 240 steps of 1/240 s
    assert energy[-1][0] == pytest.approx(1.0)
    assert max(row[1] for row in energy) > 0.1 and max(row[2] for row in energy) > 0.0
    # Every puck's last row is the table as it is now, bit for bit.
    _, pucks = read_csv(puck_path)
    last = np.array(pucks[-len(app.table.pucks) :])
    assert np.array_equal(last[:, 4:6], app.table.pos_m) and np.array_equal(last[:, 6:8], app.table.vel_mps)
    assert np.array_equal(last[:, 2], app.table.mass_kg)


def test_memory_is_bounded_by_bytes_and_the_newest_samples_stay():
    table = AirTable()
    for k in range(10):
        table.add_puck((1.0 + 0.8 * k, 4.0), radius_m=0.3, vel_mps=(0.1 * k, 0.2))
    per_sample = 10 * 6 * 8 + SAMPLE_OVERHEAD_BYTES  # 880 bytes
    rec = Recorder(budget_bytes=100 * per_sample)
    for _ in range(1000):
        table.step(0.01)
        rec.sample(table)
    assert len(rec) == 100 and rec.nbytes == 100 * per_sample and rec.dropped == 900
    assert rec.samples[-1].t_s == table.time_s
    assert rec.span_s == pytest.approx(0.99)
    assert "dropped" in rec.summary()
    # One sample bigger than the budget is still kept: the newest always stays.
    tiny = Recorder(budget_bytes=10)
    tiny.sample(table)
    tiny.sample(table)
    assert len(tiny) == 1


@pytest.mark.parametrize("n_pucks, samples", [(10, 6000), (1000, 120)])
def test_the_memory_really_used_stays_within_the_budget(n_pucks, samples):
    import tracemalloc

    table = AirTable()
    for k in range(n_pucks):
        table.add_puck((0.5 + (k % 90) * 0.1, 0.5 + (k // 90) * 0.5), radius_m=0.04, vel_mps=(0.1, 0.2))
    budget = 2 * 2**20
    rec = Recorder(budget_bytes=budget)
    tracemalloc.start()
    try:
        for _ in range(samples):  # well past the budget: 6000 x 880 B, 120 x 48.4 kB
            table.time_s += 0.01
            rec.sample(table)
        used, _ = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert rec.dropped > 0 and rec.nbytes <= budget
    assert used <= 1.05 * budget, f"{used} bytes for a budget of {budget}"


def test_csv_pair_names():
    assert [p.name for p in csv_pair("run")] == ["run.csv", "run_energy.csv"]
    assert [p.name for p in csv_pair("lab/run.CSV")] == ["run.CSV", "run_energy.CSV"]


def test_the_export_key_writes_the_pair_and_says_where(demos, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    app = App(demos, demo_key="1", headless=True)
    pygame.event.clear()
    for _ in range(30):
        app.frame(FRAME_S)
    press(app, pygame.K_x)
    written = sorted(p.name for p in (tmp_path / "recordings").iterdir())
    assert len(written) == 2 and written[0].endswith(".csv") and written[1].endswith("_energy.csv")
    assert str((tmp_path / "recordings" / written[0]).resolve()) in app.message
    assert written[1] in app.message and app.message in app.hud_lines()
    check_pair_agrees(*(tmp_path / "recordings" / n for n in written), app.dt_s, len(app.table.pucks))
    press(app, pygame.K_x)  # a second export in the same second never overwrites the first
    assert len(list((tmp_path / "recordings").iterdir())) == 4


def test_record_option_writes_the_pair_in_a_headless_run(tmp_path, capsys):
    path = tmp_path / "cradle.csv"
    assert main(["--headless", "--no-server", "--demo", "7", "--seconds", "3", "--record", str(path)]) == 0
    energy = check_pair_agrees(path, tmp_path / "cradle_energy.csv", 1 / 240, 3)
    assert len(energy) == 721
    assert "cradle_energy.csv" in capsys.readouterr().out


@pytest.mark.parametrize("bad", ["no/such/folder/run.csv", "."])
def test_record_option_with_a_bad_path_is_one_line_and_exit_1(bad, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["--headless", "--no-server", "--seconds", "0.1", "--record", bad]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("airtable: --record")
    assert not list(tmp_path.iterdir())
