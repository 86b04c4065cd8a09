"""The "window" section of `make bench`: the whole app, 10000 pucks, a real 1920x1080 window.

It starts a private Xvfb of 1920x1080 with the openbox window manager, runs
the teacher's app full screen with `--stats` for a few seconds on two scenes of
10000 pucks: the burst (demo 0's last variation: collisions off, what drawing
costs) and the gas (demo Shift+0's last variation: every collision resolved,
dt 1/240), and reports the frame rate it printed: the median and p5 (95 % of
frames are faster), against 60 fps, and the share of real time the physics
kept (a frame's physics stops at its budget: a table too heavy for real time
runs in slow motion, app.PHYSICS_SHARE). The loop caps the rate at the
display's (60 Hz here), so 60 is the most it can show; the CPU time per frame
says how much room is left under that.

Xvfb has no GPU, so this is a laptop without one: everything, OpenGL
included, runs on the processor. A third run of the burst with SDL's OpenGL
framebuffer (`SDL_FRAMEBUFFER_ACCELERATION=1`, what SDL does unless told
otherwise) shows why the app asks for the plain one on X11 (see
window.prefer_plain_framebuffer).

Run alone with `python -m bench --only window`; `--quick` runs 3 s
and skips the OpenGL comparison.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import time

from airtable.processes import stop_process
from bench.cpu import start_xvfb

SCREEN = "1920x1080"
PUCKS = 10000
TARGET_FPS = 60.0
SLACK = 0.99  # the loop aims at exactly the display's 60 Hz: 1 % for timer jitter
STATS = re.compile(r"stats: frames (\d+), fps median (\S+) p5 (\S+), steps (\d+), cpu (\S+) s")


def window_section(args: argparse.Namespace) -> bool:
    """Frame rate of the app with 10000 pucks in a 1920x1080 window; True if the median is 60 fps."""
    seconds = 3.0 if args.quick else 6.0
    print(
        f"window: the app full screen at {SCREEN} under Xvfb + openbox (no GPU), {PUCKS} pucks, {seconds:g} s a scene"
    )
    if shutil.which("Xvfb") is None:
        print("  skipped: needs Xvfb (apt install xvfb)\n")
        return True
    print(f"  target: median >= {TARGET_FPS:g} fps (the loop caps at the display's rate) with the physics in real time")
    xvfb, display = start_xvfb(SCREEN)
    wm = _start_openbox(display)
    env = {**os.environ, "DISPLAY": display, "SDL_VIDEODRIVER": "x11", "PYGAME_HIDE_SUPPORT_PROMPT": "1"}
    env.pop("SDL_FRAMEBUFFER_ACCELERATION", None)
    try:
        runs = [("burst, plain framebuffer (the app's)", env, "0"), ("gas, every collision", env, "0p")]
        if not args.quick:
            runs.append(("burst, OpenGL framebuffer (SDL's)", {**env, "SDL_FRAMEBUFFER_ACCELERATION": "1"}, "0"))
        ok = True
        for label, run_env, demo in runs:
            result = _run_app(run_env, seconds, demo)
            ok = _report(label, result, checked="OpenGL" not in label) and ok
    finally:
        for proc in (wm, xvfb):
            if proc is not None:
                stop_process(proc)
    print()
    return ok


def _start_openbox(display: str) -> subprocess.Popen | None:
    """openbox on `display`, once it manages the screen (None if it is not installed)."""
    if shutil.which("openbox") is None:
        print("  (openbox is not installed: no window manager)")
        return None
    env = {**os.environ, "DISPLAY": display}
    wm = subprocess.Popen(["openbox"], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 10.0
    while shutil.which("xprop") and time.monotonic() < deadline:  # a window manager sets this on the root
        check = subprocess.run(["xprop", "-root", "_NET_SUPPORTING_WM_CHECK"], env=env, capture_output=True, text=True)
        if "window id" in check.stdout:
            break
        time.sleep(0.05)
    return wm


def _variation(demo: str) -> tuple[int, float]:
    """(the demo's variation with PUCKS pucks, as --variation counts from 1; its dt)."""
    from airtable.app.demo_loader import BUILTIN_DIR, discover

    demos, _ = discover([BUILTIN_DIR])
    names = demos[demo].variations  # "n = 10000", "10000 pucks"
    return next(k for k, name in enumerate(names) if str(PUCKS) in name.split()) + 1, demos[demo].dt_s


def _run_app(env: dict[str, str], seconds: float, demo: str) -> tuple[int, float, float, float, float] | str:
    """(frames, fps median, fps p5, CPU ms per frame, share of real time stepped) from the app's --stats
    line, or why there is none."""
    variation, dt_s = _variation(demo)
    cmd = [sys.executable, "-m", "airtable", "--no-server", "--fullscreen", "--demo", demo]
    cmd += ["--variation", str(variation), "--seconds", str(seconds), "--stats"]
    try:
        out = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=seconds + 60)
    except subprocess.TimeoutExpired:
        return "the app did not finish"
    match = STATS.search(out.stdout)
    if out.returncode != 0 or match is None:
        return f"the app failed: {(out.stderr.strip().splitlines() or ['no output'])[-1]}"
    frames, median, p5, steps, cpu = match.groups()
    if median == "n/a":
        return "the app drew fewer than two frames"
    share = int(steps) * dt_s / seconds
    return int(frames), float(median), float(p5), 1e3 * float(cpu) / max(1, int(frames)), share


def _report(label: str, result, checked: bool) -> bool:
    if isinstance(result, str):
        print(f"  {label:<38} {result}   MISS")
        return False
    frames, median, p5, cpu_ms, share = result
    ok = median >= SLACK * TARGET_FPS and share >= SLACK
    verdict = ("PASS" if ok else "MISS") if checked else "(for comparison)"
    rates = f"fps median {median:5.1f}  p5 {p5:5.1f}  physics {share:4.0%} of real time"
    print(f"  {label:<38} {rates}  {frames:4d} frames  cpu {cpu_ms:5.1f} ms/frame  {verdict}")
    return ok or not checked
