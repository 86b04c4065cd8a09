"""Record and export: the recording streamed to its CSV pair, its bounded memory, rewinding it, the export key
and --record."""

from __future__ import annotations

import csv
import os
from collections import defaultdict

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, press
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable.app import recorder as recorder_module
from airtable.app.app import App
from airtable.app.recorder import ENERGY_COLUMNS, PUCK_COLUMNS, Recorder, csv_pair
from airtable.cli import main
from airtable.physics.table import AirTable


def app_after_frames(demos, key: str, frames: int, **options) -> App:
    """A headless App on demo `key` after `frames` frames of FRAME_S (its recording that long)."""
    app = App(demos, demo_key=key, headless=True, **options)
    pygame.event.clear()
    for _ in range(frames):
        app.frame(FRAME_S)
    return app


def read_csv(path) -> tuple[list[str], list[list[float]]]:
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    return rows[0], [[float(v) for v in row] for row in rows[1:]]


def check_pair_agrees(puck_path, energy_path, dt_s: float, n_pucks: int) -> list[list[float]]:
    """The energy file's kinetic energy and momentum, recomputed from the puck file, to round-off; times are
    k dt to the microsecond; pucks are numbered 1..n at each time."""
    head, pucks = read_csv(puck_path)
    assert tuple(head) == PUCK_COLUMNS
    head, energy = read_csv(energy_path)
    assert tuple(head) == ENERGY_COLUMNS
    assert len(pucks) == n_pucks * len(energy)
    by_time = defaultdict(list)
    for t, puck, m, _r, _x, _y, vx, vy in pucks:
        by_time[t].append((puck, m, vx, vy))
    times = [row[0] for row in energy]
    first = round(times[0] / dt_s)
    assert times == [round((first + k) * dt_s, 6) for k in range(len(times))]  # one sample every step
    for t, ke, se, ge, total, px, py in energy:
        rows = np.array(by_time[t])
        assert rows[:, 0].tolist() == list(range(1, n_pucks + 1))
        m, vx, vy = rows[:, 1], rows[:, 2], rows[:, 3]
        assert 0.5 * np.sum(m * (vx * vx + vy * vy)) == pytest.approx(ke, rel=1e-12, abs=1e-15)
        assert np.sum(m * vx) == pytest.approx(px, rel=1e-12, abs=1e-15)
        assert np.sum(m * vy) == pytest.approx(py, rel=1e-12, abs=1e-15)
        assert total == pytest.approx(ke + se + ge, rel=1e-15)
    return energy


def line_count(path) -> int:
    with open(path, "rb") as f:
        return sum(1 for _ in f)


def test_the_pair_round_trips_and_kinetic_energy_and_momentum_match(demos, tmp_path):
    app = App(demos, demo_key="5", headless=True)  # a spring pair thrown: kinetic and spring energy
    app.run(seconds=1.0, frame_dt_s=FRAME_S)
    rec = app.lessons.recorder
    rec.flush()
    energy = check_pair_agrees(rec.puck_path, rec.energy_path, app.dt_s, len(app.table.pucks))
    assert len(energy) == 241  # t = 0 and 240 steps of 1/240 s
    assert energy[-1][0] == 1.0
    assert max(row[1] for row in energy) > 0.1 and max(row[2] for row in energy) > 0.0
    # Every puck's last row is the table as it is now, bit for bit.
    _, pucks = read_csv(rec.puck_path)
    last = np.array(pucks[-len(app.table.pucks) :])
    assert np.array_equal(last[:, 4:6], app.table.pos_m) and np.array_equal(last[:, 6:8], app.table.vel_mps)
    assert np.array_equal(last[:, 2], app.table.mass_kg)
    with open(rec.energy_path, encoding="utf-8") as f:
        assert f.readlines()[1].startswith("0.000000,")  # times to the microsecond, not 13.279166666666233


