"""GameWindow off screen: sizes, type, the status line, panels and the bounded sprite cache."""

from __future__ import annotations

import dataclasses

import numpy as np
import pygame
import pytest
from hypothesis import given
from hypothesis import strategies as st

from airtable.app import panel_view
from airtable.app.demo_loader import key_order
from airtable.app.environment import Environment
from airtable.app.pucks_view import SPRITE_CACHE_BYTES, core_color
from airtable.app.window import PAUSED_COLOR, GameWindow, fit_parts, margins_around
from airtable.model.scene import Scene

TABLE = (10.0, 8.7556)


def window(size=(1280, 720)) -> GameWindow:
    env = Environment(width_m=TABLE[0], height_m=TABLE[1])
    return GameWindow(env, headless=True, size_px=size)


def scene(**kw) -> Scene:
    base = dict(
        width_m=TABLE[0],
        height_m=TABLE[1],
        pos_m=np.array([[5.0, 4.0], [2.0, 2.0]]),
        radius_m=np.array([0.5, 0.25]),
        color_rgb=np.array([[255, 165, 0], [255, 255, 255]], np.uint8),
    )
    base.update(kw)
    return Scene(**base)


def pixels(win: GameWindow) -> np.ndarray:
    return pygame.surfarray.array3d(win.surface)


@pytest.mark.parametrize("size", [(1280, 720), (739, 648), (3840, 2160)])
def test_text_scales_with_the_height_and_is_never_small(size) -> None:
    win = window(size)
    smallest = min(f.get_height() for f in (win.label_font, win.font, win.big_font))
    assert smallest >= 14  # readable at 720p from the back of a room
    if size[1] == 2160:
        assert smallest >= 3 * 14 * 0.9  # proportionally larger at 4K
        assert win.line_px(2) == 6


@pytest.mark.parametrize("size", [(900, 788), (1280, 720), (3840, 2160)])
def test_a_puck_resting_on_the_floor_shows_whole_above_the_status_line(size) -> None:
    win = window(size)
    w, h = size
    # An orange puck of 0.5 m resting on the floor, in the middle of the table.
    win.draw(scene(pos_m=np.array([[5.0, 0.5], [2.0, 2.0]]), status="t = 3.00 s   gravity on   54 pucks"))
    bar = win.status_bar_px
    assert 0 < bar < 0.08 * h and win.status_top_px == h - bar
    left, top, width, height = win.env.table_rect_px
    assert top + height == pytest.approx(h - bar)  # the floor sits on the status line
    room = h - bar - win.layout.top_px  # under the top band of text, if the window has no side margins
    assert height == pytest.approx(room) or width == pytest.approx(w)  # and the table is as big as fits
    x, floor_y = win.env.to_screen(np.array([5.0, 0.0]))
    img = pixels(win)
    lowest_fill = int(floor_y - 0.25 * win.env.px_per_m)  # inside the puck, a quarter radius above the floor
    assert tuple(img[int(x), lowest_fill]) == tuple(core_color((255, 165, 0)))  # not dimmed by the bar
    assert tuple(img[int(x), int(h - bar / 2)]) != tuple(core_color((255, 165, 0)))  # the bar is below it


def test_a_resize_event_refits_the_table() -> None:
    win = window((900, 788))
    pygame.event.post(pygame.event.Event(pygame.VIDEORESIZE, size=(1600, 700), w=1600, h=700))
    for event in pygame.event.get():
        win.handle_event(event)
    assert win.surface.get_size() == (1600, 700) and win.env.size_px == (1600, 700)
    win.draw(scene())
    img = pixels(win)
    # The table is 700 px tall less the status bar, centred: walls near x = 415 and 1184, margins outside.
    table_h = 700 - win.status_bar_px
    x0 = round((1600 - table_h * TABLE[0] / TABLE[1]) / 2)
    y = table_h // 2
    assert tuple(img[x0 + 1, y]) == (255, 69, 0)
    assert tuple(img[1600 - x0 - 2, y]) == (255, 69, 0)
    assert tuple(img[x0 - 20, y]) != (0, 0, 0) or tuple(img[x0 + 20, y]) == (0, 0, 0)


def test_status_line_never_overflows_and_drops_the_least_important_parts() -> None:
    pygame.font.init()
    font = pygame.font.Font(None, 22)
    parts = ["gravity on", "correction: two-step", "8 pucks", "t = 3.00 s", "F1: help"]
    for width in (30, 80, 200, 400, 2000):
        text = fit_parts(font, parts, width)
        assert font.size(text)[0] <= width
    assert fit_parts(font, parts, 2000) == "   ".join(parts)
    assert (
        fit_parts(font, parts, font.size("gravity on   correction: two-step")[0]) == "gravity on   correction: two-step"
    )
    assert fit_parts(font, parts, 60).endswith("...")


