"""What a teacher sees at the edges of the screen and on the energy chart (defects found by user tests).

A real headless teacher's App driven with real pygame events; the numbers are the window's pixels and the
boxes it records as it draws. The chart's axis tops are worked out here by hand: a puck of 1 kg at speed v
has |p| = v N s and 0.5 v^2 J, and the top is the first of 1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 8 x 10^k at
least 5 % above the largest value in view.
"""

from __future__ import annotations

import math

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, press

from airtable.app.aids_paint import CHART_COLORS
from airtable.app.app import App
from airtable.app.demo_loader import Demo
from airtable.app.window import TEXT_COLOR
from airtable.model.aids import CHART_WINDOW_S, loses_energy
from airtable.model.client import LOCAL_COLOR
from airtable.net.server import GameServer

SIZES = [(640, 480), (1280, 720), (1920, 1080), (3840, 2160)]
MOMENTUM_COLOR = CHART_COLORS["momentum_Ns"]
WHITE = (255, 255, 255)


def one_puck(table, variation=0) -> None:
    """A puck of exactly 1 kg in the middle of the table, at rest."""
    radius_m = 0.5
    table.add_puck(pos_m=(3.0, 4.4), radius_m=radius_m, density_kgpm2=1.0 / (math.pi * radius_m**2))


ONE_PUCK = {"1": Demo(key="1", title="One puck of 1 kg", notes="", build=one_puck)}


def app_at(size, demos=ONE_PUCK, key="1", **kw) -> App:
    app = App(demos, demo_key=key, headless=True, window_size_px=size, **kw)
    pygame.event.clear()
    return app


def pixels(app) -> np.ndarray:
    return pygame.surfarray.array3d(app.window.surface)  # [x, y, rgb]


def on_black(font, text: str, color) -> np.ndarray:
    """`text` in `color` as the window draws a label: rendered smooth, then put on black ground."""
    label = font.render(text, True, color)
    ground = pygame.Surface(label.get_size())
    ground.blit(label, (0, 0))
    return pygame.surfarray.array3d(ground)


def drawn_text_at(app, text: str, color, font) -> pygame.Rect | None:
    """Where `text` in `color` shows on the window exactly as the chart draws a label (on black), if it does."""
    want = on_black(font, text, color)
    for rect in app.painter.chart_text:
        if rect.size == want.shape[:2] and np.array_equal(
            pixels(app)[rect.left : rect.right, rect.top : rect.bottom], want
        ):
            return rect
    return None


def covered_share(rect: pygame.Rect, table: pygame.Rect) -> float:
    """The share of the table's area that `rect` covers."""
    overlap = rect.clip(table)
    return overlap.width * overlap.height / (table.width * table.height)


def table_rect(app) -> pygame.Rect:
    return pygame.Rect(*(int(round(v)) for v in app.env.table_rect_px))


# ------------------------------------------------------------ 1. each line's scale is labelled


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_momentum_axis_is_labelled_in_n_s_in_its_lines_colour(size):
    app = app_at(size)
    app.table.vel_mps[0] = (0.5, 0.0)  # |p| 0.5 N s, 0.125 J
    press(app, pygame.K_c, frames=30)
    assert app.aids.show_chart
    font = app.window.label_font
    # 1.05 x 0.5 N s = 0.525: the top is 0.6 N s; 1.05 x 0.125 J = 0.131: 0.15 J.
    momentum = drawn_text_at(app, "0.6 N s", MOMENTUM_COLOR, font)
    energy = drawn_text_at(app, "0.15 J", TEXT_COLOR, font)
    plot = app.painter.chart_plot
    assert momentum is not None and energy is not None
    # Above the plot, over none of its lines: J at the left, N s at the right.
    assert momentum.right == plot.right and momentum.bottom <= plot.top
    assert energy.left == plot.left and energy.bottom <= plot.top and not energy.colliderect(momentum)
    # The |p| line is drawn against its own scale: 0.5 of 0.6 of the plot's height.
    column = pixels(app)[plot.centerx, plot.top + 1 : plot.bottom - 1]
    ys = np.flatnonzero(np.all(column == MOMENTUM_COLOR, axis=1)) + plot.top + 1
    expected = plot.bottom - 0.5 / 0.6 * plot.height
    assert len(ys) and abs(ys.mean() - expected) <= app.window.line_px(1.5) + 1


