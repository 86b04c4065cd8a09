"""A spring too stiff for the step is softened, and the teacher is told: once, and by `i`."""

from __future__ import annotations

import pygame
from conftest import FRAME_S

from airtable.app.aids_view import inspector_lines
from airtable.app.app import App
from airtable.physics.table import AirTable

# Two 9 g pucks 1 m apart: k dt^2 / mu passes the softening limit (1e6) near 2.6e8 N/m at 1/240 s.
LIGHT_DENSITY = 0.009 / (3.141592653589793 * 0.1**2)
TOO_STIFF_NPM = 1e12


def _stiff_pair(table: AirTable):
    a = table.add_puck(pos_m=(4.0, 4.0), radius_m=0.1, density_kgpm2=LIGHT_DENSITY)
    b = table.add_puck(pos_m=(5.0, 4.0), radius_m=0.1, density_kgpm2=LIGHT_DENSITY)
    return a, table.add_spring(a, b, length_m=1.0, k_Npm=TOO_STIFF_NPM, damper_Nspm=0.0)


def test_the_inspector_shows_the_stiffness_a_softened_spring_acts_with() -> None:
    table = AirTable()
    a, spring = _stiff_pair(table)
    table.step(1 / 240)
    assert spring.k_effective_Npm < spring.k_Npm
    lines = inspector_lines(table, a)
    softened = f"acts with {spring.k_effective_Npm:.4g} N/m (softened)"
    assert f"spring to puck 2: k {TOO_STIFF_NPM:.4g} N/m, {softened}" in lines


def test_an_ordinary_spring_is_listed_without_softening() -> None:
    table = AirTable()
    a = table.add_puck(pos_m=(4.0, 4.0))
    b = table.add_puck(pos_m=(5.5, 4.0))
    table.add_spring(a, b, k_Npm=20.0)
    table.step(1 / 240)
    assert inspector_lines(table, a)[-1] == "spring to puck 2: k 20 N/m"


def test_the_inspector_shows_round_off_as_zero() -> None:
    """A settled demo 6 showed "speed 3.293e-14 m/s" and "kinetic energy 8.624e-28 J" (user test)."""
    from airtable.model.readout import SceneScale

    table = AirTable()
    a = table.add_puck(pos_m=(4.0, 4.0), vel_mps=(3.0e-14, -1.0e-14))
    scale = SceneScale()
    scale.observe((2.0, 0.0, 0.0), 1.5, float(table.mass_kg.sum()))  # the scene once had 2 J
    lines = inspector_lines(table, a, scale)
    assert "speed 0 m/s" in lines and "velocity (0.000, 0.000) m/s" in lines and "kinetic energy 0 J" in lines
    a.vel_mps = (0.25, 0.0)  # a real speed stays
    assert "speed 0.25 m/s" in inspector_lines(table, a, scale)


def test_a_gap_of_round_off_is_never_minus_zero() -> None:
    from airtable.model.readout import fixed

    assert fixed(-1e-9, 1) == "0.0" and fixed(-0.04, 1) == "0.0" and fixed(-0.06, 1) == "-0.1"


def test_the_app_says_each_notice_once(demos, capsys) -> None:
    app = App(demos, demo_key="5", headless=True)
    app.table.clear()
    _stiff_pair(app.table)
    app.frame(FRAME_S)
    assert app.table.notices, "softening a spring must leave a notice"
    said = app.message
    assert said in app.table.notices
    assert capsys.readouterr().err.count(said) == 1
    for _ in range(30):
        app.frame(FRAME_S)
    assert capsys.readouterr().err == ""  # not again while the scene lasts
    pygame.event.clear()


def test_the_inspector_says_when_a_puck_sleeps() -> None:
    # A puck laid on the floor under gravity, no bounce: still for 0.5 s, it falls asleep (physics/sleep.py).
    table = AirTable()
    table.gravity_on, table.cr_wall = True, 0.0
    puck = table.add_puck(pos_m=(5.0, 0.25), radius_m=0.25)
    table.step(1 / 240)
    assert not any(line.startswith("asleep") for line in inspector_lines(table, puck))
    for _ in range(240):
        table.step(1 / 240)
    assert table.asleep[puck.index]
    assert inspector_lines(table, puck)[-1] == "asleep: the step skips it until disturbed"
