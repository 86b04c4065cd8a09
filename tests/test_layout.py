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
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable.app.app import App
from airtable.app.panel_view import wrap
from airtable.app.predict_view import paint_round
from airtable.model.rounds import RoundInfo
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


def drawn_after_keys(demos, server, size, demo: str, keys) -> App:
    """The teacher's app on `demo` in a window of `size`, `keys` pressed in turn, one frame drawn."""
    app = App(demos, demo_key=demo, headless=True, server=server, window_size_px=size)
    pygame.event.clear()
    for key in keys:
        press(app, key)
    app.frame(FRAME_S)
    return app


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


def inside_window(app, boxes) -> list[pygame.Rect]:
    """The text boxes not wholly inside the window."""
    window = pygame.Rect((0, 0), app.window.surface.get_size())
    return [box for box in boxes if not window.contains(box)]


def wrong_places(app) -> list:
    boxes = list(app.window.label_boxes)
    return crossings(app, boxes) + [(box, "outside the window") for box in inside_window(app, boxes)]


LONG_PATH = "saved recordings/demo2-20261127-102233-four-pucks-and-a-long-name-for-the-file.csv (12 s)"


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("case", ["values hint 3", "values hint 8", "long path", "predict"])
def test_long_text_stays_in_its_box_and_off_the_table(demos, server, size, case):
    # User test: in 16:9 windows the values hint, a file's path and the PREDICT lines ran out of
    # their boxes in the side margins and across the table's left wall.
    demo = {"values hint 3": "3", "values hint 8": "8"}.get(case, "2")
    app = App(demos, demo_key=demo, headless=True, server=server, window_size_px=size)
    pygame.event.clear()
    press(app, pygame.K_SPACE)
    if case == "long path":
        app.say(LONG_PATH)
    elif case == "predict":
        press(app, pygame.K_F6)
        assert app.predict.round.state == "open"
    else:
        press(app, pygame.K_t)
        assert app.lessons.show_values
    app.frame(FRAME_S)
    assert app.paused
    wrong = wrong_places(app)
    if case.startswith("values") and not app.window.layout.side_px:
        # No margins: the panel is an opaque box at the window's edge, over the table by
        # necessity (see above); its text must stay inside it.
        panel = max((box for box, _ in wrong), key=lambda box: box.width * box.height)
        wrong = [(box, what) for box, what in wrong if not panel.contains(box) or what == "outside the window"]
        assert panel.height > 2 * app.window.label_font.get_linesize()  # the hint wrapped, not cut
    assert not wrong, wrong


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_reveal_summary_stays_off_the_table(demos, server, size):
    # User test at 1280x720: "puck 4: comes to rest; 0 of 2 predicted..." reached into the table.
    app = App(demos, demo_key="8", headless=True, server=server, window_size_px=size)
    pygame.event.clear()
    press(app, pygame.K_SPACE)
    info = RoundInfo(
        1,
        "revealed",
        pucks=5,
        truth=((0.0, 0.0),) * 5,
        summary=tuple(f"puck {k}: comes to rest; 0 of 2 predicted it, the nearest 0.4 m/s off" for k in range(5)),
        from_m=tuple(map(tuple, app.table.pos_m[:5])),
    )
    app.window.label_boxes.clear()
    app.painter.note_pucks(app.table.pos_m, app.table.radius_m)
    placed = paint_round(app.painter, info, {}, (255, 255, 255))
    assert len(placed) >= 6 and any("comes to rest" in text for text, _ in placed)
    assert not wrong_places(app), wrong_places(app)
    assert not inside_window(app, [rect for _, rect in placed])


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_velocity_legend_keeps_off_the_momenta_panel(demos, server, size):
    # User test at 640x480, demo 8 paused with the momenta diagram (d) on: the legend lay over its title.
    app = drawn_after_keys(demos, server, size, "8", (pygame.K_SPACE, pygame.K_v, pygame.K_d))
    boxes = app.window.label_boxes
    overlaps = [
        (a, b)
        for i, a in enumerate(boxes)
        for b in boxes[i + 1 :]
        if a.colliderect(b) and not (a.contains(b) or b.contains(a))
    ]
    assert not overlaps, overlaps


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_nothing_peeks_out_from_under_a_panel(demos, server, size):
    # User tests: in fullscreen at 1920x1080 the chart's edge showed beside the roster (F2); at 640x480 the
    # values panel's and the chart's edges did. The join line in the left margin or the top band stays in view.
    app = drawn_after_keys(demos, server, size, "1", (pygame.K_c, pygame.K_t, pygame.K_F2))
    window, painter = app.window, app.painter
    panel = window.panel_rect()
    assert panel.left >= window.layout.side_px and panel.top >= window.layout.top_px
    boxes = [painter.chart_rect(corner) for corner in range(4)]  # every corner the chart may take (m moves it)
    boxes += [box for box in window.label_boxes if box != panel and box.w < panel.w]  # the values panel, ...
    peeking = [box for box in boxes if box.colliderect(panel) and not panel.contains(box)]
    assert not peeking, (panel, peeking)


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_chart_and_the_momenta_stay_in_sight_below_the_lecture_notes(demos, server, size):
    """A user test: `2 l c` showed no chart till the notes closed; the notes leave the table below them in
    sight, and the chart and the momenta diagram move to the corners there."""
    app = drawn_after_keys(demos, server, size, "2", (pygame.K_l, pygame.K_c, pygame.K_d))
    app.frame(FRAME_S)  # (the chart keeps clear of the panel the last frame drew)
    window, painter = app.window, app.painter
    notes = window.panel_area
    assert app.panels.panel() == "notes" and notes is not None and notes.bottom < window.status_top_px // 2
    (chart,) = [box for box in window.label_boxes if box.contains(painter.chart_plot)]
    assert not chart.colliderect(notes), (chart, notes)
    under = [box for box in window.label_boxes if box.colliderect(notes)]  # the momenta box, the HUD, ...
    assert not under, (notes, under)
    press(app, pygame.K_l)  # the notes closed: the chart goes back to its corner
    app.frame(FRAME_S)
    assert window.panel_area is None and app.painter.corner_in_sight() == app.painter.chart_corner