# ------------------------------------------------------------ 2. its size on a small window


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("small", [False, True], ids=["large", "small"])
def test_the_charts_text_stays_readable_and_inside_its_box(demos, size, small):
    app = app_at(size, demos, "5")  # the spring pair: every line moves
    press(app, pygame.K_c, frames=60)
    if small:
        press(app, pygame.K_b, frames=2)
    assert app.painter.chart_small == small
    box, window = app.painter.chart_rect(), app.window.surface.get_rect()
    texts = app.painter.chart_text
    assert window.contains(box)
    assert len(texts) >= 5 + 2  # the key's five lines and the axes' tops
    assert all(box.contains(rect) for rect in texts), (box, texts)
    assert all(a.collidelist([b for b in texts if b is not a]) < 0 for a in texts)  # no text over text
    assert app.window.label_font.get_height() >= 14  # readable on a projector
    assert (
        box.contains(app.painter.chart_plot)
        and app.painter.chart_plot.height >= 3 * app.window.label_font.get_linesize()
    )


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_charts_note_keeps_off_its_key(demos, size):
    """Demo 5 without its damper: the chart explains the total's swing under the plot and its key."""
    app = App(demos, demo_key="5", variation=1, headless=True, window_size_px=size)
    pygame.event.clear()
    press(app, pygame.K_c, frames=150)
    assert app.aids.chart.euler_wiggle_note(app.table.spring_pairs.size > 0, loses_energy(app.table)) is not None
    box, texts = app.painter.chart_rect(), app.painter.chart_text
    assert len(texts) > 5 + 3  # the key, the axes and at least a line of the note
    assert all(box.contains(rect) for rect in texts), (box, texts)
    assert all(a.collidelist([b for b in texts if b is not a]) < 0 for a in texts), texts


def test_at_640x480_the_chart_covers_a_small_share_of_the_table(demos):
    app = app_at((640, 480), demos, "5")
    press(app, pygame.K_c, frames=2)
    table = table_rect(app)
    large = [covered_share(app.painter.chart_rect(corner), table) for corner in range(4)]
    press(app, pygame.K_b, frames=2)
    small = [covered_share(app.painter.chart_rect(corner), table) for corner in range(4)]
    # Before: 320 x 160 px, 21 % of the table's 450 x 394 px; small, 312 x 144 px, 18 %. Now 13 % and 6 %.
    assert max(large) <= 0.15 and max(small) <= 0.08, (large, small)


# ------------------------------------------------------------ 3. its scale after a fling


def test_after_a_fling_the_axis_follows_what_the_chart_shows():
    """A fling stays whole at its true height while it is in view; once it has left the chart's window the
    axis comes down to the calm table's numbers and the total line stands high again."""
    app = app_at((1280, 720))
    press(app, pygame.K_c)
    app.table.vel_mps[0] = (2.0, 0.0)  # the fling: 2 J
    for _ in range(30):
        app.frame(FRAME_S)
    app.table.vel_mps[0] = (0.2, 0.0)  # the table calms: 0.02 J
    for _ in range(120):
        app.frame(FRAME_S)
    font, plot = app.window.label_font, app.painter.chart_plot
    assert drawn_text_at(app, "2.5 J", TEXT_COLOR, font) is not None  # 1.05 x 2 J = 2.1: 2.5 J
    white_rows = np.flatnonzero(
        np.all(pixels(app)[plot.left + 2 : plot.right - 2, plot.top : plot.bottom] == WHITE, axis=2).any(axis=0)
    )
    assert white_rows.size and plot.top + white_rows.min() <= plot.bottom - 0.78 * plot.height  # the fling's 2/2.5
    for _ in range(round(CHART_WINDOW_S / FRAME_S)):
        app.frame(FRAME_S)
    assert drawn_text_at(app, "0.025 J", TEXT_COLOR, font) is not None  # 1.05 x 0.02 J = 0.021: 0.025 J
    plot = app.painter.chart_plot
    column = pixels(app)[plot.centerx, plot.top + 1 : plot.bottom - 1]
    ys = np.flatnonzero(np.all(column == WHITE, axis=1)) + plot.top + 1
    assert len(ys) and abs(ys.mean() - (plot.bottom - 0.8 * plot.height)) <= app.window.line_px(3)  # 0.02 / 0.025


# ------------------------------------------------------------ 4. the status line at small widths


