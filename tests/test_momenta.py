"""The momenta diagram and the values panel: their numbers by hand, and the keys that show them."""

from __future__ import annotations

import math

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, press
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable.app.app import App
from airtable.app.lessons_paint import TOTAL_COLOR, fitting, momenta_scale, momenta_titles, total_texts, values_hint
from airtable.app.panel_view import ACCENT
from airtable.model.momenta import (
    FEW_PUCKS,
    MomentaLog,
    MomentaView,
    every_puck_values,
    fit_chains,
    momenta_around_collisions,
    tip_to_tail,
    values_for,
)
from airtable.physics.table import AirTable


def test_tip_to_tail():
    tails, tips = tip_to_tail(np.array([[1.0, 0.0], [0.0, 2.0], [-3.0, 1.0]]))
    assert tails.tolist() == [[0.0, 0.0], [1.0, 0.0], [1.0, 2.0]]
    assert tips.tolist() == [[1.0, 0.0], [1.0, 2.0], [-2.0, 3.0]]  # the last tip is the total


def head_on_table() -> AirTable:
    """1 kg at 2 m/s onto a still 3 kg puck, head on; a third puck far away drifts up."""
    t = AirTable()
    t.add_puck((2.0, 4.0), radius_m=0.3, vel_mps=(2.0, 0.0))
    t.add_puck((3.0, 4.0), radius_m=0.3)
    t.add_puck((8.0, 1.0), radius_m=0.3, vel_mps=(0.0, 0.5))
    t.mass_kg[:] = (1.0, 3.0, 0.5)
    return t


def test_momenta_before_and_after_an_elastic_head_on_hit():
    t, log = head_on_table(), MomentaLog()
    for _ in range(200):
        t.step(1 / 240)
        log.observe(t)
        if log.latest is not None:
            break
    m = log.latest
    assert m is not None and m.collided.tolist() == [True, True, False]
    # Elastic, 1 kg at 2 m/s on 3 kg at rest: v1 = (1 - 3) / 4 * 2 = -1 m/s, v2 = 2 * 1 / 4 * 2 = 1 m/s.
    assert m.before_Ns[:2].tolist() == [[2.0, 0.0], [0.0, 0.0]]
    assert m.after_Ns[0] == pytest.approx([-1.0, 0.0]) and m.after_Ns[1] == pytest.approx([3.0, 0.0])
    assert m.before_Ns[2].tolist() == m.after_Ns[2].tolist() == [0.0, 0.25]
    assert m.total_before_Ns == pytest.approx([2.0, 0.25]) and m.total_after_Ns == pytest.approx([2.0, 0.25])
    assert m.t_s == t.time_s
    t.step(1 / 240)
    assert momenta_around_collisions(t) is None  # no collision this step: the log keeps the last one
    log.observe(t)
    assert log.latest is m


def first_collision(t: AirTable, dt_s: float, steps: int):
    """(The momenta around the first step of `t` that has a collision (None if none within `steps`), whether
    a puck hit a wall in that step)."""
    for _ in range(steps):
        walls = t.wall_collision_count
        t.step(dt_s)
        m = momenta_around_collisions(t)
        if m is not None:
            return m, t.wall_collision_count > walls
    return None, False


def gravity_scene(kind: str, speed: float, mass_ratio: float, mode: str) -> AirTable:
    """Two pucks under gravity: one sliding on the floor into another, two meeting in the air, or one
    dropped onto one resting on the floor."""
    t = AirTable()
    t.gravity_on, t.cr_puck, t.puck_correction = True, 1.0, mode
    if kind == "along the floor":
        t.add_puck((3.0, 0.2), radius_m=0.2, vel_mps=(speed, 0.0))
        t.add_puck((3.6, 0.2), radius_m=0.2)
    elif kind == "in the air":
        t.add_puck((3.0, 5.0), radius_m=0.2, vel_mps=(speed, 0.0))
        t.add_puck((3.6, 5.0), radius_m=0.2, vel_mps=(-speed, 0.0))
    else:
        t.add_puck((3.0, 0.2 + 0.4 + 3.0 * speed), radius_m=0.2)
        t.add_puck((3.0, 0.2), radius_m=0.2)
    t.mass_kg[1] *= mass_ratio
    return t