@pytest.mark.parametrize("width", [320, 700, 1280, 3840])
def test_status_bar_fits_every_width_and_paused_is_large_and_off_the_table(width) -> None:
    win = window((width, 720))
    status = ["PAUSED", "slow motion x1/4", "gravity off", "correction: two-step", "restitution: pucks 1, walls 1"]
    win.draw(scene(status="   ".join(status), title="Demo 1: a very long title " * 3))
    img = pixels(win)
    yellow = np.argwhere(np.all(img == PAUSED_COLOR, axis=2))
    assert len(yellow) > 0
    assert np.ptp(yellow[:, 1]) >= 30  # large: its box is at least 30 px tall at 720p
    left, top, w, h = win.env.table_rect_px
    inside = (yellow[:, 0] > left) & (yellow[:, 0] < left + w) & (yellow[:, 1] > top) & (yellow[:, 1] < top + h)
    assert not inside.any()  # never over the table (the trick shot's cue)


def test_sprite_cache_stays_bounded_at_extreme_zoom() -> None:
    win = window((1920, 1080))
    many = scene(
        pos_m=np.random.default_rng(1).uniform(0.5, 8, (300, 2)),
        radius_m=np.linspace(0.01, 0.6, 300),
        color_rgb=np.random.default_rng(2).integers(10, 255, (300, 3)).astype(np.uint8),
    )
    for zoom in np.geomspace(1.0, 1e6, 60):  # 1e6 is clamped to the largest zoom
        win.env.zoom_about((960, 540), zoom / win.env.zoom)
        win.draw(many)
        assert win.sprites.bytes <= SPRITE_CACHE_BYTES
    assert win.env.zoom == 200.0


def test_a_puck_larger_than_the_window_is_drawn_directly() -> None:
    win = window((1280, 720))
    s = scene()
    win.env.zoom = 200.0
    win.env.origin_m = np.array([5.0, 4.0]) - np.array([640, 360]) / win.env.px_per_m  # the big puck in the middle
    win.draw(s)
    assert tuple(pixels(win)[640, 360]) == core_color((255, 165, 0))
    assert win.sprites.bytes < 1024 * 1024


def test_help_fits_720p_with_nothing_cut_and_demos_in_natural_order() -> None:
    pygame.font.init()
    win = window((1280, 720))
    win.draw(scene(status="gravity off   F1: help"), hud=["join with: airtable-client 10.0.0.7:8888", "C1 Ann"])
    keys = [(f"key {k}", f"does thing number {k}, which takes a few words to say") for k in range(28)]
    demo_keys = sorted([f"t{k}" for k in range(1, 26)] + [str(k) for k in range(10)], key=key_order)
    assert demo_keys.index("t2") < demo_keys.index("t10")
    demos = [(k, f"Demo {k}: a title") for k in demo_keys]
    rect = win.panel_rect()
    assert rect.collidelist(win.label_boxes[:2]) == -1  # the title and the join line stay visible
    body = panel_view.body_rect(rect.size, win.font, win.big_font, win.label_font)
    assert body.bottom <= rect.height and body.right <= rect.width
    pages = panel_view.layout(win.font, [("", keys), ("Demos", demos)], body.size)
    shown = " ".join(p.text for page in pages for p in page)
    for k, text in keys + demos:
        assert f" {k} {text} " in f" {shown} "  # every row, whole, on some page
    for page in pages:
        for p in page:
            assert p.x + win.font.size(p.text)[0] <= body.width
            assert p.y + win.font.get_linesize() <= body.height
    # The window picks smaller (but still readable) type to save a page.
    assert win.draw_panel("Keys", keys, side_title="Demos", side_rows=demos) <= len(pages)


@pytest.mark.parametrize("size", [(1280, 720), (1920, 1080), (3840, 2160)])
def test_the_apps_help_fits_one_page_on_common_screens(size) -> None:
    from airtable.app.app import App
    from airtable.app.demo_loader import BUILTIN_DIR, discover

    demos, _ = discover([BUILTIN_DIR])
    app = App(demos, headless=True, window_size_px=size)
    app.panels.show_help = True
    app.frame(1 / 60)
    assert app.panels.help_pages == 1


def test_the_framebuffer_hint_is_set_only_by_the_entry_points_and_only_on_x11(monkeypatch) -> None:
    import os
    import subprocess
    import sys

    from airtable import cli
    from airtable.app.window import FRAMEBUFFER_HINT, prefer_plain_framebuffer

    env = {k: v for k, v in os.environ.items() if k != FRAMEBUFFER_HINT}
    imports = "import os, airtable.cli, airtable.app.app, airtable.app.window, airtable.net.player;"
    check = f"print(os.environ.get({FRAMEBUFFER_HINT!r}))"
    out = subprocess.run([sys.executable, "-c", imports + check], env=env, capture_output=True, text=True, timeout=60)
    assert out.stdout.strip() == "None", out.stderr  # importing sets nothing
    monkeypatch.delenv(FRAMEBUFFER_HINT, raising=False)
    assert prefer_plain_framebuffer() is False and FRAMEBUFFER_HINT not in os.environ  # the dummy driver: left alone
    assert cli.main(["--headless", "--no-server", "--seconds", "0.05"]) == 0
    assert FRAMEBUFFER_HINT not in os.environ  # no window, no hint