def test_a_long_run_of_demo_4_writes_every_row_in_bounded_memory(demos, tmp_path):
    """20 000 steps of demo 4 (54 pucks, 83 s): every step on disk, fewer than 4096 rows ever in memory."""
    table = AirTable()
    demos["4"].build(table, 0)
    n, dt, steps, bound = len(table.pos_m), demos["4"].dt_s, 20_000, 4096
    rec = Recorder(tmp_path / "long.csv", buffer_rows=bound)
    rec.sample(table)
    most = rec.buffered_rows
    for _ in range(steps):
        table.step(dt)
        rec.sample(table)
        most = max(most, rec.buffered_rows)
    rec.close()
    assert most < bound  # rows waiting in memory, never more than the bound
    assert line_count(rec.energy_path) == 1 + steps + 1  # the header, t = 0 and every step
    assert line_count(rec.puck_path) == 1 + n * (steps + 1)
    assert (rec.samples, rec.rows) == (steps + 1, n * (steps + 1))
    with open(rec.energy_path, "rb") as f:
        f.seek(-200, os.SEEK_END)
        last = f.read().splitlines()[-1].split(b",")
    assert last[0] == f"{steps * dt:.6f}".encode()


def test_the_written_file_is_on_disk_while_the_run_goes(tmp_path):
    table = AirTable()
    table.add_puck((2.0, 2.0), radius_m=0.2, vel_mps=(1.0, 0.5))
    rec = Recorder(tmp_path / "live.csv", buffer_rows=100)
    for _ in range(1000):
        table.step(0.01)
        rec.sample(table)
    # Without close: all but the rows still buffered (fewer than 100) are in the file already.
    assert line_count(rec.energy_path) - 1 >= 1000 - 100 // 2


def fill(rec: Recorder, table: AirTable, steps: int, dt_s: float) -> list[float]:
    times = []
    for _ in range(steps):
        table.step(dt_s)
        rec.sample(table)
        times.append(table.time_s)
    return times


@settings(max_examples=25, deadline=None)
@given(
    steps=st.integers(1, 40),
    cut=st.integers(-1, 45),
    block=st.integers(8, 300),
    pucks=st.integers(0, 3),
    buffer_rows=st.integers(1, 50),
)
def test_drop_after_cuts_both_files_back_to_the_rewound_time(steps, cut, block, pucks, buffer_rows, tmp_path_factory):
    """Against an oracle that filters the rows by time: any cut, any block size of the backward read (rows
    split across blocks), any buffering; recording then goes on from the cut."""
    folder = tmp_path_factory.mktemp("cut")
    table = AirTable()
    for k in range(pucks):
        table.add_puck((1.0 + k, 2.0), radius_m=0.2, vel_mps=(0.3, 0.1 * k))
    rec = Recorder(folder / "r.csv", buffer_rows=buffer_rows)
    rec.sample(table)
    dt = 1 / 240
    times = [0.0, *fill(rec, table, steps, dt)]
    cut_s = cut * dt
    kept = [t for t in times if t <= cut_s + 1e-9]
    old = recorder_module.READ_BACK_BYTES
    recorder_module.READ_BACK_BYTES = block
    try:
        gone = rec.drop_after(cut_s)
    finally:
        recorder_module.READ_BACK_BYTES = old
    assert gone == len(times) - len(kept) and rec.samples == len(kept)
    more = fill(rec, table, 3, dt)  # the table runs on (here from where it was: only the files matter)
    rec.close()
    _, energy = read_csv(rec.energy_path)
    _, rows = read_csv(rec.puck_path)
    expected = [round(t, 6) for t in [*kept, *more]]
    assert [row[0] for row in energy] == expected
    assert [row[0] for row in rows] == [t for t in expected for _ in range(pucks)]
    assert rec.rows == pucks * len(expected)


def test_a_disk_that_refuses_stops_the_recording_and_says_why(tmp_path):
    for p in csv_pair(tmp_path / "full.csv"):
        p.symlink_to("/dev/full")  # every write: "No space left on device"
    table = AirTable()
    table.add_puck((2.0, 2.0), radius_m=0.2, vel_mps=(1.0, 0.5))
    rec = Recorder(tmp_path / "full.csv", buffer_rows=10)
    for _ in range(50):  # no exception: the app goes on
        table.step(0.01)
        rec.sample(table)
    assert rec.error == "No space left on device" and rec.closed
    rec.close()


def test_csv_pair_names():
    assert [p.name for p in csv_pair("run")] == ["run.csv", "run_energy.csv"]
    assert [p.name for p in csv_pair("lab/run.CSV")] == ["run.CSV", "run_energy.CSV"]