@settings(max_examples=40, deadline=None)
@given(
    kind=st.sampled_from(["along the floor", "in the air", "dropped onto one on the floor"]),
    speed=st.floats(0.1, 1.0),
    mass_ratio=st.floats(0.2, 5.0),
    dt_s=st.sampled_from([1 / 60, 1 / 120, 1 / 240]),
    mode=st.sampled_from(["two-step", "perfect-kiss"]),
)
def test_under_gravity_the_diagram_s_totals_are_the_same_before_and_after(kind, speed, mass_ratio, dt_s, mode):
    """User tests: with gravity on, a puck sliding on the floor into another showed "before |total| 0.01312,
    after 0.004524" (the floor took back gravity's g dt later in the step); two pucks meeting in the air
    showed gravity's M g dt as momentum gained (20.38 and 20.5 N s); one dropped onto a puck on the floor,
    the floor's push. The diagram is the collision's: what it found and what it left."""
    t = gravity_scene(kind, speed, mass_ratio, mode)
    m, walls = first_collision(
        t, dt_s, round((0.25 / speed + 1.0) / dt_s)
    )  # (they meet within 0.2 m / speed, or 0.8 s)
    assert m is not None and m.collided.tolist() == [True, True]
    scale = float(np.abs(m.before_Ns).sum())
    same = m.total_after_Ns == pytest.approx(m.total_before_Ns, rel=1e-12, abs=1e-12 * scale)
    title = momenta_titles(m.view)[0]
    # Only where a wall acted in the step, through a puck resting on it (the drop) or between two collisions,
    # the totals differ: the title says by how much, from outside.
    assert (
        (same and "outside" not in title)
        or (walls or kind == "dropped onto one on the floor")
        and ("from outside" in title and not same)
    )
    assert not np.array_equal(m.before_Ns, m.after_Ns)
    if kind == "along the floor":  # found moving along the floor at its speed (and down by at most g dt)
        assert m.before_Ns[0, 0] == t.mass_kg[0] * speed and m.after_Ns[1, 0] > 0.0
        assert np.all(np.abs(m.before_Ns[:, 1]) <= t.mass_kg * t.gravity_mps2 * dt_s * (1 + 1e-12))


def test_one_scale_fits_both_chains():
    fit = fit_chains([np.array([[0.0, 0.0], [2.0, 0.0]]), np.array([[1.0, 1.0]])], (100, 100), margin=0.1)
    assert fit.px_per_Ns == 40.0  # 80 px for the 2 N s of the first; the second would take 80
    assert fit.centers_Ns == ((1.0, 0.0), (0.5, 0.5))
    assert fit.to_px(0, np.array([[0.0, 0.0], [2.0, 0.0]]), (100, 100)).tolist() == [[10.0, 50.0], [90.0, 50.0]]
    assert fit.to_px(1, np.array([[1.0, 1.0]]), (100, 100)).tolist() == [[70.0, 30.0]]  # y up is up the screen


def test_values_of_few_pucks_and_of_the_puck_under_the_cursor():
    t = AirTable()
    t.add_puck((2.0, 2.0), vel_mps=(3.0, 4.0))
    t.add_puck((5.0, 2.0), vel_mps=(0.0, -1.0))
    t.mass_kg[:] = (1.0, 2.0)
    rows = values_for(t, None)
    assert [(r.name, r.mass_kg, r.speed_mps, r.momentum_Ns, r.kinetic_J) for r in rows[:2]] == [
        ("1", 1.0, 5.0, 5.0, 12.5),  # numbered from 1, as everywhere
        ("2", 2.0, 1.0, 2.0, 1.0),
    ]
    total = rows[2]
    assert (total.name, total.mass_kg, total.speed_mps, total.kinetic_J) == ("total", 3.0, None, 13.5)
    assert total.momentum_Ns == pytest.approx(math.hypot(3.0, 2.0))
    assert total.cells() == ("total", "3", "", "3.61", "13.5")
    for k in range(5):
        t.add_puck((1.0 + k, 6.0))
    assert values_for(t, None) == []  # seven pucks: only the one under the cursor
    assert [(r.name, r.row) for r in values_for(t, 1)] == [("2", 1)]


def test_a_cradles_still_pucks_show_zero_not_round_off():
    # After a cradle's hit the still pucks keep 1e-13 m/s of round-off; equal and opposite momenta sum to 1e-17.
    rows = every_puck_values(np.array([0.2, 0.2, 0.2]), np.array([[1e-13, 0.0], [-2e-14, 0.0], [4.0, 0.0]]))
    assert [r.cells()[2:] for r in rows[:3]] == [("0", "0", "0"), ("0", "0", "0"), ("4", "0.8", "1.6")]
    opposite = every_puck_values(np.array([0.2, 0.2]), np.array([[1.0, 0.0], [-1.0 + 1e-16, 0.0]]))
    assert opposite[2].cells() == ("total", "0.4", "", "0", "0.2")


def pixels_of(app: App, color) -> int:
    image = pygame.surfarray.pixels3d(app.window.surface)
    count = int(np.count_nonzero(np.all(image == np.array(color, dtype=np.uint8), axis=2)))
    del image
    return count