def test_f11_twice_brings_back_the_windowed_size(monkeypatch) -> None:
    # A real display window on the dummy driver; leaving fullscreen, SDL under a window manager
    # first hands back the desktop's size (user test: 740x648 came back 1280x720): mimic that.
    env = Environment(width_m=TABLE[0], height_m=TABLE[1])
    win = GameWindow(env, size_px=(740, 648))
    before = win.surface.get_size()
    assert before == (740, 648)
    real_set_mode, asked = pygame.display.set_mode, []

    def set_mode_under_a_wm(size, flags=0):
        left_fullscreen = asked and asked[-1] & pygame.FULLSCREEN and not flags & pygame.FULLSCREEN
        asked.append(flags)
        return real_set_mode((1280, 720) if left_fullscreen else size, flags)

    monkeypatch.setattr(pygame.display, "set_mode", set_mode_under_a_wm)
    for event in (pygame.event.Event(pygame.KEYDOWN, key=pygame.K_F11, mod=0),) * 2:
        assert win.handle_event(event)
    assert not win.fullscreen
    assert win.surface.get_size() == before == win.env.size_px
    assert win.windowed_size_px == before


@given(st.integers(-50, 700), st.integers(-50, 500), st.integers(0, 900), st.integers(0, 700))
def test_the_margins_and_the_table_cover_the_screen_once(x, y, w, h):
    """Every pixel of the screen is in the table's rectangle or in exactly one margin, never in two."""
    screen, table = pygame.Rect(0, 0, 640, 480), pygame.Rect(x, y, w, h)
    cover = np.zeros((480, 640), dtype=int)
    inside = table.clip(screen)
    cover[inside.top : inside.bottom, inside.left : inside.right] += 1
    for m in margins_around(screen, table):
        assert screen.contains(m)
        cover[m.top : m.bottom, m.left : m.right] += 1
    assert (cover == 1).all()


@pytest.mark.parametrize("size", [(493, 432), (640, 480), (1280, 720), (3840, 2160)])
def test_every_demos_lecture_notes_fit_the_notes_panel_whole(size) -> None:
    """The gas's notes in a window on a 640x480 screen lost their last line, with no sign of it."""
    from airtable.app.demo_loader import BUILTIN_DIR, discover

    demos, _ = discover([BUILTIN_DIR])
    win = window(size)
    win.draw(scene(status="t = 5.35 s | F1: help | gravity off"))  # (drawing places the status bar)
    for demo in demos.values():
        notes = demo.notes or "(no notes)"
        assert win.draw_panel(demo.label(0), [notes], large=True) == 1, demo.key  # one page: nothing cut
    if size[1] >= 720:  # where it fits, in the large type
        gas = demos["0p"]
        body = panel_view.body_rect(win.panel_rect().size, win.big_font, win.big_font, win.label_font)
        assert len(panel_view.layout(win.big_font, [("", (gas.notes,))], body.size)) == 1


@given(
    st.lists(st.text("abcdefghijklmnopqrstuvwxyzäöüжщ", min_size=1, max_size=12), min_size=1, max_size=400),
    st.integers(120, 900),
    st.integers(30, 400),
)
def test_a_paragraph_taller_than_a_column_goes_on_in_the_next_column_or_page(words, width, height) -> None:
    """A long paragraph was cut at the column's foot, and the panel said it had one page."""
    pygame.font.init()
    font = pygame.font.Font(None, 22)
    pages = panel_view.layout(font, [("", (" ".join(words),))], (width, height))
    shown = [piece for page in pages for piece in page]
    # Every letter in order, nothing lost (a word wider than the column is broken across lines).
    assert "".join(p.text for p in shown).replace(" ", "") == "".join(words)
    for page in pages:
        assert all(p.y + font.get_linesize() <= max(height, font.get_linesize()) for p in page)


