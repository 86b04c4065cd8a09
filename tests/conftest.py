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
