"""What a run cost, for `--stats`: frames and their rate, physics steps, CPU time, peak memory.

The app counts each frame and each physics step; at exit `RunStats.line()`
is one line a teacher can compare between laptops:

    stats: frames 600, fps median 60.0 p5 57.9, steps 2400, cpu 3.1 s, peak memory 142 MB

- fps comes from the wall-clock time between frames: the median frame and the
  slowest twentieth (p5 is the rate that 95 % of frames beat). A headless run of
  simulated time runs frames back to back, so there it is how fast this machine
  goes. The wait before an idle frame (a still table: the loop draws a few a
  second on purpose) is no measure of the machine and is left out. "n/a" until
  two frames have run at the full rate.
- cpu is the process's CPU time (every thread: the server's too) since the
  app started, in seconds: divided by the run's length, the share of one core.
- peak memory is the most resident memory the process has used, in MB of
  2^20 bytes ("n/a" where the system does not say).
"""

from __future__ import annotations

import sys
import time
from array import array
from collections.abc import Callable

import numpy as np

try:
    import resource
except ImportError:  # Windows
    resource = None


def cpu_s() -> float:
    """CPU time of this process so far (user + system, all threads), in seconds."""
    if resource is not None:
        usage = resource.getrusage(resource.RUSAGE_SELF)
        return usage.ru_utime + usage.ru_stime
    return time.process_time()


def peak_memory_mb() -> float | None:
    """The most resident memory this process has used, in MB (2^20 bytes); None if unknown."""
    if resource is not None:
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        return peak / 2**20 if sys.platform == "darwin" else peak / 2**10  # bytes on macOS, KB elsewhere
    if sys.platform == "win32":
        return _windows_peak_mb()
    return None


def _windows_peak_mb() -> float | None:
    """PeakWorkingSetSize from GetProcessMemoryInfo."""
    import ctypes
    from ctypes import wintypes

    class Counters(ctypes.Structure):  # PROCESS_MEMORY_COUNTERS
        _fields_ = [("cb", wintypes.DWORD), ("PageFaultCount", wintypes.DWORD)] + [
            (name, ctypes.c_size_t)
            for name in (
                "PeakWorkingSetSize",
                "WorkingSetSize",
                "QuotaPeakPagedPoolUsage",
                "QuotaPagedPoolUsage",
                "QuotaPeakNonPagedPoolUsage",
                "QuotaNonPagedPoolUsage",
                "PagefileUsage",
                "PeakPagefileUsage",
            )
        ]

    try:
        counters = Counters(cb=ctypes.sizeof(Counters))
        process = ctypes.windll.kernel32.GetCurrentProcess()
        if not ctypes.windll.psapi.GetProcessMemoryInfo(process, ctypes.byref(counters), counters.cb):
            return None
    except (AttributeError, OSError):
        return None
    return counters.PeakWorkingSetSize / 2**20


class RunStats:
    """Frames, physics steps and what they cost, counted over a run.

    Call `frame()` once per frame and add to `steps` per physics step; `clock`
    (seconds, perf_counter) and `cpu` (cpu_s) may be fakes in tests.
    """

    def __init__(self, clock: Callable[[], float] = time.perf_counter, cpu: Callable[[], float] = cpu_s) -> None:
        self.clock, self.cpu = clock, cpu
        self.frames = 0
        self.steps = 0
        self._frame_s = array("d")  # wall-clock time between frames: 8 bytes each, 3.5 MB for 2 h at 60 fps
        self._last: float | None = None
        self._cpu0 = cpu()

    def frame(self, idle: bool = False) -> None:
        """Count a frame that has just been drawn; `idle`: it came at the idle loop's pace (its wait not timed)."""
        now = self.clock()
        if self._last is not None and not idle:
            self._frame_s.append(now - self._last)
        self._last = now
        self.frames += 1

    def fps(self) -> tuple[float, float] | None:
        """(median, p5) frames per second, or None before two frames."""
        if not self._frame_s:
            return None
        median_s, p95_s = np.percentile(np.frombuffer(self._frame_s, dtype=np.float64), [50, 95])
        return 1.0 / max(median_s, 1e-9), 1.0 / max(p95_s, 1e-9)

    def line(self) -> str:
        """`stats: frames F, fps median M p5 P, steps S, cpu C s, peak memory R MB`."""
        fps = self.fps()
        rate = "median n/a p5 n/a" if fps is None else f"median {fps[0]:.1f} p5 {fps[1]:.1f}"
        peak = peak_memory_mb()
        memory = "n/a" if peak is None else f"{peak:.0f} MB"
        cpu = self.cpu() - self._cpu0
        return f"stats: frames {self.frames}, fps {rate}, steps {self.steps}, cpu {cpu:.1f} s, peak memory {memory}"
