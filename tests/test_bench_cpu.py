"""The cpu bench's measuring stick: a process's CPU time read from /proc (the figures themselves are
measured by `make bench`, never in a test)."""

from __future__ import annotations

import os
import sys
import time

import pytest

from bench.cpu import cpu_seconds


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_cpu_seconds_counts_this_process_like_process_time():
    before, own_before = cpu_seconds(os.getpid()), time.process_time()
    total = 0
    for i in range(3_000_000):  # some work of our own
        total += i * i
    spent, own_spent = cpu_seconds(os.getpid()) - before, time.process_time() - own_before
    assert total > 0
    tick = 1 / os.sysconf("SC_CLK_TCK")
    assert spent == pytest.approx(own_spent, abs=3 * tick)
