"""The "cpu" section of `make bench`: what a still table costs a laptop.

A teacher's laptop on battery, or one projecting all lesson, should stay quiet
while nothing moves. This section runs the real programs under a private Xvfb
display (software rendering: a real screen costs less) and reads each
process's CPU time from /proc over a 10 s window (after 2 s of start-up):

- the teacher's app with its server on and no students, on a still table
  (demo 2 before the cue moves) and paused;
- a student's client (`airtable-client`) joined to a still table.

Run alone with `python -m bench --only cpu`; `--quick` uses 3 s windows.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

from airtable.processes import stop_process
from bench import ROOT

TARGETS = {"app": 20.0, "client": 15.0}  # most per cent of one core while still
WARM_UP_S = 2.0
READY_TIMEOUT_S = 30.0


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of process `pid` (all its threads) so far, from /proc."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def start_xvfb(size: str = "1280x720") -> tuple[subprocess.Popen, str]:
    """A private Xvfb of `size` (WxH) on a display number it picks itself; returns it and ':N'."""
    read_fd, write_fd = os.pipe()
    xvfb = subprocess.Popen(
        # -noreset: a reset when the last client leaves would drop a client that is still connecting
        ["Xvfb", "-displayfd", str(write_fd), "-screen", "0", f"{size}x24", "-nolisten", "tcp", "-noreset"],
        pass_fds=(write_fd,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(write_fd)
    with os.fdopen(read_fd) as pipe:
        number = pipe.readline().strip()
    if not number:
        xvfb.kill()
        raise RuntimeError("Xvfb did not start")
    return xvfb, f":{number}"


def measure(cmd: list[str], env: dict[str, str], window_s: float) -> float:
    """Start `cmd`, wait for its first line of output, warm up, then its CPU % over `window_s`."""
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, cwd=ROOT)
    try:
        if not proc.stdout.readline():
            raise RuntimeError(f"{' '.join(cmd[2:])} exited before it was ready")
        time.sleep(WARM_UP_S)
        cpu0, t0 = cpu_seconds(proc.pid), time.monotonic()
        time.sleep(window_s)
        cpu1, t1 = cpu_seconds(proc.pid), time.monotonic()
        return 100.0 * (cpu1 - cpu0) / (t1 - t0)
    finally:
        stop_process(proc)


def _child_app(how: str) -> None:
    """`python -m bench.cpu still|paused|server`: the app with its server on, until killed."""
    from airtable.app.app import App
    from airtable.app.demo_loader import BUILTIN_DIR, DemoShelf
    from airtable.app.window import prefer_plain_framebuffer
    from airtable.net.server import GameServer

    if how != "server":
        prefer_plain_framebuffer()  # as the app's own entry point does (cli.main)
    server = GameServer(host="127.0.0.1", port=0)
    server.start()
    app = App(DemoShelf([BUILTIN_DIR]), demo_key="2", headless=how == "server", server=server)
    app.paused = how == "paused"
    print(server.port, flush=True)
    try:
        app.run()
    finally:
        server.stop()


def cpu_section(args: argparse.Namespace) -> bool:
    """CPU per cent of one core for the app and a client on a still table; True if within the targets."""
    window_s = 3.0 if args.quick else 10.0
    print(f"cpu: process CPU time over {window_s:g} s under Xvfb 1280x720 (software rendering), no students")
    if shutil.which("Xvfb") is None or not Path("/proc/self/stat").exists():
        print("  skipped: needs Linux and Xvfb (apt install xvfb)\n")
        return True
    xvfb, display = start_xvfb()
    env = {**os.environ, "DISPLAY": display, "SDL_VIDEODRIVER": "x11", "PYGAME_HIDE_SUPPORT_PROMPT": "1"}
    me = [sys.executable, "-m", "bench.cpu"]
    ok = True
    try:
        rows = [
            ("app, still table (demo 2), server on", "app", me + ["still"]),
            ("app, paused, server on", "app", me + ["paused"]),
        ]
        for label, kind, cmd in rows:
            ok &= _report(label, measure(cmd, env, window_s), TARGETS[kind])
        ok &= _report("student client, still table", _client_share(env, window_s), TARGETS["client"])
    finally:
        stop_process(xvfb)
    print()
    return ok


def _client_share(env: dict[str, str], window_s: float) -> float:
    """A headless table with its server (still), and one windowed client joined to it."""
    server = subprocess.Popen(
        [sys.executable, "-m", "bench.cpu", "server"], env=env, stdout=subprocess.PIPE, text=True, cwd=ROOT
    )
    try:
        port = server.stdout.readline().strip()
        client = [sys.executable, "-m", "airtable.client_cli", f"127.0.0.1:{port}", "--name", "bench"]
        return measure(client, env, window_s)
    finally:
        stop_process(server)


def _report(label: str, share: float, target: float) -> bool:
    ok = share <= target
    print(f"  {label:<40} {share:5.1f} %   target <= {target:g} %   {'PASS' if ok else 'MISS'}")
    return ok


if __name__ == "__main__":
    _child_app(sys.argv[1])