def test_a_word_wider_than_the_line_is_broken_not_cut():
    font = pygame.font.Font(None, 24)
    lines = wrap(font, LONG_PATH, 150)
    assert all(font.size(line)[0] <= 150 for line in lines)
    assert "".join(lines).replace(" ", "") == LONG_PATH.replace(" ", "")
    assert lines[0] == "saved" and len(lines) >= 5


@settings(max_examples=60, deadline=None)
@given(
    parts=st.lists(st.text(st.characters(categories=["L", "Nd"]), min_size=1, max_size=14), min_size=1, max_size=4),
    joiner=st.sampled_from(["-", "/", "_"]),
    width=st.integers(30, 300),
)
def test_a_long_word_breaks_after_a_hyphen_or_slash_where_one_fits(parts, joiner, width):
    """A user test: the student "Александр-Константин" read "Александр-Кон" / "стантин" in a side panel."""
    font = pygame.font.Font(None, 24)
    word = joiner.join(parts)
    lines = wrap(font, word, width)
    assert "".join(lines) == word
    assert all(font.size(line)[0] <= width or len(line) == 1 for line in lines)
    for line, rest in zip(lines, lines[1:]):
        fits = line + rest[0]
        cut = fits.rfind(joiner, 0, len(line)) + 1  # the last joiner in what fits on the line
        if cut > len(line) // 2:
            assert line.endswith(joiner)  # broken after it, not in the middle of the part after it


def test_the_name_of_the_user_test_breaks_at_its_hyphen():
    font = pygame.font.Font(None, 24)
    name = "Александр-Константин"
    width = font.size("Александр-Конст")[0]
    assert wrap(font, name, width) == ["Александр-", "Константин"]
