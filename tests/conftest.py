"""Test set-up: every test runs headless unless it asks for a real X display."""

import os

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")


import pytest  # noqa: E402  (after the SDL settings above, which must come first)


@pytest.fixture(scope="session")
def demos():
    """The built-in demos by key, loaded once."""
    from airtable.app.demo_loader import BUILTIN_DIR, discover

    found, errors = discover([BUILTIN_DIR])
    assert not errors
    return found


WAIT_S = 5.0


def wait_until(condition, timeout_s: float = WAIT_S, what: str = "condition"):
    """Poll `condition` until it returns something truthy, and return that; fail after
    `timeout_s` (generous: a wait is a bound, never a measurement)."""
    import time

    deadline = time.monotonic() + timeout_s
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout_s} s waiting for {what}")
        time.sleep(0.005)