def test_the_export_key_gives_the_demo_so_far_and_later_the_later_part_too(demos, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    app = app_after_frames(demos, "1", 30)
    press(app, pygame.K_x)
    written = sorted(p.name for p in (tmp_path / "recordings").iterdir())
    assert len(written) == 2 and written[0].endswith(".csv") and written[1].endswith("_energy.csv")
    assert f"recordings/{written[0]}" in app.message and app.message in app.hud_lines()
    assert len(app.message) <= 80  # one line of a 640 px window
    first = check_pair_agrees(*(tmp_path / "recordings" / n for n in written), app.dt_s, len(app.table.pucks))
    assert len(first) == 30 * 4 + 1  # 30 frames of 4 steps, and t = 0
    for _ in range(30):
        app.frame(FRAME_S)
    press(app, pygame.K_x)  # a second export in the same second never overwrites the first
    later = sorted(p for p in (tmp_path / "recordings").iterdir() if p.name not in written)
    assert len(later) == 2 and later[1].name == later[0].stem + "_energy.csv"
    both = check_pair_agrees(later[0], later[1], app.dt_s, len(app.table.pucks))
    assert len(both) == 61 * 4 + 1 and both[: len(first)] == first  # from the demo's start to now


def test_the_export_after_a_rewind_leaves_out_the_dropped_future(demos, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    app = app_after_frames(demos, "1", 60)
    press(app, pygame.K_SPACE)
    for _ in range(20):
        press(app, pygame.K_COMMA)  # back 20 frames
    t_back = app.table.time_s
    press(app, pygame.K_SPACE)  # runs on from there: one frame more
    press(app, pygame.K_x)
    energy_file = next((tmp_path / "recordings").glob("*_energy.csv"))
    _, energy = read_csv(energy_file)
    times = [row[0] for row in energy]
    assert times[-1] == round(t_back + 4 * app.dt_s, 6)  # the frame that ran on, then x
    assert len(times) == round(times[-1] / app.dt_s) + 1 and np.all(np.diff(times) > 0)


def test_quitting_loses_the_unexported_part_only_without_record(demos, tmp_path):
    app = app_after_frames(demos, "1", 180)
    assert app.lessons.unexported_s() == pytest.approx(3.0)
    app.lessons.record_into(tmp_path / "all.csv", app.table)  # as --record does: every row is in its file
    for _ in range(180):
        app.frame(FRAME_S)
    assert app.lessons.unexported_s() == 0.0 and not app.quit_would_lose()


def test_record_option_writes_the_pair_in_a_headless_run(tmp_path, capsys):
    path = tmp_path / "cradle.csv"
    assert main(["--headless", "--no-server", "--demo", "7", "--seconds", "3", "--record", str(path)]) == 0
    energy = check_pair_agrees(path, tmp_path / "cradle_energy.csv", 1 / 240, 3)
    assert len(energy) == 721
    out = capsys.readouterr().out
    assert "recorded 3.00 s (721 steps)" in out and "cradle_energy.csv" in out


def test_record_keeps_each_demo_started_in_a_file_of_its_own(demos, tmp_path):
    app = App(demos, demo_key="5", headless=True)
    pygame.event.clear()
    app.lessons.record_into(tmp_path / "lesson.csv", app.table)
    for _ in range(15):
        app.frame(FRAME_S)
    press(app, pygame.K_7)  # another demo: its own file beside the first
    for _ in range(30):
        app.frame(FRAME_S)
    recs = app.lessons.finish()
    assert [r.puck_path.name for r in recs] == ["lesson.csv", "lesson-2.csv"]
    assert len(check_pair_agrees(*csv_pair(tmp_path / "lesson.csv"), app.dt_s, 2)) == 15 * 4 + 1
    assert len(check_pair_agrees(*csv_pair(tmp_path / "lesson-2.csv"), app.dt_s, 3)) == 31 * 4 + 1


@pytest.mark.parametrize("bad", ["no/such/folder/run.csv", "."])
def test_record_option_with_a_bad_path_is_one_line_and_exit_1(bad, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["--headless", "--no-server", "--seconds", "0.1", "--record", bad]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("airtable: --record")
    assert not list(tmp_path.iterdir())


def test_a_crowd_too_big_for_the_export_key_is_not_recorded_and_x_says_why(demos, tmp_path, monkeypatch):
    from airtable.app.lessons import SPOOL_MAX_PUCKS

    monkeypatch.chdir(tmp_path)
    app = app_after_frames(demos, "1", 10)
    for k in range(SPOOL_MAX_PUCKS):  # a crowd added live
        app.table.add_puck((0.3 + 0.45 * (k % 20), 0.3 + 0.45 * (k // 20)), radius_m=0.1)
    for _ in range(10):
        app.frame(FRAME_S)
    press(app, pygame.K_x)
    assert "--record" in app.message and str(SPOOL_MAX_PUCKS) in app.message
    energy = check_pair_agrees(*sorted((tmp_path / "recordings").iterdir()), app.dt_s, 5)
    assert len(energy) == 10 * 4 + 1  # up to the crowd, every step


def test_x_on_a_demo_too_big_to_record_writes_nothing_and_says_why_first(demos, tmp_path, monkeypatch):
    """The 10000-puck gas: x wrote two files of headers only, and the window cut the reason off."""
    monkeypatch.chdir(tmp_path)
    app = app_after_frames(demos, "0p", 5, window_size_px=(640, 480))  # 2000 pucks
    press(app, pygame.K_x)
    assert not (tmp_path / "recordings").exists() or not list((tmp_path / "recordings").iterdir())
    assert app.message.startswith("nothing recorded yet (over 200 pucks: --record FILE.csv records every puck)")
    assert app.window.font.size(app.message)[0] <= 640  # whole, in the smallest window


def test_the_recording_for_x_stops_at_its_size_on_disk_and_x_says_so(demos, tmp_path, monkeypatch):
    from airtable.app import lessons

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(lessons, "SPOOL_MAX_BYTES", 20_000)
    app = app_after_frames(demos, "1", 30)  # five pucks: about 570 bytes a step
    rec = app.lessons.recorder
    assert rec.closed and 20_000 < rec.nbytes < 21_000 and "GB written" in rec.error
    press(app, pygame.K_x)
    assert "stopped" in app.message and "--record" in app.message
    pucks, energy = sorted((tmp_path / "recordings").iterdir())
    assert pucks.stat().st_size + energy.stat().st_size == rec.nbytes
    check_pair_agrees(pucks, energy, app.dt_s, 5)


def test_nbytes_follows_a_cut(tmp_path):
    table = AirTable()
    table.add_puck((2.0, 2.0), radius_m=0.2, vel_mps=(1.0, 0.5))
    rec = Recorder(tmp_path / "n.csv", buffer_rows=7)
    rec.sample(table)
    fill(rec, table, 50, 0.01)
    rec.drop_after(0.2)
    fill(rec, table, 5, 0.01)
    rec.close()
    assert rec.nbytes == rec.puck_path.stat().st_size + rec.energy_path.stat().st_size


def test_a_demo_left_before_x_keeps_its_recording_for_the_next_x(demos, tmp_path, monkeypatch):
    """A user test: demo 7 ran 20 s, then 2, then x: only demo 2's 3 s were written, and the quit
    question said nothing of the 20 s. A demo left unexported now keeps its recording until x."""
    monkeypatch.chdir(tmp_path)
    app = app_after_frames(demos, "7", 150)  # 2.5 s of demo 7
    press(app, pygame.K_2)
    for _ in range(150):  # 2.5 s of demo 2
        app.frame(FRAME_S)
    assert app.lessons.unexported_s() == pytest.approx(5.0, abs=0.05)  # both, as quitting would lose
    assert any("5 s of recording not exported" in line for line in app.quit_would_lose())
    press(app, pygame.K_2)  # restarted after 2.5 s: kept too
    press(app, pygame.K_x)
    files = sorted(p.name for p in (tmp_path / "recordings").glob("*.csv") if not p.stem.endswith("_energy"))
    assert [name.split("-")[0] for name in files] == ["demo2", "demo2", "demo7"], files
    spans = sorted(len(read_csv(tmp_path / "recordings" / name.replace(".csv", "_energy.csv"))[1]) for name in files)
    assert spans[-1] >= round(2.5 * 240)  # demo 7's 2.5 s, every step, from its start
    assert app.lessons.unexported_s() < 0.1 and not app.lessons.kept  # (the frame after x)


def test_x_in_the_quit_question_exports_as_the_question_says(demos, tmp_path, monkeypatch):
    """A user test: the question said "(x exports it)", and x only closed it."""
    monkeypatch.chdir(tmp_path)
    app = app_after_frames(demos, "1", 180)
    press(app, pygame.K_ESCAPE)
    assert app.panels.panel() == "quit"
    press(app, pygame.K_x)
    assert app.panels.panel() is None and app.running
    assert list((tmp_path / "recordings").glob("demo1-*_energy.csv"))
    assert not app.quit_would_lose()
