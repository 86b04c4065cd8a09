"""One real window under Xvfb, driven with xdotool as a person would drive it."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time

import numpy as np
import pygame
import pytest

pytestmark = [
    pytest.mark.xvfb,
    pytest.mark.skipif(
        not (shutil.which("Xvfb") and shutil.which("xdotool") and sys.platform.startswith("linux")),
        reason="needs Xvfb and xdotool (apt-get install xvfb xdotool)",
    ),
]
ORANGE = (255, 165, 0)


def wait_for(condition, timeout_s: float = 15.0, what: str = "condition"):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}")


@pytest.fixture
def display():
    proc = subprocess.Popen(
        ["Xvfb", "-displayfd", "1", "-screen", "0", "1024x900x24", "-nolisten", "tcp"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
    )
    try:
        number = proc.stdout.readline().decode().strip()
        assert number, "Xvfb did not start"
        yield f":{number}"
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def xdotool(display: str, *args: str) -> str:
    out = subprocess.run(
        ["xdotool", *args], env={**os.environ, "DISPLAY": display}, capture_output=True, text=True, timeout=20
    )
    return out.stdout.strip()


def find_window(display: str) -> str | None:
    # `search --name` misses SDL's windows on some xdotool builds; list them all and match the title.
    for wid in xdotool(display, "search", "--class", "").split():
        if "Air Table" in xdotool(display, "getwindowname", wid):
            return wid
    return None


def test_demo_key_and_mouse_drag_in_a_real_window(display, tmp_path):
    shot = tmp_path / "final.png"
    env = {**os.environ, "DISPLAY": display, "SDL_VIDEODRIVER": "x11"}
    app = subprocess.Popen(
        [sys.executable, "-m", "airtable", "--no-server", "--demo", "2", "--seconds", "60", "--screenshot", str(shot)],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    try:
        wid = wait_for(lambda: find_window(display), what="the window")
        xdotool(display, "windowfocus", "--sync", wid)
        assert "Demo 2" in xdotool(display, "getwindowname", wid)
        xdotool(display, "key", "3")
        wait_for(lambda: "Demo 3" in xdotool(display, "getwindowname", wid), what="demo 3 to start")
        # Demo 3's orange puck sits at (4.5, 4.5) m: pixel (405, 383) of the 900 x 788 window.
        xdotool(display, "mousemove", "--window", wid, "405", "383")
        time.sleep(0.3)  # let SDL see the pointer arrive before the press
        xdotool(display, "mousedown", "1")
        time.sleep(0.3)
        xdotool(display, "mousemove", "--window", wid, "700", "650")
        time.sleep(2.0)  # the string pulls the puck over; the final check does not depend on how far
        xdotool(display, "mouseup", "1")
        xdotool(display, "key", "space")  # pause, so the puck stays where the string left it
        time.sleep(0.3)
        xdotool(display, "key", "Escape")
        assert app.wait(timeout=20) == 0, app.stderr.read().decode()
    finally:
        if app.poll() is None:
            app.kill()
            app.wait()
    pygame.display.init()
    image = pygame.surfarray.array3d(pygame.image.load(str(shot)))
    orange = np.argwhere(np.all(image == ORANGE, axis=2))
    assert len(orange) > 20
    centre = orange.mean(axis=0)
    # It was pulled toward the cursor: down and to the right of where it started.
    assert centre[0] > 405 + 50 and centre[1] > 383 + 50
