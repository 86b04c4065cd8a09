"""One real window under Xvfb, driven with xdotool as a person would drive it."""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import sys
import time

import numpy as np
import pygame
import pytest
from conftest import wait_until

pytestmark = [
    pytest.mark.xvfb,
    pytest.mark.skipif(
        not (all(map(shutil.which, ("Xvfb", "xdotool", "xwininfo"))) and sys.platform.startswith("linux")),
        reason="needs Xvfb, xdotool and xwininfo (apt-get install xvfb xdotool x11-utils)",
    ),
]
ORANGE = (255, 165, 0)


def wait_for(condition, what: str = "condition"):
    """Wait on X (each poll runs a tool): a longer bound and a slower poll than the in-process waits."""
    return wait_until(condition, timeout_s=60.0, what=what, poll_s=0.1)  # a bound: a busy machine starts slowly


@pytest.fixture
def display():
    # -noreset: without it Xvfb resets whenever its last client leaves, and a reset drops a client still
    # connecting: an xwininfo poll ending as the app connects failed the app's XOpenDisplay ("x11 not
    # available") 106 times in 3000 here, 0 with -noreset.
    proc = subprocess.Popen(
        ["Xvfb", "-displayfd", "1", "-screen", "0", "1024x900x24", "-nolisten", "tcp", "-noreset"],
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


def xwininfo(display: str, *args: str) -> str:
    env = {**os.environ, "DISPLAY": display}
    return subprocess.run(["xwininfo", *args], env=env, capture_output=True, text=True, timeout=20).stdout


def find_window(display: str, title: str = "Air Table") -> str | None:
    """The window once it is on screen: keys sent to a window not yet mapped are lost."""
    # `xdotool search --name` misses SDL's windows on some builds; xwininfo lists them all, as
    # `0x200002 "Air Table - Demo 1": ("Air Table" "Air Table")`: the title, then the class,
    # which says "Air Table" before the app has set the title.
    # A window of an app that just quit, or one SDL has not mapped, may come first: look on past it.
    for line in xwininfo(display, "-root", "-tree").splitlines():
        if line.split('": (')[0].strip().split(" ", 1)[-1].startswith(f'"{title}'):
            wid = str(int(line.split()[0], 16))
            if "IsViewable" in xwininfo(display, "-id", wid):
                return wid
    return None


def window_place(display: str, wid: str) -> tuple[int, int] | None:
    """Where the window's top-left corner is on the screen now (None once it is gone)."""
    lines = xwininfo(display, "-id", wid).splitlines()
    at = dict(line.strip().split(": ", 1) for line in lines if line.strip().startswith("Absolute upper-left"))
    return (int(at["Absolute upper-left X"]), int(at["Absolute upper-left Y"])) if len(at) == 2 else None


def window_size(display: str, wid: str) -> tuple[int, int] | None:
    """The window's size as X has it now (None once it is gone)."""
    lines = xwininfo(display, "-id", wid).splitlines()
    sizes = dict(line.strip().split(": ", 1) for line in lines if line.strip().startswith(("Width", "Height")))
    return (int(sizes["Width"]), int(sizes["Height"])) if len(sizes) == 2 else None


def orange_centre(path) -> np.ndarray | None:
    """Where the orange puck is in a screenshot (None while the file is missing or half written)."""
    try:
        image = pygame.surfarray.array3d(pygame.image.load(str(path)))
    except (pygame.error, FileNotFoundError):
        return None
    orange = np.argwhere(np.all(image == ORANGE, axis=2))
    return orange.mean(axis=0) if len(orange) > 20 else None


def sized_window(display: str, size: tuple[int, int]) -> str | None:
    """The app's window once X has it at `size` (SDL may make a new window when it goes fullscreen)."""
    wid = find_window(display)
    return wid if wid and window_size(display, wid) == size else None


def key_taken(display: str, wid: str, key: str) -> bool:
    """Focus the window and press `key`; True, so a wait can repeat a key whose effect it then checks."""
    xdotool(display, "windowfocus", "--sync", wid)
    xdotool(display, "key", key)
    return True


@contextlib.contextmanager
def running(display: str, args: list[str], cwd=None):
    """A process on the display and the id of its window; killed if the test leaves it running."""
    env = {**os.environ, "DISPLAY": display, "SDL_VIDEODRIVER": "x11"}
    proc = subprocess.Popen(args, env=env, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:

        def seen() -> str | None:  # the window; or, if the process ended first, that (not a 60 s wait)
            return find_window(display) or ("exited" if proc.poll() is not None else None)

        wid = wait_for(seen, what=f"the window of {args[-1]!r} on {display}")
        if wid == "exited":
            pytest.fail(f"the process ended with {proc.returncode} before its window showed: {proc.stderr.read()!r}")
        yield proc, wid
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def demo_2(shot) -> list[str]:
    """The app on demo 2, which saves a screenshot to `shot` when it quits."""
    return [
        sys.executable,
        "-m",
        "airtable",
        "--no-server",
        "--demo",
        "2",
        "--seconds",
        "60",
        "--screenshot",
        str(shot),
    ]


def quit_with_escape(display: str, wid: str, proc: subprocess.Popen) -> None:
    """Esc asks, Esc again quits (with nothing open over the table), each after a person's pause (a
    burst of Escs answers nothing); pressed until it quits, as a key sent while a window settles
    into fullscreen can be lost."""
    from airtable.app.overlays import ESC_PAUSE_S

    def escape_after_a_pause() -> bool:
        key_taken(display, wid, "Escape")
        time.sleep(ESC_PAUSE_S)
        return proc.poll() is not None

    wait_for(escape_after_a_pause, what="the app to quit")
    assert proc.wait(timeout=20) == 0, proc.stderr.read().decode()


WALL = (255, 69, 0)
TABLE_ASPECT = 10.0 / 8.7556


def wall_columns(image: np.ndarray, row: int) -> np.ndarray:
    """The x of every wall-coloured pixel on one row of a screenshot."""
    return np.flatnonzero(np.all(image[:, row] == WALL, axis=1))


def laid_out(size: tuple[int, int]):
    """A headless window of `size` laid out as the app lays out its own: the table between the
    text's places (the top band or the side margins) and the status bar."""
    from airtable.app.environment import Environment
    from airtable.app.window import GameWindow

    return GameWindow(Environment(size, width_m=10.0, height_m=8.7556), headless=True)


def status_bar_px(size: tuple[int, int]) -> int:
    """The status bar's height in a window of `size` (the app fits the table above it)."""
    return laid_out(size).status_bar_px


def assert_table_fills_the_height(shot, size: tuple[int, int]) -> np.ndarray:
    """The screenshot is `size`, and the table fills the height the text leaves it, centred,
    with its aspect kept."""
    pygame.display.init()
    image = pygame.surfarray.array3d(pygame.image.load(str(shot)))
    (w, h) = size
    assert image.shape[:2] == size
    left, top, width, height = laid_out(size).env.table_rect_px
    assert width == pytest.approx(height * TABLE_ASPECT)
    xs = wall_columns(image, int(top + height / 2))
    assert abs(xs.min() - left) <= 2 and abs(xs.max() - (left + width - 1)) <= 2
    return image


def test_demo_key_and_mouse_drag_in_a_real_window(display, tmp_path):
    shot = tmp_path / "final.png"
    pygame.display.init()

    def pulled_far_enough():
        # A screenshot now (F12), then the newest one: has the string pulled the puck down and right?
        xdotool(display, "key", "F12")
        shots = sorted((tmp_path / "screenshots").glob("*.png"), key=lambda p: p.stat().st_mtime_ns)
        centre = orange_centre(shots[-1]) if shots else None
        return centre is not None and centre[0] > start[0] + 50 and centre[1] > start[1] + 50

    start = [0, 0]
    with running(display, demo_2(shot), cwd=tmp_path) as (app, wid):  # F12 saves into ./screenshots
        xdotool(display, "windowfocus", "--sync", wid)
        # (On a busy machine the window can be found before the app names it: "Air Table" alone.)
        wait_for(lambda: "Demo 2" in xdotool(display, "getwindowname", wid), what="the window's name")
        xdotool(display, "key", "3")
        wait_for(lambda: "Demo 3" in xdotool(display, "getwindowname", wid), what="demo 3 to start")
        # Demo 3's orange puck sits at (4.5, 4.5) m: where the window's layout puts it.
        # X delivers the move before the press, and SDL reads them in that order: no wait needed between.
        x, y = (int(round(v)) for v in laid_out(window_size(display, wid)).env.to_screen(np.array([4.5, 4.5])))
        start[:] = (x, y)
        xdotool(display, "mousemove", "--window", wid, "--sync", str(x), str(y))
        xdotool(display, "mousedown", "1")
        xdotool(display, "mousemove", "--window", wid, "--sync", "700", "650")
        wait_for(pulled_far_enough, what="the string to pull the puck toward the cursor")
        xdotool(display, "mouseup", "1")
        xdotool(display, "key", "space")  # pause, so the puck stays where the string left it
        quit_with_escape(display, wid, app)
    centre = orange_centre(shot)
    # It was pulled toward the cursor: down and to the right of where it started.
    assert centre is not None and centre[0] > start[0] + 50 and centre[1] > start[1] + 50


def test_the_table_follows_a_resize_of_the_window(display, tmp_path):
    shot = tmp_path / "resized.png"
    with running(display, demo_2(shot)) as (app, wid):
        xdotool(display, "windowsize", "--sync", wid, "1000", "500")
        wait_for(lambda: window_size(display, wid) == (1000, 500), what="the new size")
        quit_with_escape(display, wid, app)
    # The table, 500 px less the status bar tall, is centred: walls near x = 230 and 769, not at the old edges.
    image = assert_table_fills_the_height(shot, (1000, 500))
    ys = np.flatnonzero(np.all(image[500] == WALL, axis=1))
    bottom = 499 - status_bar_px((1000, 500))
    assert ys.min() <= 2 and abs(ys.max() - bottom) <= 2  # the top wall at the window's edge, the floor above the bar


FULLSCREEN_DRIVER = """
import sys, numpy as np, pygame
from airtable.app.environment import Environment
from airtable.model.scene import Scene
from airtable.app.window import GameWindow, prefer_plain_framebuffer
prefer_plain_framebuffer()  # as the app's entry points do (no OpenGL framebuffer on X11)
env = Environment(width_m=10.0, height_m=8.7556)
win = GameWindow(env, caption="Air Table - fullscreen test", size_px=(640, 480))
scene = Scene(10.0, 8.7556, np.array([[5.0, 4.4]]), np.array([0.5]), np.array([[255, 165, 0]], np.uint8))
clock = pygame.time.Clock()
for frame in range(1200):
    for event in pygame.event.get():
        if event.type == pygame.KEYDOWN and event.key == pygame.K_F12:
            win.save_screenshot(sys.argv[1])
        elif event.type == pygame.KEYDOWN and event.key == pygame.K_ESCAPE:
            print("size", *win.surface.get_size(), int(win.fullscreen), flush=True)
            sys.exit(0)
        win.handle_event(event)
    win.draw(scene)
    win.present()
    clock.tick(60)
sys.exit(3)
"""


def test_f11_toggles_desktop_fullscreen_and_back(display, tmp_path):
    shot = tmp_path / "full.png"
    with running(display, [sys.executable, "-c", FULLSCREEN_DRIVER, str(shot)]) as (proc, wid):
        key_taken(display, wid, "F11")
        wid = wait_for(lambda: sized_window(display, (1024, 900)), what="the fullscreen window")  # may be a new one
        # SDL takes keys again only once it has settled into fullscreen: a screenshot (F12) may be asked
        # for again until one is written, which also tells that the next key will be seen.
        wait_for(lambda: key_taken(display, wid, "F12") and shot.exists(), what="the screenshot")
        xdotool(display, "key", "F11")  # and back to the window
        wid = wait_for(lambda: sized_window(display, (640, 480)), what="the window again")
        wait_for(lambda: key_taken(display, wid, "Escape") and proc.poll() is not None, what="the driver to quit")
        assert proc.wait(timeout=20) == 0, proc.stderr.read().decode()
        assert proc.stdout.read().decode().split() == ["size", "640", "480", "0"]
    # The table fills the height of the whole 1024 x 900 Xvfb screen, centred: side walls at x = 30 and 993.
    assert_table_fills_the_height(shot, (1024, 900))


def test_f11_in_the_app_fills_the_screen(display, tmp_path):
    shot = tmp_path / "app_full.png"
    with running(display, demo_2(shot)) as (app, wid):
        key_taken(display, wid, "F11")
        wid = wait_for(lambda: sized_window(display, (1024, 900)), what="the fullscreen window")
        quit_with_escape(display, wid, app)
    assert_table_fills_the_height(shot, (1024, 900))


@pytest.mark.skipif(not shutil.which("openbox"), reason="needs a window manager (apt-get install openbox)")
def test_f11_twice_under_a_window_manager_brings_back_the_window(display, tmp_path):
    # User tests: under a window manager the window came back at the desktop's size, partly off screen,
    # and a title bar lower each time.
    wm = subprocess.Popen(
        ["openbox"], env={**os.environ, "DISPLAY": display}, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    try:
        with running(display, demo_2(tmp_path / "shot.png"), cwd=tmp_path) as (app, wid):
            before = wait_for(lambda: window_size(display, wid), what="the window's size")
            assert before != (1024, 900)
            place = window_place(display, wid)
            key_taken(display, wid, "F11")
            wid = wait_for(lambda: sized_window(display, (1024, 900)), what="the fullscreen window")
            # SDL takes keys again once it has settled into fullscreen: a screenshot (F12) tells.
            shots = tmp_path / "screenshots"
            wait_for(lambda: key_taken(display, wid, "F12") and any(shots.glob("*.png")), what="a screenshot")
            xdotool(display, "key", "F11")
            wid = wait_for(lambda: sized_window(display, before), what="the window at its size again")
            for _ in range(10):  # and it stays so once the window manager is done
                assert window_size(display, wid) == before
            # Where it was, too: it came back a title bar lower each time, then partly off the screen.
            assert window_place(display, wid) == place
            quit_with_escape(display, wid, app)
    finally:
        wm.terminate()
        wm.wait(timeout=10)


def test_on_x11_the_window_keeps_its_pixels_in_the_plain_framebuffer(display):
    # The entry points ask for it on X11 (a flip of software OpenGL costs 11-35 ms at 1920x1080); a user's value stays.
    code = (
        "import os; from airtable.app.window import prefer_plain_framebuffer as p; "
        "print(os.environ.get('SDL_FRAMEBUFFER_ACCELERATION'), p(), os.environ.get('SDL_FRAMEBUFFER_ACCELERATION'))"
    )
    env = {k: v for k, v in os.environ.items() if k != "SDL_FRAMEBUFFER_ACCELERATION"}
    env.update(DISPLAY=display, SDL_VIDEODRIVER="x11")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert out.stdout.split() == ["None", "True", "0"], out.stderr
    env["SDL_FRAMEBUFFER_ACCELERATION"] = "1"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert out.stdout.split() == ["1", "False", "1"], out.stderr


def window_class(display: str, wid: str) -> str:
    """X11's WM_CLASS of a window: what a taskbar and Alt+Tab call it."""
    env = {**os.environ, "DISPLAY": display}
    out = subprocess.run(["xprop", "-id", wid, "WM_CLASS"], env=env, capture_output=True, text=True, timeout=20)
    return out.stdout.strip()


@pytest.mark.skipif(shutil.which("xprop") is None, reason="needs xprop (apt-get install x11-utils)")
def test_the_taskbar_calls_the_teachers_and_the_students_window_air_table(display):
    from airtable.net.server import GameServer

    teacher = [sys.executable, "-m", "airtable", "--no-server", "--seconds", "60"]
    with running(display, teacher) as (_, wid):
        assert window_class(display, wid) == 'WM_CLASS(STRING) = "Air Table", "Air Table"'
    # The killed teacher's window can outlive it a moment; the student's is the next one found.
    wait_for(lambda: find_window(display) is None, what="the teacher's window to go")
    server = GameServer(host="127.0.0.1", port=0)
    server.start()
    try:
        student = [sys.executable, "-c", "import sys; from airtable.client_cli import main; sys.exit(main())"]
        with running(display, [*student, f"127.0.0.1:{server.port}", "--seconds", "60"]) as (_, wid):
            assert window_class(display, wid) == 'WM_CLASS(STRING) = "Air Table", "Air Table"'
    finally:
        server.stop()
