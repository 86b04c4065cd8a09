"""The "window" bench section: skipped with a reason where Xvfb is missing; reads the app's --stats line."""

from __future__ import annotations

import argparse
import shutil

from bench import frames as bench_frames


def test_without_xvfb_the_section_says_why_and_passes(monkeypatch, capsys) -> None:
    monkeypatch.setattr(shutil, "which", lambda name: None)
    assert bench_frames.window_section(argparse.Namespace(quick=True)) is True
    assert "skipped: needs Xvfb" in capsys.readouterr().out


def test_the_stats_line_is_read_and_judged_against_60_fps(capsys) -> None:
    line = "stats: frames 360, fps median 60.1 p5 43.0, steps 1440, cpu 1.4 s, peak memory 56 MB"
    frames, median, p5, _, cpu = bench_frames.STATS.search(line).groups()
    assert (frames, median, p5, cpu) == ("360", "60.1", "43.0", "1.4")
    assert bench_frames._report("app", (360, 60.1, 43.0, 3.9, 1.0), checked=True) is True
    assert bench_frames._report("app", (300, 50.0, 30.0, 9.0, 1.0), checked=True) is False
    assert bench_frames._report("app", (360, 60.0, 55.0, 9.0, 0.7), checked=True) is False  # slow motion
    assert bench_frames._report("OpenGL", (100, 16.0, 11.0, 18.0, 1.0), checked=False) is True
    out = capsys.readouterr().out
    assert "PASS" in out and "MISS" in out and "(for comparison)" in out and "70% of real time" in out


def test_the_window_section_asks_for_the_burst_and_the_gas_of_its_count_counting_variations_from_1(demos):
    burst, burst_dt = bench_frames._variation("0")
    gas, gas_dt = bench_frames._variation("0p")
    assert demos["0"].variations[burst - 1] == f"n = {bench_frames.PUCKS}"
    assert demos["0p"].variations[gas - 1] == f"{bench_frames.PUCKS} pucks"
    assert (burst_dt, gas_dt) == (demos["0"].dt_s, demos["0p"].dt_s)
