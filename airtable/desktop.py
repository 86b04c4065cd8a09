"""What both windows ask of the desktop before pygame starts: a quiet import and the app's own name.

Without a name of its own SDL gives an X11 window the class of the script that started it,
so the taskbar and Alt+Tab said "__main__.py". No pygame here: this runs before it is imported.
"""

from __future__ import annotations

import os

APP_NAME = "Air Table"  # the taskbar's name for both windows (X11's WM_CLASS)
APP_ID = "airtable"  # Wayland's app id (a name without spaces)


def prepare_for_pygame() -> None:
    """Set (unless the user already has) the environment pygame and SDL read when they start."""
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")  # the app's first line is its own, not pygame's banner
    os.environ.setdefault("SDL_VIDEO_X11_WMCLASS", APP_NAME)
    os.environ.setdefault("SDL_VIDEO_WAYLAND_WMCLASS", APP_ID)