@pytest.fixture(scope="module")
def server():
    with GameServer(host="127.0.0.1", port=0) as running:
        yield running


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_status_line_keeps_its_most_important_parts_whole(demos, server, size):
    app = app_at(size, demos, "3", server=server)
    server.hands_off = True
    try:
        for key in (pygame.K_s, pygame.K_s, pygame.K_F6):  # slow motion x1/4, a prediction round
            press(app, key)
        app.frame(FRAME_S)
        parts = app.status_parts()
    finally:
        server.hands_off = False
    assert parts[:3] == ["PAUSED", "HANDS OFF", "PREDICT: 0 of 0 predicted (F6 reveals)"]
    shown = app.window.status_boxes
    texts = [text for text, _ in shown]
    w, h = size
    bar_top = h - app.window.status_bar_px
    font = app.window.font
    # Whole parts, most important first (PAUSED is drawn large at the top): a part may lose its closing hint.
    assert texts[:2] == ["HANDS OFF", "PREDICT: 0 of 0 predicted"] or texts[:2] == parts[1:3]
    assert "0 collisions, 0 on walls" in texts and "slow motion x1/4" in texts
    for k, (text, rect) in enumerate(shown):
        assert rect.width == font.size(text)[0] and 0 <= rect.left and rect.right <= w and bar_top <= rect.top
        assert rect.bottom <= h
        if k:
            assert rect.left > shown[k - 1][1].right  # in order, apart
    # Nothing of a part left out shows: the bar is dark from the last part to the window's edge.
    last = shown[-1][1]
    assert not pixels(app)[last.right + 1 :, bar_top + app.window.timeline_strip_px :].any()


# ------------------------------------------------------------ 5. cursor names off the window's own text


def green_outside(app, region: pygame.Rect, tip) -> int:
    """Pixels of the teacher's colour in `region` apart from the arrow at `tip` (its 13 x 15 units)."""
    u = max(1.0, app.window.unit)
    arrow = pygame.Rect(int(tip[0]) - 1, int(tip[1]) - 1, int(14 * u) + 3, int(16 * u) + 3)
    green = np.all(pixels(app) == LOCAL_COLOR, axis=2)
    count = 0
    for x, y in zip(*np.nonzero(green)):
        count += region.collidepoint(int(x), int(y)) and not arrow.collidepoint(int(x), int(y))
    return count


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_a_cursors_name_keeps_off_the_status_line_and_the_heads_up_text(demos, size):
    app = app_at(size, demos, "3")
    w, h = size
    for tip in ((w // 3, h - 3), (w - 4, h - 3), (w // 3, 3)):
        pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=tip, rel=(0, 0), buttons=(0, 0, 0)))
        app.frame(FRAME_S)
        window = app.window
        bar = pygame.Rect(0, window.status_top_px, w, h - window.status_top_px)
        (name,) = window.cursor_boxes
        assert window.surface.get_rect().contains(name) and name.width >= window.label_font.size("teacher")[0]
        assert name.collidelist(window.hud_boxes) < 0 and not name.colliderect(bar), (tip, name)
        assert green_outside(app, bar, tip) == 0  # no letter of it over the status line
        if window.layout.top_px:
            assert green_outside(app, pygame.Rect(0, 0, w, window.layout.top_px), tip) == 0


# ------------------------------------------------------------ 6. the frame rate while idle


