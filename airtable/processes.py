"""Stopping the helper processes the benchmarks and the link harness start (Xvfb, a window manager, a server)."""

from __future__ import annotations

import subprocess


def stop_process(proc: subprocess.Popen, timeout_s: float = 10.0) -> None:
    """Ask `proc` to end, wait up to timeout_s, then kill it: never left running, never waited on forever."""
    proc.terminate()
    try:
        proc.wait(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(timeout=timeout_s)
