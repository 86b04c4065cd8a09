"""Everything has its place (issue 22, item 4): at 640x480, 1280x720, 1920x1080 and 3840x2160
no text rectangle crosses the table's walls or a puck at rest.

A real headless teacher's App with a real server (so the join line and the student
count show), paused (PAUSED shows), with the aids on, driven with real key events.
The text rectangles are the ones the window records as it draws (`label_boxes`):
the heads-up text and its band, the status bar, PAUSED, the chart, the values panel,
the legend and the annotations' boxes. Where the window has no side margins the
chart and the values panel are opaque boxes at its edges, over the table by
necessity; the rest must still keep clear.
"""

from __future__ import annotations

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, press

from airtable.app.app import App
from airtable.net.server import GameServer

SIZES = [(640, 480), (1280, 720), (1920, 1080), (3840, 2160)]


@pytest.fixture(scope="module")
def server():
    with GameServer(host="127.0.0.1", port=0) as running:
        yield running


def puck_rects(app) -> list[pygame.Rect]:
    env, t = app.env, app.table
    centers, r = env.to_screen(t.pos_m), env.length_to_px(t.radius_m)
    return [pygame.Rect(int(x - q), int(y - q), int(2 * q), int(2 * q)) for (x, y), q in zip(centers, r)]


def crossings(app, boxes) -> list[tuple]:
    """Each text box that crosses a wall line or a puck, with what it crosses."""
    keep_clear = [("wall", r) for r in app.window.wall_rects()] + [("puck", r) for r in puck_rects(app)]
    return [(box, what) for box in boxes for what, r in keep_clear if box.colliderect(r)]


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("demo", ["3", "6", "8"])
def test_no_text_crosses_a_wall_or_a_resting_puck(demos, server, size, demo):
    app = App(demos, demo_key=demo, headless=True, server=server, window_size_px=size)
    pygame.event.clear()
    app.say("a message for the room, long enough to need its own line on a small window")
    for key in (pygame.K_SPACE, pygame.K_v, pygame.K_a, pygame.K_k):
        press(app, key)
    app.frame(FRAME_S)
    assert app.paused
    window = app.window
    text = list(window.label_boxes)
    assert text and not crossings(app, text), crossings(app, text)
    if window.layout.side_px:  # the chart and the values panel fit in the margins
        press(app, pygame.K_c)
        press(app, pygame.K_t)
        assert app.aids.show_chart and app.lessons.show_values
        assert not crossings(app, window.label_boxes), crossings(app, window.label_boxes)


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_whole_table_shows_between_the_text(demos, server, size):
    app = App(demos, demo_key="3", headless=True, server=server, window_size_px=size)
    app.frame(FRAME_S)
    left, top, width, height = app.env.table_rect_px
    w, h = size
    assert left >= 0 and top >= 0 and left + width <= w + 1e-6
    assert top + height == pytest.approx(h - app.window.status_bar_px) or top >= app.window.layout.top_px
    assert height >= 0.75 * h  # the text takes a band, not the table's room
    walls = app.window.wall_rects()
    assert len(walls) == 4 and all(np.all(np.array(r.size) > 0) for r in walls)
