"""--stats: one line at exit with frames, frame rate, steps, CPU time and peak memory."""

from __future__ import annotations

import re

import pytest

from airtable import cli
from airtable.app.stats import RunStats, cpu_s, peak_memory_mb

LINE = re.compile(
    r"^stats: frames (\d+), fps median (\S+) p5 (\S+), steps (\d+), cpu (\d+\.\d) s, peak memory (\d+ MB|n/a)$"
)


def test_the_line_reports_median_and_slowest_frames_from_the_clock() -> None:
    now = [0.0]
    cpu = [10.0]
    stats = RunStats(clock=lambda: now[0], cpu=lambda: cpu[0])
    # 100 frames: 94 of 1/60 s, then 6 of 1/20 s (a stall): the median is 60 fps, p5 is 20.
    for k in range(101):
        now[0] += 1 / 60 if k < 95 else 1 / 20
        stats.frame()
    stats.steps = 404
    cpu[0] = 12.5
    match = LINE.match(stats.line())
    assert match, stats.line()
    frames, median, p5, steps, cpu_text, _ = match.groups()
    assert (int(frames), int(steps)) == (101, 404)
    assert float(median) == pytest.approx(60.0, abs=0.05) and float(p5) == pytest.approx(20.0, abs=0.05)
    assert cpu_text == "2.5"  # since the stats began


def test_the_idle_loops_waits_are_not_timed() -> None:
    """A lesson spent mostly on a still table drew 12 frames a second on purpose: not a slow machine."""
    now = [0.0]
    stats = RunStats(clock=lambda: now[0])
    for k in range(200):  # 50 frames at 60 fps, then 150 idle ones at 12 fps
        now[0] += 1 / 60 if k < 50 else 1 / 12
        stats.frame(idle=k >= 50)
    median, p5 = stats.fps()
    assert stats.frames == 200 and median == pytest.approx(60.0) and p5 == pytest.approx(60.0)


def test_before_two_frames_the_rate_is_not_made_up() -> None:
    stats = RunStats()
    stats.frame()
    assert "fps median n/a p5 n/a" in stats.line() and stats.fps() is None


def test_cpu_and_peak_memory_are_this_processes() -> None:
    before = cpu_s()
    sum(i * i for i in range(200_000))  # some work
    assert cpu_s() > before
    peak = peak_memory_mb()
    assert peak is None or 10 < peak < 100_000  # this interpreter, numpy and pygame take tens of MB


def test_a_headless_run_prints_the_line_at_exit_counted_in_frames(capsys) -> None:
    # 0.5 s of simulated time in frames of 1/60 s, each 4 steps of the burst's 1/240 s.
    status = cli.main(["--headless", "--no-server", "--demo", "0", "--seconds", "0.5", "--stats"])
    assert status == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("stats:")]
    assert len(lines) == 1
    match = LINE.match(lines[0])
    assert match, lines[0]
    assert (int(match.group(1)), int(match.group(4))) == (30, 120)
    assert float(match.group(2)) > 0 and float(match.group(3)) > 0


def test_without_the_flag_nothing_is_printed(capsys) -> None:
    assert cli.main(["--headless", "--no-server", "--demo", "0", "--seconds", "0.1"]) == 0
    assert "stats:" not in capsys.readouterr().out
