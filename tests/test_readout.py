"""Numbers a class can read: round-off of the scene's scale shows as 0 in the chart, its axis, the values
panel and the momenta diagram, and real values stay as they are."""

from __future__ import annotations

import math

import numpy as np
import pygame
import pytest
from conftest import press

from airtable.app.aids_paint import chart_top
from airtable.app.app import App
from airtable.app.lessons_paint import total_texts
from airtable.model.aids import EnergyChart
from airtable.model.momenta import values_for
from airtable.model.readout import ROUND_OFF, SceneScale, readable
from airtable.physics.table import AirTable


def test_readable_by_hand():
    assert readable(1.73e-16, 66.9) == 0.0 and readable(-1.79e-15, 30.7) == 0.0
    assert math.copysign(1.0, readable(-1e-20, 1.0)) == 1.0  # never -0
    assert readable(1.5e-6, 66.9) == 1.5e-6 and readable(-2.0, 1.0) == -2.0
    assert readable(1e-30, 0.0) == 1e-30  # a scene with no scale yet hides nothing but 0


def test_the_scene_scale_by_hand():
    s = SceneScale()
    s.observe((2.0, -1.0, 0.5), 0.0, mass_kg=4.0)  # |2| + |-1| + |0.5| = 3.5 J; sqrt(2 * 4 * 3.5) = 5.29 N s
    assert s.energy_J == 3.5 and s.momentum_Ns == pytest.approx(math.sqrt(28.0))
    s.observe((0.1, 0.0, 0.0), 9.0, mass_kg=4.0)  # the largest seen stays
    assert s.energy_J == 3.5 and s.momentum_Ns == 9.0
    assert s.energy(3.5 * ROUND_OFF) == 0.0 and s.energy(4 * ROUND_OFF) == 4 * ROUND_OFF
    s.clear()
    assert (s.energy_J, s.momentum_Ns) == (0.0, 0.0)


@pytest.fixture(scope="module")
def settled_triangle(demos):
    """Demo 6, a corner pulled 0.8 m out, after 10 s: the damped triangle at rest, with round-off left in its
    energy and momentum."""
    table, chart = AirTable(), EnergyChart()
    demos["6"].build(table, 0)
    table.pos_m[3, 0] += 0.8  # the demo starts at rest length: stretch two springs to set it ringing
    chart.sample(table)
    for _ in range(2400):
        table.step(demos["6"].dt_s)
        chart.sample(table)
    return table, chart


def test_a_settled_spring_triangle_reads_0_in_the_chart_and_the_values(settled_triangle):
    table, chart = settled_triangle
    ke, p = table.kinetic_energy_J(), float(np.hypot(*table.momentum_Ns()))
    assert 0 < ke < 1e-12 and 0 < p < 1e-12  # what the issue saw: 1.7e-16 J, 1.8e-15 N s
    latest = chart.latest()
    assert latest["kinetic_J"] == 0.0 and latest["momentum_Ns"] == 0.0 and latest["total_J"] == 0.0
    assert chart.scale.energy_J > 60.0  # the spring energy it started with (the pulled corner's)
    rows = values_for(table, None, chart.scale)
    assert [r.cells()[2:] for r in rows] == [("0", "0", "0")] * 4 + [("", "0", "0")]  # the triangle, the free puck
    # The momenta diagram's totals, at the scale of the first collision's momenta (about 3 N s).
    assert total_texts(table.momentum_Ns(), 3.0)[0][0] == "total (0, 0) N s"


def test_real_values_are_shown_as_they_are(demos):
    table, chart = AirTable(), EnergyChart()
    demos["5"].build(table, 0)  # the spring pair, thrown
    for _ in range(240):
        table.step(demos["5"].dt_s)
        chart.sample(table)
    latest = chart.latest()
    assert latest["kinetic_J"] == table.kinetic_energy_J() > 0.001
    assert latest["spring_J"] == table.spring_energy_J()
    assert latest["momentum_Ns"] == float(np.hypot(*table.momentum_Ns()))


def test_a_still_tables_chart_axis_reads_0_j(demos):
    app = App(demos, demo_key="1", headless=True)  # five pucks at rest: nothing has moved
    pygame.event.clear()
    press(app, pygame.K_c, frames=30)
    series, latest = app.aids.chart.series(), app.aids.chart.latest()
    assert len(series["time_s"]) > 2 and latest["total_J"] == 0.0
    assert f"{chart_top(series['total_J'], latest['energy_scale_J']):.3g} J" == "0 J"  # not 1.1e-12 J
    assert chart_top(np.array([0.0, 2.0]), 1.0) == 2.5  # the first round step 5 % above 2 J


def test_the_values_panel_of_the_app_uses_the_scene_scale(demos):
    app = App(demos, demo_key="7", headless=True)  # Newton's cradle: still pucks keep round-off after a hit
    pygame.event.clear()
    press(app, pygame.K_t, frames=240)
    assert app.table.collision_count > 0
    rows = values_for(app.table, None, app.aids.chart.scale)
    speeds = [r.speed_mps for r in rows[:-1]]
    assert sum(1 for s in speeds if s == 0.0) >= 1 and max(speeds) > 0.1
    raw = np.hypot(app.table.vel_mps[:, 0], app.table.vel_mps[:, 1])
    for r, v in zip(rows[:-1], raw, strict=True):
        small = v * app.table.mass_kg[r.row] <= ROUND_OFF * app.aids.chart.scale.momentum_Ns
        assert r.speed_mps == (0.0 if small else v)


def test_figures_read_as_a_class_reads_them():
    """The chart's axis read '2e+03 J' and the values '1.39e+03' (a user test): no exponent from 0.001 to a
    million, every digit of a whole number, the exponent only beyond."""
    from airtable.model.readout import figures

    assert [figures(v) for v in (2000.0, 1390.4, 999.6, 12.34, 0.5, 0.0123, 0.001)] == [
        "2000", "1390", "1000", "12.3", "0.5", "0.0123", "0.001",
    ]  # fmt: skip
    assert [figures(v, 4) for v in (1390.4, 12.345, 123456.7, -2000.0)] == ["1390", "12.35", "123457", "-2000"]
    assert [figures(v) for v in (0.0, -0.0, 1e7, 1.5e-5)] == ["0", "0", "1e+07", "1.5e-05"]
