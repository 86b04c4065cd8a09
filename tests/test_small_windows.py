"""A window shrunk to a strip or a dot keeps the lesson: every panel and aid opens and draws at any size.

A window manager lets a teacher drag the window down to a few pixels (to see the desktop
behind it, or by accident); the panels then had less room than their margins, and creating a
surface of negative size raised: the app ended, and the lesson with it.
"""

from __future__ import annotations

import pygame
import pytest
from conftest import FRAME_S, press

from airtable.app import panel_view
from airtable.app.app import App
from airtable.model.aids import loses_energy

# Keys that open, close or change what is drawn over the table (the key table's rows: F1 help,
# F2-F5 roster pages, Tab menu, l notes, F6 prediction, d/t/k lessons, e/a/v/c/m/b aids, s stats).
OVERLAY_KEYS = (
    pygame.K_F1, pygame.K_F2, pygame.K_F3, pygame.K_F4, pygame.K_F5, pygame.K_TAB, pygame.K_l,
    pygame.K_F6, pygame.K_d, pygame.K_t, pygame.K_k, pygame.K_e, pygame.K_a, pygame.K_v, pygame.K_c,
    pygame.K_m, pygame.K_b, pygame.K_s,
)  # fmt: skip
SIZES = ((1, 1), (1920, 1), (1, 1080), (120, 40), (40, 300), (320, 60))


def resize(app: App, size: tuple[int, int]) -> None:
    """The window manager's resize, as a real window gets it."""
    pygame.event.post(pygame.event.Event(pygame.VIDEORESIZE, size=size, w=size[0], h=size[1]))
    app.frame(FRAME_S)


@pytest.mark.parametrize("size", SIZES)
def test_every_panel_opens_and_draws_in_a_window_shrunk_to_a_strip(demos, size):
    app = App(demos, demo_key="4", headless=True)  # pucks, springs and collisions: every aid has something
    pygame.event.clear()
    resize(app, size)
    assert app.window.surface.get_size() == size
    for key in OVERLAY_KEYS:
        press(app, key, frames=2)  # open (or turn on) ...
    for key in (pygame.K_i, pygame.K_h):  # ... the held keys too (inspect, zoom in)
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=key, mod=0, unicode="", scancode=0))
        app.frame(FRAME_S)
        pygame.event.post(pygame.event.Event(pygame.KEYUP, key=key, mod=0, unicode="", scancode=0))
    for button in (1, 3):  # a click and a right click anywhere in what is left of the window
        pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=(0, 0), button=button))
        app.frame(FRAME_S)
        pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONUP, pos=(0, 0), button=button))
        app.frame(FRAME_S)
    for key in reversed(OVERLAY_KEYS):
        press(app, key, frames=2)  # ... and closed again, all drawn in the strip
    assert app.running
    resize(app, (1280, 720))  # dragged back out: the lesson is still there, and it draws
    press(app, pygame.K_F1)
    assert app.running and app.window.surface.get_size() == (1280, 720)
    assert app.table.n_pucks > 0 and app.table.time_s > 0.0


@pytest.mark.parametrize("size", SIZES)
def test_the_energy_chart_with_its_note_draws_in_a_strip(demos, size):
    """Demo 5 without its damper: the chart explains the total's swing in a note under the plot, which in a
    strip has fewer than no lines of room (an IndexError ended the app)."""
    app = App(demos, demo_key="5", variation=1, headless=True)
    pygame.event.clear()
    press(app, pygame.K_c, frames=150)
    assert app.aids.chart.euler_wiggle_note(app.table.spring_pairs.size > 0, loses_energy(app.table)) is not None
    resize(app, size)
    for _ in range(3):
        app.frame(FRAME_S)
    assert app.running and app.window.surface.get_size() == size


def test_resizing_or_resetting_the_view_while_holding_a_puck_adds_no_energy(demos):
    """A held puck, still on its string: the window resized and the view zoomed, then reset (q).
    The pointer used to stay on the screen while the table moved under it: the string's end jumped to
    another point of the table and yanked the puck (17 J at 640x480; a user saw 11 m/s after F11)."""
    app = App(demos, demo_key="1", headless=True)
    pygame.event.clear()
    puck = app.table.pucks[0]
    at = tuple(int(round(v)) for v in app.env.to_screen(puck.pos_m))
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=at, rel=(0, 0), buttons=(0, 0, 0)))
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=at, button=1))
    for _ in range(60):
        app.frame(FRAME_S)
    assert app.local.held is puck and app.table.kinetic_energy_J() < 1e-12
    for size in ((1920, 1080), (640, 480), (1280, 200), (3840, 2160)):
        resize(app, size)
        for _ in range(30):
            app.frame(FRAME_S)
        assert app.table.kinetic_energy_J() < 1e-9, size
    for _ in range(10):  # wheel zooms about the pointer: the table under it stays put
        pygame.event.post(pygame.event.Event(pygame.MOUSEWHEEL, x=0, y=1, precise_x=0.0, precise_y=1.0, flipped=False))
        app.frame(FRAME_S)
    press(app, pygame.K_q, frames=30)  # the view back as it was
    assert app.env.zoom == 1.0
    assert app.local.held is puck and app.table.kinetic_energy_J() < 1e-9


def test_a_panel_with_no_key_for_pages_says_so_and_the_note_is_cut_to_the_panel():
    """The demo menu (Tab) in a small window read 'page 1 of 15: press F1 for the next': F1 opens the
    help instead; and the note, wider than the panel, lost its left end ('5: press F1 for the next')."""
    assert panel_view.page_note(0, 15, None) == "page 1 of 15: a larger window shows the rest"
    assert panel_view.page_note(0, 3, "F1") == "page 1 of 3: press F1 for the next"
    assert panel_view.page_note(2, 3, "L") == "page 3 of 3: L again closes it"
    pygame.font.init()
    font = pygame.font.Font(None, 20)
    rows = [f"demo {k}: a title long enough to wrap in a narrow panel" for k in range(60)]
    panel, pages = panel_view.render_panel(
        (160, 120), "Demos", [("", rows)], font=font, title_font=font, small_font=font, page_key=None
    )
    assert pages > 1 and panel.get_size() == (160, 120)


def test_f11_lets_go_of_a_held_puck(demos):
    """F11 moves the window under the pointer at the window manager's own pace: the string's end would jump
    with the pointer's place in the window (a user test: 243 J after F11 and back). The puck is let go."""
    app = App(demos, demo_key="1", headless=True)
    pygame.event.clear()
    puck = app.table.pucks[0]
    at = tuple(int(round(v)) for v in app.env.to_screen(puck.pos_m))
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=at, button=1))
    app.frame(FRAME_S)
    assert app.local.held is puck
    before = app.table.kinetic_energy_J()  # (the grab's own small tug: a pixel off the centre)
    press(app, pygame.K_F11, frames=2)
    assert app.local.held is None and app.table.kinetic_energy_J() <= before * (1 + 1e-9)


def test_a_narrow_values_panel_keeps_momentum_and_kinetic_energy():
    """In fullscreen's side margin the values table kept mass and speed and lost KE (a user test): the
    columns go mass first, then speed."""
    from airtable.app.lessons_paint import shown_columns

    widths = (50, 60, 70, 80, 90)  # puck, m, |v|, |p|, KE
    assert shown_columns(widths, 350) == [0, 1, 2, 3, 4]
    assert shown_columns(widths, 290) == [0, 2, 3, 4]  # no room for mass
    assert shown_columns(widths, 220) == [0, 3, 4]  # nor for speed
    assert shown_columns(widths, 130) == [0, 3]