def test_notes_too_long_for_the_window_turn_pages_with_l_and_say_so() -> None:
    from airtable.app.app import App
    from airtable.app.demo_loader import BUILTIN_DIR, discover

    demos, _ = discover([BUILTIN_DIR])
    long_notes = " ".join(["A teacher's own demo with a very long lecture note."] * 60)
    demos = {"1": dataclasses.replace(demos["1"], notes=long_notes)}
    app = App(demos, demo_key="1", headless=True, window_size_px=(640, 480))
    key = pygame.event.Event(pygame.KEYDOWN, key=pygame.K_l, mod=0, unicode="l")
    pygame.event.post(key)
    app.frame(1 / 60)
    pages = app.panels.notes_pages
    assert pages > 1 and app.panels.show_notes
    seen = []
    for _ in range(pages):  # L turns the pages, then closes the notes
        seen.append((app.panels.notes_page, app.panels.show_notes))
        pygame.event.post(key)
        app.frame(1 / 60)
    assert seen == [(k, True) for k in range(pages)]
    assert not app.panels.show_notes and app.panels.notes_page == 0


@pytest.mark.parametrize("size", [(640, 480), (1280, 720), (1920, 1080), (3840, 2160), (1000, 300), (400, 900)])
def test_panels_leave_the_frame_rate_and_paused_in_view(size) -> None:
    """Help at 1280x720 full screen covered the frame-rate box (--stats) in the top right corner."""
    win = window(size)
    win.show_fps = True
    win.draw(scene(status="   ".join(["PAUSED", "t = 5.35 s", "F1: help"]), fps=59.7))
    corner = [box for box in win.label_boxes if box.right > win.surface.get_width() - win.layout.side_px]
    corner = [box for box in corner if box.top < win.hud_bottom_px and box.left > win.layout.side_px]
    panel = win.panel_rect()
    if win.layout.side_px:  # in the margins layout the two boxes sit in the right margin's top
        assert len(corner) == 2
    assert panel.collidelist(corner) == -1
    assert panel.height >= 4 * win.font.get_linesize()


def test_the_notes_panel_is_no_taller_than_its_text_so_the_table_shows_below() -> None:
    """The notes covered the whole table, the orange puck they speak of too, with the panel's lower half empty."""
    from airtable.app.demo_loader import BUILTIN_DIR, discover

    gas = discover([BUILTIN_DIR])[0]["0p"]
    win = window((1920, 1080))
    win.draw(scene(status="t = 5.35 s"))
    rect = win.panel_rect()
    font = win._panel_font([("", (gas.notes,))], rect, "big")
    args = dict(font=font, title_font=win.big_font, small_font=win.label_font)
    full, _ = panel_view.render_panel(rect.size, gas.label(1), [("", (gas.notes,))], **args)
    fitted, pages = panel_view.render_panel(rect.size, gas.label(1), [("", (gas.notes,))], fit=True, **args)
    assert pages == 1 and full.get_size() == rect.size
    assert fitted.get_width() == rect.width and fitted.get_height() < 0.7 * rect.height
    body = panel_view.body_rect(rect.size, font, win.big_font, win.label_font)
    lines = panel_view.layout(font, [("", (gas.notes,))], body.size)[0]
    assert body.y + max(p.y for p in lines) + font.get_linesize() <= fitted.get_height()  # every line inside it


@pytest.mark.parametrize("size", [(640, 480), (1280, 720), (3840, 2160)])
def test_a_cursors_name_stays_whole_on_screen_on_dark_ground(size) -> None:
    """The teacher's "teacher" was cut to "teac" at the right edge, and hard to read over the gas."""
    win = window(size)
    win.draw(scene())
    w, h = win.surface.get_size()
    for at_px in ((w - 2, h // 2), (w // 2, h - 2), (w - 2, h - 2), (5, 5)):
        box = win.draw_cursor("teacher", (120, 255, 120), win.env.to_world(at_px))
        assert win.surface.get_rect().contains(box) and box.width >= win.label_font.size("teacher")[0]
        corner = tuple(win.surface.get_at(box.topleft))[:3]
        assert corner == (0, 0, 0)  # the name's own dark ground


@pytest.mark.parametrize("size", [(640, 480), (1280, 720)])
def test_a_banner_wraps_its_sentence_instead_of_cutting_the_advice(size) -> None:
    """A user test: the student's banner read "nothing from the teacher's table for 9 s: the network..."."""
    from airtable.app.window import ACCENT

    win = window(size)
    sentence = "nothing from the teacher's table for 9 s: the network to it may be down; your seat is kept"
    lines = panel_view.wrap(win.big_font, sentence, size[0] - 40)
    assert 1 < len(lines) <= 3 and " ".join(lines) == sentence  # the whole advice fits in three lines
    win.surface.fill((0, 0, 0))
    win.draw_banner(sentence)
    pixels = pygame.surfarray.pixels3d(win.surface)
    accent = np.all(pixels == np.array(ACCENT), axis=2)
    rows = np.flatnonzero(accent[size[0] // 4 : 3 * size[0] // 4].any(axis=0))  # text rows, frame aside
    text_rows = rows[(rows > rows.min() + 3) & (rows < rows.max() - 3)]  # the box's frame lines dropped
    assert np.ptp(text_rows) > (len(lines) - 0.7) * win.big_font.get_linesize()  # one line each
