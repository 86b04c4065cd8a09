"""The rewind history: moving through it restores exact moments; its memory is bounded by bytes at any size."""

from __future__ import annotations

import gc
import tracemalloc

import numpy as np
import pytest
from airtable.demos.demo_0p_gas import gas_scene

from airtable.app.history import BUDGET_BYTES, History
from airtable.physics.state import same_bits
from airtable.physics.table import AirTable


def frames(table: AirTable, history: History, n: int, steps: int = 4, dt_s: float = 1 / 240) -> list:
    """Run `n` frames of `steps` steps, recording each; the positions after each frame."""
    out = []
    for _ in range(n):
        for _ in range(steps):
            table.step(dt_s)
        history.record(table)
        out.append(table.pos_m.copy())
    return out


def test_back_and_forward_show_the_recorded_moments_exactly():
    table = gas_scene(60, seed=2)
    table.gravity_on, table.cr_puck, table.cr_wall = True, 0.5, 0.8
    h = History()
    h.record(table)
    seen = frames(table, h, 50)
    assert len(h) == 51 and not h.in_past
    assert h.back(table, 10)
    assert h.in_past and h.index == 40 and same_bits(table.pos_m, seen[39])
    assert h.forward(table) and same_bits(table.pos_m, seen[40])
    assert h.forward(table, 100)  # past the newest: stops there, live again
    assert not h.in_past and same_bits(table.pos_m, seen[-1])
    assert not h.forward(table)  # nothing newer: the app steps instead


def test_jumps_by_seconds_land_on_the_moments_a_second_apart():
    table = gas_scene(30, seed=2)
    h = History()
    h.record(table)
    frames(table, h, 180)  # 3 s of 1/60 s frames
    assert h.back_seconds(table, 1.0)
    assert table.time_s == pytest.approx(2.0)
    assert h.back_seconds(table, 1.0) and table.time_s == pytest.approx(1.0)
    assert h.back_seconds(table, 5.0) and table.time_s == 0.0 and h.index == 0
    assert not h.back_seconds(table, 1.0)  # the oldest moment
    assert h.forward_seconds(table, 1.0) and table.time_s == pytest.approx(1.0)
    assert h.forward_seconds(table, 10.0) and not h.in_past and table.time_s == pytest.approx(3.0)


def test_running_on_from_the_past_drops_the_future_and_replays_it_bit_for_bit():
    table = gas_scene(200, seed=4)
    table.gravity_on, table.cr_puck = True, 0.3
    h = History()
    h.record(table)
    first = frames(table, h, 40)
    end_vel = table.vel_mps.copy()
    h.back(table, 25)
    nbytes = h.nbytes
    assert h.drop_future() == 25
    assert len(h) == 16 and not h.in_past and h.nbytes < nbytes
    again = frames(table, h, 25)
    for a, b in zip(first[15:], again, strict=True):
        assert same_bits(a, b)
    assert same_bits(table.vel_mps, end_vel) and len(h) == 41


def test_a_change_made_while_paused_at_the_newest_moment_is_kept():
    table = gas_scene(20, seed=1)
    h = History()
    h.record(table)
    frames(table, h, 5)
    table.vel_mps[:] = 0.0  # "freeze", while paused
    moved = table.pos_m.copy()
    assert h.back(table) and len(h) == 7  # the frozen table became a moment of its own
    assert h.forward(table) and not np.any(table.vel_mps) and same_bits(table.pos_m, moved)


def test_an_unchanged_table_is_not_kept_twice():
    table = gas_scene(20, seed=1)
    h = History()
    assert h.record(table)
    assert not h.record(table)
    assert len(h) == 1


def measured_bytes(build, budget_bytes: int) -> tuple[int, int, int]:
    """A history filled by `build(history)`: the bytes tracemalloc sees it hold, its own count, moments dropped."""
    gc.collect()
    tracemalloc.start()
    try:
        h = History(budget_bytes)
        build(h)
        gc.collect()
        held = tracemalloc.get_traced_memory()[0]
        counted, dropped = h.nbytes, h.dropped
        h.clear()
        gc.collect()
        freed = held - tracemalloc.get_traced_memory()[0]
    finally:
        tracemalloc.stop()
    return freed, counted, dropped


def test_the_history_is_bounded_by_64_MB_unless_told_otherwise():
    assert History().budget_bytes == BUDGET_BYTES == 64 * 2**20


# The bound is checked on a smaller budget: the same bookkeeping, a sixteenth of
# the memory and of tracemalloc's time.
TEST_BUDGET_BYTES = BUDGET_BYTES // 16


@pytest.mark.parametrize("n_pucks", [10, 1000, 10000])
def test_the_history_never_holds_more_than_its_budget(n_pucks):
    table = gas_scene(n_pucks, seed=5)
    table.gravity_on = True
    table.step(1 / 240)  # a neighbour list too, for the big ones
    per_frame = 32 * n_pucks + 2000
    total_frames = int(1.3 * TEST_BUDGET_BYTES / per_frame)

    def fill(h: History) -> None:
        for _ in range(total_frames):
            # A new moment each frame (cheaper than stepping, the same bytes): positions and velocities change.
            table.pos_m[:, 0] += 1e-7
            table.vel_mps[:, 1] -= 1e-7
            table.time_s += 1 / 60
            table.steps += 4
            h.record(table)

    held, counted, dropped = measured_bytes(fill, TEST_BUDGET_BYTES)
    assert held <= TEST_BUDGET_BYTES and counted <= TEST_BUDGET_BYTES
    assert dropped > 0 and counted > 0.95 * TEST_BUDGET_BYTES  # full, and the oldest went
    if n_pucks > 10:  # (a few pucks' small arrays: Python's own overheads are most of what tracemalloc sees)
        assert held == pytest.approx(counted, rel=0.1)  # its own count is close to the truth


def test_thirty_seconds_of_a_99_puck_gas_under_gravity_fit():
    table = gas_scene(99, seed=6)
    table.gravity_on = True  # the list of neighbours is rebuilt almost every frame: a state's worst size
    h = History()
    h.record(table)
    # 10 s of it, then a bound for the next 20 s: none of their seconds costs more than the dearest second so far
    # (the gas bouncing as it falls: 1.3 MB; the pile after 6 s, 0.7 MB a second; 30 s in fact take 22.8 MB).
    frames(table, h, 10 * 60, steps=1, dt_s=1 / 60)
    assert h.dropped == 0 and h.span_s == pytest.approx(10.0)
    dearest_second = max(sum(h.costs[k : k + 60]) for k in range(1, len(h), 60))
    assert h.nbytes + 20 * dearest_second < BUDGET_BYTES


def test_a_table_too_big_for_the_budget_keeps_no_moment():
    table = gas_scene(1000, seed=1)
    h = History(budget_bytes=20_000)
    assert h.record(table)
    assert len(h) == 0 and h.nbytes == 0
    assert not h.back(table) and h.timeline() is None


def test_its_own_count_is_never_below_what_it_really_holds_with_contacts():
    table = gas_scene(10, seed=2)
    table.gravity_on, table.cr_puck, table.cr_wall = True, 0.0, 0.0  # a pile: the contact stage keeps its rounds

    def fill(h: History) -> None:
        h.record(table)
        frames(table, h, 300, steps=1, dt_s=1 / 60)

    held, counted, dropped = measured_bytes(fill, BUDGET_BYTES)
    assert dropped == 0 and held <= counted
