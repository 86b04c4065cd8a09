"""The fixed-step game loop: how many physics steps a frame runs, the frame rate, the pacing.

Physics runs at a fixed step `dt_s` with an accumulator, so its results do not
depend on the frame rate; drawing runs once per frame. Three small pieces,
used by the teacher's app and by the load tool's headless table:

- `FixedStep`: turns each frame's (scaled) time into a whole number of steps,
  with a cap so a stalled frame cannot make the physics run away.
- `FpsCounter`: frames counted over the last second (the frame itself ticks it,
  with its own clock, so a simulated run reports its simulated rate).
- `FrameLoop`: calls `frame(dt_s)` until told to stop. In real time it sleeps
  until the next frame is due (it never spins), at most `fps` frames a second;
  with `fixed_dt_s` it runs simulated frames of that length back to back, so
  tests and headless runs count frames, not wall-clock seconds. `period_s`
  may change between frames (the app slows down while the table is still).

A headless table in a thread, as the load tool runs one:

    stepper, counter, loop = FixedStep(1 / 240), FpsCounter(), FrameLoop(fps=60)

    def frame(dt_s):
        for _ in range(stepper.steps(dt_s)):
            table.step(stepper.dt_s, pulls)
        fps = counter.tick(time.monotonic())
        ...

    thread = threading.Thread(target=loop.run, args=(frame,), daemon=True)
    thread.start()
    ...
    loop.stop.set()   # wakes the loop at once; it returns after the current frame
    thread.join()
"""

from __future__ import annotations

import contextlib
import signal
import threading
import time
from collections import deque
from collections.abc import Callable, Iterator

# A stalled frame (window dragged, laptop busy) runs at most this much
# simulated time; the rest is dropped rather than exploding the physics.
MAX_SIM_PER_FRAME_S = 0.1
# A real frame longer than this (the process was stopped) counts as this long.
MAX_FRAME_S = 0.25
# A frame's physics takes at most this much real time, however long drawing the last frame took:
# a window that draws slowly (4K without a GPU) still answers input a few times a second.
MAX_PHYSICS_PER_FRAME_S = 0.1


class FixedStep:
    """Fixed physics steps of `dt_s` out of variable frame times.

    In real time (`budget_s` set, with the clock that measures it) a frame's
    steps stop once they have taken budget_s, or as long as the rest of the
    last frame took (drawing it) if that was longer, and the steps left are
    dropped: a table heavier than the computer can step in real time (a
    10000-puck gas) then runs in slow motion at a steady frame rate, instead of
    a frame that takes ever longer to catch up, and where drawing is slow (a 4K
    screen without a GPU) the physics still gets half the time. Each step is the
    same fixed step either way, so the results do not change; `real_time_share`
    says how much of real time the physics kept up with over the last second.
    """

    def __init__(
        self,
        dt_s: float,
        max_sim_per_frame_s: float = MAX_SIM_PER_FRAME_S,
        budget_s: float | None = None,
        clock: Callable[[], float] = time.perf_counter,
    ) -> None:
        self.dt_s = dt_s
        self.max_sim_per_frame_s = max_sim_per_frame_s
        self.accumulator_s = 0.0
        self.budget_s = budget_s
        self.clock = clock
        self._asked: deque[tuple[float, int, int]] = deque()  # (clock, steps asked, steps run) per frame
        self._ended: float | None = None  # when the last frame's steps ended (the clock's)
        self.last_run_s = 0.0  # how long the last frame's steps took (the clock's)

    def reset(self, dt_s: float | None = None) -> None:
        if dt_s is not None:
            self.dt_s = dt_s
        self.accumulator_s = 0.0
        self._asked.clear()
        self._ended = None

    def run(self, frame_dt_s: float, speed: float, step: Callable[[], bool]) -> int:
        """Run this frame's steps (`steps`) with `step`, until one returns False or the budget is
        spent; returns how many ran."""
        asked = self.steps(frame_dt_s, speed)
        start = self.clock()
        budget = self.budget_s
        if budget is not None and self._ended is not None:  # at least the rest of the last frame
            budget = min(max(budget, start - self._ended), MAX_PHYSICS_PER_FRAME_S)
        ran = 0
        while ran < asked and step():
            ran += 1
            if budget is not None and self.clock() - start > budget:
                break
        first, now = self._ended is None, self.clock()
        self.last_run_s = now - start
        self._ended = now
        if not first:  # (the first frame after a reset spans building the demo: not the physics' pace)
            self._asked.append((now, asked, ran))
        while self._asked and self._asked[0][0] < now - 1.0:
            self._asked.popleft()
        return ran

    @property
    def real_time_share(self) -> float:
        """The share of the steps asked for over the last second that ran (1.0: none dropped)."""
        asked = sum(a for _, a, _ in self._asked)
        return sum(r for _, _, r in self._asked) / asked if asked else 1.0

    def steps(self, frame_dt_s: float, speed: float = 1.0) -> int:
        """How many steps to run for a frame of `frame_dt_s` at `speed` times real time."""
        self.accumulator_s += frame_dt_s * speed
        max_steps = max(1, int(self.max_sim_per_frame_s / self.dt_s))
        # The small slack keeps 1/60 s frames of 1/240 s steps at exactly 4 despite round-off.
        steps = min(int(self.accumulator_s / self.dt_s + 1e-9), max_steps)
        self.accumulator_s -= steps * self.dt_s
        if steps == max_steps:
            self.accumulator_s = min(self.accumulator_s, self.dt_s)
        return steps


