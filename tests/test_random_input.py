"""Input nobody planned: generated sequences of keys, clicks, drags, wheels, typing and resizes.

Whatever a teacher (or a cat on the keyboard) does, the lesson goes on: no exception, the
app still running, the table still finite, and it still answers F1 afterwards. Found this
way: a window resized to a strip ended the app (test_small_windows.py).
"""

from __future__ import annotations

import numpy as np
import pygame
from conftest import FRAME_S
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from airtable.app.app import App

# Every key a hand may hit but Esc (Esc, a pause, Esc quits on purpose: tests/test_overlays.py) and
# Right (it climbs to the 10000-puck variations: right, but too slow for a test of many frames);
# Ctrl+Q and Ctrl+W quit on purpose too (asking first only if something would be lost): see `key`.
KEYS = (
    *(getattr(pygame, f"K_{c}") for c in "abcdefghijklmnopqrstuvwxyz0123456789"),
    *(getattr(pygame, f"K_F{n}") for n in range(1, 13)),
    pygame.K_TAB, pygame.K_SPACE, pygame.K_COMMA, pygame.K_PERIOD, pygame.K_MINUS, pygame.K_EQUALS,
    pygame.K_LEFTBRACKET, pygame.K_RIGHTBRACKET, pygame.K_PAGEUP, pygame.K_PAGEDOWN, pygame.K_LEFT,
    pygame.K_UP, pygame.K_DOWN, pygame.K_RETURN, pygame.K_BACKSPACE, pygame.K_DELETE,
)  # fmt: skip
MODS = (0, pygame.KMOD_LSHIFT, pygame.KMOD_LCTRL, pygame.KMOD_LALT, pygame.KMOD_LSHIFT | pygame.KMOD_LCTRL)
TEXT = ("a", "Я", "ж", "é", "中", "😀", "\u202e", " ")
SIZES = ((1, 1), (200, 30), (640, 480), (1280, 720), (1920, 1080), (3000, 200))

points = st.tuples(st.integers(-100, 2100), st.integers(-100, 1200))
key = st.builds(
    lambda k, mod, text: [
        pygame.event.Event(pygame.KEYDOWN, key=k, mod=mod, unicode=text, scancode=0),
        pygame.event.Event(pygame.KEYUP, key=k, mod=mod, unicode=text, scancode=0),
    ],
    st.sampled_from(KEYS),
    st.sampled_from(MODS),
    st.sampled_from(("", *TEXT)),
).filter(lambda events: not (events[0].key in (pygame.K_q, pygame.K_w) and events[0].mod & pygame.KMOD_CTRL))
held_key = st.builds(  # pressed in one frame, let go some frames later (zoom, inspect, hands off)
    lambda k: [pygame.event.Event(pygame.KEYDOWN, key=k, mod=0, unicode="", scancode=0)],
    st.sampled_from((pygame.K_h, pygame.K_n, pygame.K_i, pygame.K_LCTRL)),
)
typing = st.builds(lambda text: [pygame.event.Event(pygame.TEXTINPUT, text=text)], st.sampled_from(TEXT))
drag = st.builds(
    lambda button, a, b: [
        pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=a, button=button),
        pygame.event.Event(pygame.MOUSEMOTION, pos=b, rel=(b[0] - a[0], b[1] - a[1]), buttons=(1, 0, 0)),
        pygame.event.Event(pygame.MOUSEBUTTONUP, pos=b, button=button),
    ],
    st.integers(1, 5),
    points,
    points,
)
press_only = st.builds(  # a button pressed and never let go (the release went to another window)
    lambda button, a: [pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=a, button=button)], st.integers(1, 3), points
)
wheel = st.builds(
    lambda y: [pygame.event.Event(pygame.MOUSEWHEEL, x=0, y=y, precise_x=0.0, precise_y=float(y), flipped=False)],
    st.integers(-30, 30),
)
resize = st.builds(
    lambda size: [pygame.event.Event(pygame.VIDEORESIZE, size=size, w=size[0], h=size[1])], st.sampled_from(SIZES)
)
focus = st.just([pygame.event.Event(pygame.WINDOWFOCUSLOST), pygame.event.Event(pygame.WINDOWFOCUSGAINED)])
actions = st.lists(
    st.tuples(
        st.one_of(key, key, key, held_key, typing, drag, press_only, wheel, resize, resize, focus), st.integers(1, 3)
    ),
    min_size=5,
    max_size=40,
)


@settings(max_examples=60, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(demo=st.sampled_from(("1", "2", "4", "5", "6", "9")), steps=actions)
def test_whatever_a_teacher_does_the_lesson_goes_on(demos, demo, steps):
    app = App(demos, demo_key=demo, headless=True)
    pygame.event.clear()
    try:
        for events, frames in steps:
            for event in events:
                pygame.event.post(event)
            for _ in range(frames):
                app.frame(FRAME_S)
            assert app.running
            assert np.isfinite(app.table.pos_m).all() and np.isfinite(app.table.vel_mps).all()
        for k in (pygame.K_h, pygame.K_n, pygame.K_i, pygame.K_LCTRL):  # let go of anything held
            pygame.event.post(pygame.event.Event(pygame.KEYUP, key=k, mod=0, unicode="", scancode=0))
        pygame.event.post(pygame.event.Event(pygame.VIDEORESIZE, size=(1280, 720), w=1280, h=720))
        app.frame(FRAME_S)
        assert app.running and app.window.surface.get_size() == (1280, 720)
    finally:
        pygame.event.clear()
