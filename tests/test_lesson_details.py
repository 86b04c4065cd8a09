"""The small things of a lesson: one puck numbering from 1 and the key that shows it, the momenta of a collision
that came before the diagram was opened, messages that end with their demo or fit a small window, and the
starter demo's defaults."""

from __future__ import annotations

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, press

from airtable.app.aids_view import inspector_lines
from airtable.app.app import App
from airtable.app.demo_loader import discover
from airtable.app.predict import puck_summary
from airtable.cli import main
from airtable.model.momenta import puck_values
from airtable.physics.table import AirTable

WHITE = (255, 255, 255)


def run(app: App, frames: int) -> None:
    for _ in range(frames):
        app.frame(FRAME_S)


@pytest.fixture
def app(demos):
    a = App(demos, demo_key="1", headless=True, window_size_px=(900, 788))
    pygame.event.clear()
    return a


def white_pixels_at(app: App, row: int, half_px: int = 6) -> int:
    x, y = (int(v) for v in app.env.to_screen(app.table.pos_m[row]))
    area = pygame.surfarray.array3d(app.window.surface)[x - half_px : x + half_px, y - half_px : y + half_px]
    return int(np.count_nonzero(np.all(area == WHITE, axis=2)))


def test_pucks_are_numbered_from_1_in_values_predict_and_inspect(app):
    t = app.table
    names = [v.name for v in puck_values(t.mass_kg, t.vel_mps, range(len(t.pos_m)))]
    assert names == ["1", "2", "3", "4", "5"]
    assert puck_summary(0, (1.0, 0.0), []).startswith("puck 1:")
    assert inspector_lines(t, t.pucks[2])[0] == "puck 3"


def test_k_draws_each_pucks_number_on_it(app):
    run(app, 1)
    before = [white_pixels_at(app, k) for k in range(5)]
    press(app, pygame.K_k)
    assert app.lessons.show_numbers and "numbers shown" in app.message
    after = [white_pixels_at(app, k) for k in range(5)]
    assert all(a > b + 5 for a, b in zip(after, before, strict=True)), (before, after)
    press(app, pygame.K_k)
    assert not app.lessons.show_numbers
    assert [white_pixels_at(app, k) for k in range(5)] == before


def test_the_momenta_diagram_shows_a_collision_from_before_it_was_opened(demos):
    app = App(demos, demo_key="8", headless=True)  # the pool line: the cue hits at once
    pygame.event.clear()
    run(app, 120)
    assert app.table.collision_count > 0 and not app.lessons.show_momenta
    press(app, pygame.K_d, frames=0)
    latest = app.lessons.momenta.latest
    assert latest is not None and 0 < latest.t_s <= app.table.time_s
    assert latest.collided.any()
    # Equal and opposite: the total is the same before and after; the pucks that collided changed (a puck
    # between two hits of the step may pass its momentum on and end as it began), the others did not.
    assert np.allclose(latest.total_before_Ns, latest.total_after_Ns, rtol=0, atol=1e-12)
    changed = np.any(latest.before_Ns != latest.after_Ns, axis=1)
    assert changed.any() and not (changed & ~latest.collided).any()


def test_rewound_to_before_the_latest_collision_the_diagram_shows_none_yet(demos):
    """A user test: rewound to t = 0.45 s ("0 collisions"), the diagram showed the collision at t = 0.67 s,
    still to come on screen; back at it, the diagram shows it again."""
    app = App(demos, demo_key="8", headless=True)
    pygame.event.clear()
    run(app, 120)
    press(app, pygame.K_d, frames=0)
    latest = app.lessons.momenta.latest
    assert latest is not None and app.lessons.momenta_shown(app.table) is latest.view
    press(app, pygame.K_SPACE)  # pause, then back a second and more
    for _ in range(3):
        press(app, pygame.K_COMMA, mod=pygame.KMOD_LSHIFT)
    assert app.table.time_s < latest.t_s and app.lessons.momenta_shown(app.table) is None
    for _ in range(4):
        press(app, pygame.K_PERIOD, mod=pygame.KMOD_LSHIFT)
    assert app.table.time_s >= latest.t_s and app.lessons.momenta_shown(app.table) is latest.view


def test_a_restart_takes_away_the_old_demos_messages_but_not_where_a_file_went(app, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    run(app, 60)
    press(app, pygame.K_SPACE)
    for _ in range(5):
        press(app, pygame.K_COMMA)
    press(app, pygame.K_SPACE)
    assert app.message.startswith("running on from t = ") and app.message in app.hud_lines()
    press(app, pygame.K_1)  # the demo starts again
    assert app.message == "" and not app.hud_lines()
    press(app, pygame.K_x)
    said = app.message
    assert said.startswith("recorded ")
    press(app, pygame.K_1)
    assert app.message == said  # where the file went stays its few seconds


@pytest.mark.parametrize("size", [(640, 480), (1280, 720)])
def test_the_export_message_fits_a_small_window(demos, tmp_path, monkeypatch, size):
    monkeypatch.chdir(tmp_path)
    app = App(demos, demo_key="5", headless=True, window_size_px=size)
    pygame.event.clear()
    run(app, 30)
    press(app, pygame.K_x)
    font = app.window.font
    pad = font.get_height() // 2
    assert font.size(app.message)[0] <= size[0] - 2 * pad, app.message
    assert "recordings/demo5-" in app.message


def test_the_starter_demo_sets_the_defaults_it_says_it_sets(tmp_path):
    path = tmp_path / "mine.py"
    assert main(["--new-demo", str(path)]) == 0
    text = path.read_text(encoding="utf-8")
    assert "(these are the defaults)" in text
    found, errors = discover([tmp_path])
    assert not errors
    fresh, built = AirTable(), AirTable()
    found["t1"].build(built, 0)
    for setting in ("gravity_on", "cr_puck", "cr_wall", "puck_correction"):
        assert getattr(built, setting) == getattr(fresh, setting), setting
    assert built.puck_correction == "perfect-kiss"