class FpsCounter:
    """Frames counted over the last second: steadier than 1 / dt of one frame."""

    def __init__(self) -> None:
        self.fps = 0.0
        self._times: deque[float] = deque()

    def tick(self, now_s: float) -> float:
        """Count a frame at time `now_s` (seconds, any origin); returns the frame rate."""
        times = self._times
        times.append(now_s)
        while times[0] < now_s - 1.0:
            times.popleft()
        span = times[-1] - times[0]
        if span > 0:
            self.fps = (len(times) - 1) / span
        return self.fps

    def restart(self) -> None:
        """Forget the frames counted so far (they came at another pace: the idle loop's)."""
        self._times.clear()


class FrameLoop:
    """Calls `frame(dt_s)` once per frame until it returns False or a limit is reached.

    Real time (`fixed_dt_s` None): `dt_s` is the measured frame time, and the
    loop sleeps until the next frame is due, so it runs at most `fps` frames a
    second and a still table leaves the processor idle. `stop` (a
    threading.Event) ends the loop from another thread, waking it at once.

    Simulated time (`fixed_dt_s` given): every frame is `fixed_dt_s` long and
    nothing sleeps.
    """

    def __init__(
        self,
        fps: float = 60.0,
        fixed_dt_s: float | None = None,
        clock: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], object] | None = None,
    ) -> None:
        """`clock` and `sleep` (seconds) are time.monotonic and a wait on `stop`; tests pass fakes."""
        if not fps > 0:
            raise ValueError(f"fps must be above 0, not {fps!r}")
        self.period_s = 1.0 / fps
        self.fixed_dt_s = fixed_dt_s
        self.clock = clock
        self.stop = threading.Event()
        self.sleep = sleep if sleep is not None else self.stop.wait
        self.frame_began = 0.0  # (clock) when the frame running now began

    def run(
        self,
        frame: Callable[[float], bool | None],
        max_frames: int | None = None,
        max_time_s: float | None = None,
    ) -> int:
        """Run frames until `frame` returns False, `max_frames` frames or `max_time_s`
        seconds (of simulated time when `fixed_dt_s` is set). Returns the frames run."""
        ran, elapsed_s = 0, 0.0
        start = last = next_due = self.clock()
        while not self.stop.is_set():
            if self.fixed_dt_s is not None:
                dt_s = self.fixed_dt_s
                elapsed_s += dt_s
            else:
                now = self.clock()
                dt_s, last = min(now - last, MAX_FRAME_S), now
                elapsed_s = now - start
            ran += 1
            self.frame_began = self.clock()
            if frame(dt_s) is False:
                break
            if max_frames is not None and ran >= max_frames:
                break
            if max_time_s is not None and elapsed_s >= max_time_s - 1e-9:  # 120 frames of 1/60 s are 2 s
                break
            if self.fixed_dt_s is None:
                next_due = self._wait(next_due + self.period_s)
        return ran

    def _wait(self, due: float) -> float:
        """Sleep until `due`; returns when the frame after it is due from."""
        delay = due - self.clock()
        if delay > 0:
            self.sleep(delay)
            return due
        return self.clock()  # fell behind: start afresh rather than burst to catch up


