"""The benchmark's instruction count: how it reads callgrind, and what it says without valgrind."""

from __future__ import annotations

import argparse
import subprocess

from bench import instructions as bench_instructions


def _valgrind_says(monkeypatch, stderr: str, returncode: int = 0) -> list[list[str]]:
    """Make `subprocess.run` answer as valgrind would; return the commands it was given."""
    calls = []

    def run(cmd, **kwargs):
        calls.append(cmd)
        return subprocess.CompletedProcess(cmd, returncode, "", stderr)

    monkeypatch.setattr(bench_instructions.subprocess, "run", run)
    return calls


def test_the_count_is_callgrinds_total_over_the_steps(monkeypatch) -> None:
    calls = _valgrind_says(monkeypatch, "==7== Events    : Ir\n==7== Collected : 1580000\n==7== I   refs: 1,580,000\n")
    assert bench_instructions.instructions_per_step(1000, 4) == 395000
    cmd = calls[0]
    assert cmd[:2] == ["valgrind", "--tool=callgrind"] and "--toggle-collect=functools_reduce" in cmd
    assert cmd[-4:] == ["-m", "bench.instructions", "1000", "4"]


def test_a_count_of_nothing_or_a_failed_run_is_no_count(monkeypatch) -> None:
    _valgrind_says(monkeypatch, "==7== Collected : 0\n")
    assert bench_instructions.instructions_per_step(1000, 4) is None
    _valgrind_says(monkeypatch, "valgrind: failed to start tool\n", returncode=1)
    assert bench_instructions.instructions_per_step(1000, 4) is None


def test_without_valgrind_the_section_says_so_and_passes(monkeypatch, capsys) -> None:
    monkeypatch.setattr(bench_instructions.shutil, "which", lambda name: None)
    assert bench_instructions.instructions_section(argparse.Namespace(quick=True)) is True
    assert "skipped: needs valgrind" in capsys.readouterr().out


def test_the_child_steps_the_gas_inside_reduce(monkeypatch) -> None:
    stepped = []
    real_reduce = bench_instructions.functools.reduce

    def reduce(fn, items, start):
        stepped.append(len(items))
        return real_reduce(fn, items, start)

    monkeypatch.setattr(bench_instructions.functools, "reduce", reduce)
    bench_instructions._step_inside_reduce(60, 3)
    assert stepped == [3]
