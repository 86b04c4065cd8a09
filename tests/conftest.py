"""Test set-up: every test runs headless unless it asks for a real X display; shared helpers."""

import math
import os
import sys
from pathlib import Path

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import contextlib  # noqa: E402  (after the SDL settings above, which must come first)
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402

import pytest  # noqa: E402

# The benchmarks and tools sit beside the package (bench/, tools/), not in it: the tests of
# them and the scenes they share import them from the checkout's top folder.
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

FRAME_S = 1 / 60  # one frame of the app in tests: simulated time, never the clock
WAIT_S = 5.0  # the bound on every wait for a condition (generous: never a measurement)


@pytest.fixture(autouse=True)
def _in_a_folder_of_its_own(tmp_path, monkeypatch):
    """Every test runs in its own empty folder, so what the app reads or writes at relative
    paths (./my_demos, screenshots, CSV exports) never meets the checkout's files."""
    monkeypatch.chdir(tmp_path)


@pytest.fixture(scope="session", autouse=True)
def temporary_files_under_pytests_folder(tmp_path_factory):
    """The app's own temporary files (the recording the export key copies) go under pytest's temporary
    folder, in this process and in the processes it starts."""
    import tempfile

    folder = str(tmp_path_factory.mktemp("tempfiles"))
    old, old_env = tempfile.tempdir, os.environ.get("TMPDIR")
    tempfile.tempdir, os.environ["TMPDIR"] = folder, folder
    yield
    tempfile.tempdir = old
    if old_env is None:
        os.environ.pop("TMPDIR", None)
    else:
        os.environ["TMPDIR"] = old_env


@pytest.fixture(scope="session", autouse=True)
def config_folder_under_pytests_folder(tmp_path_factory):
    """The config folder (the teacher's seat key, the students' seat tokens: identity.config_dir) is one
    under pytest's temporary folder, in this process and in the processes it starts."""
    folder = str(tmp_path_factory.mktemp("config"))
    saved = {name: os.environ.get(name) for name in ("XDG_CONFIG_HOME", "APPDATA")}
    os.environ["XDG_CONFIG_HOME"] = os.environ["APPDATA"] = folder
    yield
    for name, value in saved.items():
        if value is None:
            os.environ.pop(name, None)
        else:
            os.environ[name] = value


@pytest.fixture(scope="session")
def demos():
    """The built-in demos by key, loaded once."""
    from airtable.app.demo_loader import BUILTIN_DIR, discover

    found, errors = discover([BUILTIN_DIR])
    assert not errors
    return found


@contextlib.contextmanager
def teacher_and_student(demos, demo_key: str):
    """A headless teacher's App on `demo_key`, serving on a free port of 127.0.0.1, and one student
    (Ann) joined over a real socket: yields (teacher, net). Closes the socket and the server after."""
    import pygame

    from airtable.app.app import App
    from airtable.net.player import NetPlayer
    from airtable.net.server import GameServer

    server = GameServer(host="127.0.0.1", port=0)
    server.start()
    net = None
    try:  # the server stops even if the App or the join fails
        teacher = App(demos, demo_key=demo_key, headless=True, server=server)
        pygame.event.clear()
        net = NetPlayer("127.0.0.1", server.port, name="Ann", max_backoff_s=0.3)
        net.connect()
        yield teacher, net
    finally:
        if net is not None:
            net.close()
        server.stop()
        pygame.event.clear()


def post_key(key: int, down: bool = True, mod: int = 0, unicode: str = "") -> None:
    """Post a real KEYDOWN (or KEYUP) event, as the keyboard would."""
    import pygame

    kind = pygame.KEYDOWN if down else pygame.KEYUP
    pygame.event.post(pygame.event.Event(kind, key=key, mod=mod, unicode=unicode, scancode=0))


def press(app, key: int, mod: int = 0, frames: int = 1, unicode: str = "") -> None:
    """Press and release `key`, then run `frames` frames of the app."""
    post_key(key, mod=mod, unicode=unicode)
    post_key(key, down=False, mod=mod, unicode=unicode)
    for _ in range(frames):
        app.frame(FRAME_S)


def escape_again(app) -> None:
    """Esc as a person answers the quit question: after a pause (a burst of Escs answers nothing)."""
    import pygame

    from airtable.app.overlays import ESC_PAUSE_S

    for _ in range(math.ceil(ESC_PAUSE_S / FRAME_S)):
        app.frame(FRAME_S)
    press(app, pygame.K_ESCAPE)


def wait_until(
    condition: Callable[[], object], timeout_s: float = WAIT_S, what: str = "condition", poll_s: float = 0.005
) -> object:
    """Poll `condition` every `poll_s` until truthy and return it; fail after `timeout_s` (a bound, not a delay)."""
    deadline = time.monotonic() + timeout_s
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout_s} s waiting for {what}")
        time.sleep(poll_s)


def server_frames(data: bytes) -> list[tuple[int, bytes]]:
    """The (type, payload) frames in bytes a server sent, read as a player reads them (all checks on)."""
    from airtable.net import protocol

    return protocol.FrameReader(protocol.MAX_SERVER_FRAME, sender="the server").feed(data)


def frames_until(app, condition: Callable[[], object], what: str = "condition", max_frames: int | None = None):
    """Run app frames (1/60 s of simulated time each) until `condition()` holds, and return its value.

    Bounded by `max_frames` where the condition depends on the table alone, else by WAIT_S of real time
    (students' sockets take what real time they take, however fast the frames run)."""
    if max_frames is None:

        def step():
            app.frame(FRAME_S)
            return condition()

        return wait_until(step, WAIT_S, what)
    for _ in range(max_frames):
        if value := condition():
            return value
        app.frame(FRAME_S)
    pytest.fail(f"{what} did not happen within {max_frames} frames")