@contextlib.contextmanager
def signals_end_the_run(stop: Callable[[], None]) -> Iterator[None]:
    """While the loop runs: SIGTERM (a logout, `kill`) calls `stop`, Ctrl+C raises KeyboardInterrupt.

    SDL turns both into the QUIT event a window's close button sends, and that one asks
    before quitting; a signal is no person at the window to answer. Only in the main
    thread (where Python delivers signals); the previous handlers come back after."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    before = {sig: signal.getsignal(sig) for sig in (signal.SIGTERM, signal.SIGINT)}
    signal.signal(signal.SIGTERM, lambda *_: stop())
    signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        for sig, handler in before.items():
            signal.signal(sig, handler if handler is not None else signal.SIG_DFL)


# A still window that steps no physics (paused, or a student's) takes at most this share of the
# processor: a frame that costs much (10000 pucks at 3840x2160 take 27 ms) comes less often than
# idle_fps, but at least every IDLE_MAX_PERIOD_S (a message's end, a student's cursor are shown that
# late at most). A window whose physics runs keeps idle_fps: a frame steps at most
# MAX_SIM_PER_FRAME_S of simulated time, so longer frames would slow its clock.
IDLE_CPU_SHARE = 0.05
IDLE_MAX_PERIOD_S = 0.5


class IdlingLoop(FrameLoop):
    """The windows' loop (the teacher's and each student's): full rate while anything moves or input
    came lately, `idle_fps` while the window is still (`still()` says so after each frame; less often
    if a frame costs more than IDLE_CPU_SHARE of that while `stepping()` says no physics runs), and
    while idle the wait between frames ends at once on input (a pygame event)."""

    def __init__(
        self,
        fps: float,
        idle_fps: float,
        still: Callable[[], bool],
        headless: bool,
        sleep: Callable[[float], object] | None = None,
        stepping: Callable[[], bool] = lambda: False,
        **kw,
    ) -> None:
        """`sleep`: how to wait where no input can end the wait (headless, or at the full rate);
        `stepping`: whether the frames step physics in real time now (the teacher's, unless paused)."""
        super().__init__(fps=fps, sleep=self._sleep, **kw)
        self._plain_sleep = sleep if sleep is not None else self.stop.wait
        self.stepping = stepping
        self.full_period_s, self.idle_period_s = 1.0 / fps, 1.0 / idle_fps
        self.still, self.headless = still, headless

    @property
    def idling(self) -> bool:
        """The wait before the coming frame is the idle one (the last frame found the window still)."""
        return self.period_s != self.full_period_s

    def after_frame(self) -> None:
        """Call at the end of each frame: the next one comes at the full or the idle rate."""
        if not self.still():
            self.period_s = self.full_period_s
            return
        if self.stepping():
            self.period_s = self.idle_period_s
            return
        took_s = self.clock() - self.frame_began
        self.period_s = max(self.idle_period_s, min(took_s / IDLE_CPU_SHARE, IDLE_MAX_PERIOD_S))

    def _sleep(self, seconds: float) -> None:
        if self.headless or self.period_s == self.full_period_s:
            self._plain_sleep(seconds)
            return
        import pygame  # only the windows idle this way; the load tool's loops have no pygame

        event = pygame.event.wait(max(1, int(seconds * 1000)))
        if event.type != pygame.NOEVENT:
            pygame.event.post(event)  # back in the queue, for the frame it woke