def corner_shows(app, text: str) -> bool:
    """Whether `text` shows, as the frame rate's box draws it, in the window's top right quarter."""
    font = app.window.font
    label = on_black(font, text, TEXT_COLOR)
    w, h = app.window.surface.get_size()
    region = pixels(app)[w // 2 :, : h // 4]
    lw, lh = label.shape[:2]
    first = np.argwhere(np.all(region == label[lw // 2, lh // 2], axis=2))  # candidates from one pixel
    for x, y in first:
        x0, y0 = x - lw // 2, y - lh // 2
        if 0 <= x0 and 0 <= y0 and np.array_equal(region[x0 : x0 + lw, y0 : y0 + lh], label):
            return True
    return False


def test_the_frame_rate_says_idle_while_the_loop_idles_and_the_rate_while_pucks_move():
    app = app_at((1280, 720), show_fps=True)
    app.run(max_frames=3 * 60, frame_dt_s=FRAME_S)  # a still puck, no input for 3 s: the loop idles
    assert app.window.idle and corner_shows(app, "idle") and not corner_shows(app, f"{app.fps:5.1f} fps")
    app.table.vel_mps[0] = (1.0, 0.0)  # moving: the loop runs at its full rate
    app.run(max_frames=30, frame_dt_s=FRAME_S)
    assert not app.window.idle and corner_shows(app, " 60.0 fps")


def test_the_rate_measured_after_idling_counts_no_idle_frame():
    from airtable.app.loop import FpsCounter

    counter, now = FpsCounter(), 0.0
    for _ in range(24):  # 2 s of idle frames, 12 a second
        now += 1 / 12
        counter.tick(now)
    counter.restart()  # the app restarts it on each idle frame
    for _ in range(12):
        now += 1 / 60
        rate = counter.tick(now)
    assert rate == pytest.approx(60.0)


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_cursors_at_one_spot_keep_their_names_apart(demos, size):
    """A user test: two students' cursors at one spot wrote their names over each other."""
    from dataclasses import replace

    from airtable.model.scene import CursorView, Scene

    app = app_at(size, demos, "3")
    w, h = size
    for tip in ((w // 2, h // 2), (w - 4, h - 3), (w // 3, 3), (3, h // 2)):
        spot = tuple(float(v) for v in app.env.to_world(tip))
        cursors = tuple(CursorView(f"C{k} Student {k}", (200, 100 + 20 * k, 50), spot) for k in range(1, 4))
        scene = replace(Scene.from_table(app.table, app.clients, title="t", status="s"), cursors=cursors)
        app.window.draw(scene)
        boxes = app.window.cursor_boxes
        assert len(boxes) == 3 and all(app.window.surface.get_rect().contains(b) for b in boxes), (tip, boxes)
        assert not any(a.colliderect(b) for k, a in enumerate(boxes) for b in boxes[k + 1 :]), (tip, boxes)


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("zoom", [4.0, 40.0])
def test_zoomed_in_the_names_of_cursors_out_of_view_line_up_along_the_edge(demos, size, zoom):
    """A user test: after the teacher zoomed in, the names of idle students (their cursors at a corner of the
    table, out of the view) piled up over the title in the top left corner."""
    from dataclasses import replace

    from airtable.model.scene import CursorView, Scene

    app = app_at(size, demos, "3")
    app.env.zoom_about(app.env.to_screen(np.array([0.6 * app.table.width_m, 0.5 * app.table.height_m])), zoom)
    corners = [(0.0, 0.0), (0.0, app.table.height_m), (app.table.width_m, 0.0)]
    cursors = tuple(CursorView(f"C{k} Kid {k}", (200, 100 + 5 * k, 50), corners[k % 3]) for k in range(12))
    scene = replace(Scene.from_table(app.table, app.clients, title="t", status="s"), cursors=cursors)
    app.window.draw(scene)
    boxes, hud = app.window.cursor_boxes, app.window.hud_boxes
    assert all(app.window.surface.get_rect().contains(b) for b in boxes), boxes
    piled = [(a, b) for k, a in enumerate(boxes) for b in boxes[k + 1 :] if a.colliderect(b)]
    assert not piled and not [b for b in boxes if b.collidelist(hud) >= 0], (piled, hud)


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_zoomed_in_on_nothing_the_status_line_says_how_to_get_back(demos, size):
    """A user test: wheeled x200 in between the pucks of demo 4 the window was black, and the status line
    said "zoom x200" only: the way back, a hint in brackets, was the first thing a narrow bar left out."""
    app = app_at(size, demos, "4")
    app.paused = True
    pos = app.table.pos_m
    # Between the two pucks nearest the table's middle: the wheel zooms about the mouse.
    middle = np.array([0.5 * app.table.width_m, 0.5 * app.table.height_m])
    a, b = np.argsort(np.hypot(*(pos - middle).T))[:2]
    mouse = tuple(int(v) for v in app.env.to_screen(0.5 * (pos[a] + pos[b])))
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=mouse, rel=(0, 0), buttons=(0, 0, 0)))
    for _ in range(60):  # 1.1^60 = 304: the zoom stops at its most, x200
        pygame.event.post(pygame.event.Event(pygame.MOUSEWHEEL, x=0, y=1, flipped=False, precise_x=0.0, precise_y=1.0))
    app.frame(FRAME_S)
    assert app.env.zoom == 200.0
    texts = [text for text, _ in app.window.status_boxes]
    assert texts[0] == "zoom x200, no puck in sight: q shows the whole table"
    press(app, pygame.K_q)
    assert app.env.zoom == 1.0 and app.env.view_note(pos, app.table.radius_m)[0] == ""