@pytest.fixture
def app(demos):
    a = App(demos, demo_key="8", headless=True, window_size_px=(1280, 720))  # the pool line
    pygame.event.clear()
    yield a
    pygame.event.clear()


def test_d_shows_the_momenta_of_the_latest_collision(app):
    assert pixels_of(app, TOTAL_COLOR) == 0
    press(app, pygame.K_d)
    assert app.lessons.show_momenta
    for _ in range(240):
        app.frame(FRAME_S)
        if app.lessons.momenta.latest is not None:
            break
    m = app.lessons.momenta.latest
    assert m is not None and np.count_nonzero(m.collided) >= 2
    assert m.total_after_Ns == pytest.approx(m.total_before_Ns, abs=1e-12)
    app.draw()
    assert pixels_of(app, TOTAL_COLOR) > 100  # the two totals' arrows and their lines of text
    press(app, pygame.K_d)
    assert not app.lessons.show_momenta and pixels_of(app, TOTAL_COLOR) == 0
    press(app, pygame.K_8)  # a new demo: no collision seen yet
    assert app.lessons.momenta.latest is None


def test_t_shows_the_values_panel(app):
    press(app, pygame.K_1)  # five pucks: each one, and the total in the accent colour
    assert pixels_of(app, ACCENT) == 0
    press(app, pygame.K_t)
    assert app.lessons.show_values and pixels_of(app, ACCENT) > 20
    press(app, pygame.K_t)
    assert pixels_of(app, ACCENT) == 0


def test_the_panels_and_the_chart_take_different_corners(app):
    press(app, pygame.K_1)
    press(app, pygame.K_d)
    press(app, pygame.K_t)  # both panels choose while the chart is closed
    first = dict(app.lessons.painter.corners)
    assert first["momenta"] != first["values"]
    press(app, pygame.K_c)  # the chart takes the corner over the fewest pucks; a panel there moves
    corners = app.lessons.painter.corners
    assert len({corners["momenta"], corners["values"], app.painter.chart_corner}) == 3


def test_round_off_shows_as_zero_and_the_totals_fit_their_box():
    m = MomentaView(
        1.0, np.arange(2), np.array([[0.0954, 0.0], [0.0, 0.0]]), np.array([[0.02, 0.05], [0.0754, -0.05]]),
        np.array([0.0954, 0.0]), np.array([0.0954, 1.39e-17]), np.zeros((2, 3), np.uint8),
    )  # fmt: skip
    assert momenta_scale(m) == pytest.approx(0.0954)
    components, size = total_texts(m.total_after_Ns, momenta_scale(m))
    assert components[0] == "total (0.0954, 0) N s" and size[0] == "|total| 0.0954 N s"
    pygame.font.init()
    font = pygame.font.Font(None, 20)
    narrow = font.size("(0.0954, 0) N s")[0]
    assert fitting(font, components, narrow) == "(0.0954, 0) N s"  # the longest that fits
    assert font.size(fitting(font, components, 20))[0] <= 20  # none fits: cut


@pytest.mark.parametrize("size", [(640, 480), (1280, 720)])
def test_the_panels_stand_clear_of_paused_and_the_timeline(demos, size):
    app = App(demos, demo_key="8", headless=True, window_size_px=size)
    pygame.event.clear()
    press(app, pygame.K_d)
    press(app, pygame.K_t)
    for _ in range(240):
        app.frame(FRAME_S)
        if app.lessons.momenta.latest is not None:
            break
    press(app, pygame.K_SPACE)  # paused: PAUSED at the top, the timeline bar at the bottom
    drawn = {}
    paint = app.lessons.painter
    for name in ("momenta_diagram", "values_panel"):
        original = getattr(paint, name)
        setattr(paint, name, lambda *a, _f=original, _n=name: drawn.setdefault(_n, _f(*a)))
    app.draw()
    # PAUSED, the bar, the HUD ... (the panels' own lines, recorded too, lie inside them)
    panels = list(drawn.values())
    others = [b for b in app.window.label_boxes if b not in panels and not any(p.contains(b) for p in panels)]
    assert len(drawn) == 2 and app.rewind.timeline_shown() is not None
    for rect in drawn.values():
        assert app.window.surface.get_rect().contains(rect)
        assert rect.collidelist(others) < 0, (rect, others)
    assert not drawn["momenta_diagram"].colliderect(drawn["values_panel"])


def test_the_values_hint_says_when_the_table_is_empty():
    """A user test: on the empty table a failed build left, t said "values: more than 6 pucks, so point at one"."""
    assert values_hint(0) == "values: no pucks on the table"
    assert values_hint(FEW_PUCKS + 1).startswith(f"values: more than {FEW_PUCKS} pucks")
