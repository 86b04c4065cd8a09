"""The fixed-step loop: steps per frame, the frame rate, and pacing that sleeps rather than spins."""

from __future__ import annotations

import threading

import pytest

from airtable.app.loop import IDLE_MAX_PERIOD_S, MAX_SIM_PER_FRAME_S, FixedStep, FpsCounter, FrameLoop, IdlingLoop


class FakeClock:
    """A clock that only moves when the loop sleeps or a frame takes time."""

    def __init__(self) -> None:
        self.now = 100.0
        self.slept: list[float] = []

    def __call__(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        self.slept.append(seconds)
        self.now += seconds


def test_fixed_step_turns_frames_into_whole_steps():
    step = FixedStep(1 / 240)
    assert [step.steps(1 / 60) for _ in range(100)] == [4] * 100  # no 3-5-3 jitter from round-off
    assert sum(step.steps(1 / 144) for _ in range(144)) == 240
    slow = FixedStep(1 / 240)
    assert [slow.steps(1 / 60, speed=s) for s in (0.25, 0.25, 0.5, 1 / 16, 1 / 16, 1 / 16, 1 / 16)] == [
        1,
        1,
        2,
        0,
        0,
        0,
        1,
    ]


def test_a_stalled_frame_runs_at_most_a_tenth_of_a_second():
    step = FixedStep(1 / 240)
    assert step.steps(5.0) == round(MAX_SIM_PER_FRAME_S * 240)
    assert step.accumulator_s <= 1 / 240  # the rest is dropped, not carried
    assert step.steps(1 / 60) in (4, 5)


def test_a_frames_steps_stop_at_the_budget_and_the_table_runs_in_slow_motion():
    clock = FakeClock()

    def heavy_step() -> bool:  # 4 ms of the clock a step: 240 steps a second would need 0.96 s of every 1
        clock.now += 0.004
        return True

    def frames(stepper: FixedStep, count: int, draw_s: float) -> list[int]:
        """Real-time frames: each as long as its steps and its drawing (draw_s) took."""
        ran, last = [], clock.now - 1 / 60
        for _ in range(count):
            frame_s, last = clock.now - last, clock.now
            ran.append(stepper.run(frame_s, 1.0, heavy_step))
            clock.now += draw_s
        return ran

    quick_to_draw = FixedStep(1 / 240, budget_s=0.010, clock=clock)
    assert set(frames(quick_to_draw, 120, draw_s=0.005)) == {3}  # 8 and 12 ms: the third passes 10 ms
    assert 0.7 < quick_to_draw.real_time_share < 0.8  # 3 of the 4 a 17 ms frame asks for
    assert quick_to_draw.accumulator_s < 1 / 240  # the dropped steps are not carried over to pile up

    slow_to_draw = FixedStep(1 / 240, budget_s=0.010, clock=clock)  # drawing takes 30 ms (a 4K screen)
    counts = frames(slow_to_draw, 60, draw_s=0.030)
    assert counts[0] == 3 and set(counts[1:]) == {8}  # then as long as drawing took: 32 ms
    assert 0.5 < slow_to_draw.real_time_share < 0.6  # the physics keeps about half the time

    free = FixedStep(1 / 240, clock=clock)  # no budget (simulated time): every step runs, whatever the clock
    assert [free.run(1 / 60, 1.0, heavy_step) for _ in range(30)] == [4] * 30
    assert free.real_time_share == 1.0


def test_a_failed_step_ends_the_frames_steps():
    calls = []
    stepper = FixedStep(1 / 240)
    assert stepper.run(1 / 60, 1.0, lambda: calls.append(1) or len(calls) < 2) == 1
    assert len(calls) == 2


def test_fps_counts_the_frames_of_the_last_second():
    counter = FpsCounter()
    for i in range(90):
        fps = counter.tick(i / 45)
    assert fps == pytest.approx(45.0)


def test_simulated_frames_never_sleep():
    clock = FakeClock()
    loop = FrameLoop(fps=60, fixed_dt_s=1 / 60, clock=clock, sleep=clock.sleep)
    seen: list[float] = []
    assert loop.run(seen.append, max_time_s=2.0) == 120
    assert seen == [1 / 60] * 120
    assert clock.slept == []


def test_real_time_sleeps_until_each_frame_is_due():
    clock = FakeClock()
    loop = FrameLoop(fps=50, clock=clock, sleep=clock.sleep)

    def frame(dt_s: float) -> None:
        clock.now += 0.005  # the frame's own work: 5 ms

    assert loop.run(frame, max_frames=10) == 10
    # 20 ms a frame: 5 ms of work and 15 ms asleep, never a busy wait.
    assert clock.slept == pytest.approx([0.015] * 9)
    assert loop.run(frame, max_time_s=1.0) == 51


def test_a_slow_frame_does_not_make_the_next_ones_burst():
    clock = FakeClock()
    loop = FrameLoop(fps=50, clock=clock, sleep=clock.sleep)
    work = iter([0.1, 0.005, 0.005, 0.005])
    dts: list[float] = []

    def frame(dt_s: float) -> None:
        dts.append(dt_s)
        clock.now += next(work)

    loop.run(frame, max_frames=4)
    assert clock.slept == pytest.approx([0.015, 0.015])  # after the 100 ms frame, no sleep, then the pace again
    assert dts[1] == pytest.approx(0.1)


def test_a_still_window_redraws_at_the_idle_rate_or_less_often_if_a_frame_costs_much():
    """A paused table of 10000 pucks at 4K took 27 ms a frame, 12 times a second: a fifth of a core."""
    clock = FakeClock()
    still = iter([False, True, True, True, True])
    loop = IdlingLoop(60.0, 12.0, lambda: next(still), headless=True, clock=clock, sleep=clock.sleep)
    work = iter([0.003, 0.003, 0.010, 0.027, 0.002])  # each frame's own work (s)

    def frame(dt_s: float) -> None:
        clock.now += next(work)
        loop.after_frame()

    loop.run(frame, max_frames=5)
    # Moving: 1/60 s; still: 1/12 s for a cheap frame, 20 times a frame's cost above that (a 20th of
    # the processor), at most 0.5 s (27 ms would be 0.54 s); a cheap frame again: 1/12 s.
    periods = [work_s + slept for work_s, slept in zip([0.003, 0.003, 0.010, 0.027], clock.slept, strict=True)]
    assert periods == pytest.approx([1 / 60, 1 / 12, 0.2, IDLE_MAX_PERIOD_S])
    assert loop.period_s == pytest.approx(1 / 12)


def test_a_still_window_whose_physics_runs_keeps_the_idle_rate_and_so_real_time():
    """Idle frames half a second apart stepped at most MAX_SIM_PER_FRAME_S each: a still table's clock ran at
    a fifth of real time (a demo's timed events, a prediction waiting for its collision, all late)."""
    clock = FakeClock()
    paused = iter([False, False, True, True])
    loop = IdlingLoop(60.0, 12.0, lambda: True, True, clock=clock, sleep=clock.sleep, stepping=lambda: not next(paused))
    dts: list[float] = []

    def frame(dt_s: float) -> None:
        dts.append(dt_s)
        clock.now += 0.040  # a costly frame: 40 ms
        loop.after_frame()

    loop.run(frame, max_frames=4)
    assert dts[1:3] == pytest.approx([1 / 12, 1 / 12])  # stepping: every frame well under MAX_SIM_PER_FRAME_S
    assert max(dts[1:3]) < MAX_SIM_PER_FRAME_S
    assert dts[3] > 0.2 and loop.period_s == IDLE_MAX_PERIOD_S  # paused: nothing steps, frames may wait


def test_frame_returning_false_or_stop_ends_the_loop():
    loop = FrameLoop(fps=1000, fixed_dt_s=0.01)
    assert loop.run(lambda dt: False) == 1
    stopper = FrameLoop(fps=1000)
    thread = threading.Thread(target=lambda: stopper.run(lambda dt: None))
    thread.start()
    stopper.stop.set()
    thread.join(timeout=5.0)
    assert not thread.is_alive()


def test_the_first_frame_after_a_reset_does_not_count_against_the_pace():
    """Building a demo makes the next frame long: its dropped steps are no sign the physics is behind."""
    clock = FakeClock()

    def step() -> bool:
        clock.now += 0.003
        return True

    stepper = FixedStep(1 / 240, budget_s=0.010, clock=clock)
    stepper.reset()
    assert stepper.run(0.25, 1.0, step) == 4  # asked 24 after a quarter second of building: 12 ms ran
    for _ in range(30):
        clock.now += 1 / 60  # drawing, then waiting for the next frame
        assert stepper.run(1 / 60, 1.0, step) in (4, 5)  # (5 once: what the first frame left)
    assert stepper.real_time_share == 1.0
