"""Change the world live: restitution, gravity, a puck's mass and radius, by real key events to a headless App."""

from __future__ import annotations

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, press

from airtable.app.app import App
from airtable.app.world import gravity_label, ladder_step, next_gravity, step_restitution
from airtable.physics.table import AirTable

SHIFT = pygame.KMOD_LSHIFT


def test_restitution_steps_in_tenths_within_0_and_1():
    assert step_restitution(1.0, -1) == 0.9
    assert step_restitution(0.9, -1) == 0.8
    assert step_restitution(0.7, +1) == 0.8
    assert step_restitution(0.93, -1) == 0.9 and step_restitution(0.93, +1) == 1.0
    assert step_restitution(0.0, -1) == 0.0 and step_restitution(1.0, +1) == 1.0
    value, seen = 1.0, []
    for _ in range(12):
        value = step_restitution(value, -1)
        seen.append(value)
    assert seen == [0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1, 0.0, 0.0, 0.0]


def test_gravity_steps_and_label():
    assert next_gravity(False, 9.8) == (1.62, "Moon")
    assert next_gravity(True, 1.62) == (3.71, "Mars")
    assert next_gravity(True, 3.71) == (9.8, "Earth")
    assert next_gravity(True, 9.8) == (0.0, "off")
    assert next_gravity(True, 5.0) == (9.8, "Earth")  # a strength a demo set: on to the next above it
    t = AirTable()
    assert gravity_label(t) == "gravity off"
    t.gravity_on = True
    assert gravity_label(t) == "gravity on"
    t.gravity_mps2 = 3.71
    assert gravity_label(t) == "gravity 3.71 m/s² (Mars)"


def test_ladder_steps():
    assert ladder_step(1.0, +1, 0.001, 1000) == 1.2
    assert ladder_step(0.1, -1, 0.001, 1000) == 0.08
    assert ladder_step(0.12, +1, 0.001, 1000) == 0.15
    assert ladder_step(0.19085, +1, 0.001, 1000) == 0.2  # off the ladder: the next rung
    assert ladder_step(0.19085, -1, 0.001, 1000) == 0.15
    assert ladder_step(8.0, +1, 0.001, 1000) == 10.0
    assert ladder_step(1000.0, +1, 0.001, 1000) == 1000.0  # kept within the range
    assert ladder_step(0.05, -1, 0.05, 2.0) == 0.05


@pytest.fixture
def app(demos):
    a = App(demos, demo_key="1", headless=True)  # five pucks, restitution 1, gravity off
    pygame.event.clear()
    yield a
    pygame.event.clear()


def test_restitution_keys(app):
    press(app, pygame.K_u)
    assert (app.table.cr_puck, app.table.cr_wall) == (0.9, 1.0)
    assert app.message == "restitution of pucks (puck on puck): 0.9" and app.message in app.hud_lines()
    assert "restitution: pucks 0.9, walls 1" in app.status_line()
    for _ in range(3):
        press(app, pygame.K_w)
    assert app.table.cr_wall == 0.7 and app.message == "restitution of walls: 0.7"
    press(app, pygame.K_w, mod=SHIFT)
    press(app, pygame.K_u, mod=SHIFT)
    assert (app.table.cr_puck, app.table.cr_wall) == (1.0, 0.8)
    assert "restitution: pucks 1, walls 0.8" in app.scene().status  # what the students' windows show


def test_gravity_key_cycles_and_the_physics_follows(app):
    press(app, pygame.K_g, mod=SHIFT)
    t = app.table
    assert t.gravity_on and t.gravity_mps2 == 1.62
    assert app.message == "gravity 1.62 m/s² (Moon)" and "gravity 1.62 m/s² (Moon)" in app.status_line()
    assert (t.cr_puck, t.cr_wall) == (1.0, 1.0)  # unlike g, the restitution stays
    # One frame of 4 steps of 1/240 s later, a puck in free fall has 1.62 * 4 / 240 m/s more downward speed.
    row = int(np.argmax(t.pos_m[:, 1]))  # the highest puck: nothing below it in 4 steps
    v0 = float(t.vel_mps[row, 1])
    app.frame(FRAME_S)
    assert t.vel_mps[row, 1] == pytest.approx(v0 - 1.62 * 4 / 240)
    press(app, pygame.K_g, mod=SHIFT)
    press(app, pygame.K_g, mod=SHIFT)
    assert t.gravity_mps2 == 9.8 and "gravity on" in app.status_line()
    press(app, pygame.K_g, mod=SHIFT)
    assert not t.gravity_on and app.message == "gravity off"
    press(app, pygame.K_1)  # a new demo starts from Earth's gravity, off
    assert t.gravity_mps2 == 9.8


def hover(app: App, row: int) -> None:
    x, y = app.env.to_screen(app.table.pos_m[row])
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=(int(x), int(y)), rel=(0, 0), buttons=(0, 0, 0)))
    app.frame(FRAME_S)


def test_mass_and_radius_of_the_puck_under_the_cursor(app):
    app.paused = True  # nothing moves while we point
    t = app.table
    row = int(np.argmax(t.radius_m))
    mass, radius, others = float(t.mass_kg[row]), float(t.radius_m[row]), t.mass_kg.copy()
    hover(app, row)
    press(app, pygame.K_EQUALS)
    up = ladder_step(mass, +1, 0.001, 1000)
    assert t.mass_kg[row] == up and t.radius_m[row] == radius
    assert app.message.startswith(f"puck {row + 1}: mass {up:g} kg")  # numbered from 1
    press(app, pygame.K_MINUS)
    press(app, pygame.K_MINUS)
    assert t.mass_kg[row] == ladder_step(ladder_step(up, -1, 0.001, 1000), -1, 0.001, 1000)
    press(app, pygame.K_RIGHTBRACKET)
    assert t.radius_m[row] == ladder_step(radius, +1, 0.05, 2.0) and app.message.startswith(f"puck {row + 1}: radius")
    assert np.array_equal(np.delete(t.mass_kg, row), np.delete(others, row))  # only that puck changed
    # Nothing under the cursor: nothing changes, and the message says what to do.
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=(1, 1), rel=(0, 0), buttons=(0, 0, 0)))
    before = (t.mass_kg.copy(), t.radius_m.copy())
    press(app, pygame.K_EQUALS)
    assert np.array_equal(t.mass_kg, before[0]) and np.array_equal(t.radius_m, before[1])
    assert "put the cursor on a puck" in app.message


def test_a_bigger_puck_collides_at_its_new_size():
    """The physics sees a radius changed by hand at once (no stale neighbour list)."""
    t = AirTable()
    a = t.add_puck((3.0, 4.0), radius_m=0.5)
    b = t.add_puck((4.5, 4.0), radius_m=0.5)
    t.step(1 / 240)
    assert t.collision_count == 0 and b.pos_m[0] == 4.5
    t.radius_m[a.index] = 1.2  # now they overlap by 0.2 m: pushed apart at once
    t.step(1 / 240)
    assert b.pos_m[0] - a.pos_m[0] == pytest.approx(1.7)
