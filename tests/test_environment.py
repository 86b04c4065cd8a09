"""Environment: the world (m, y up) <-> screen (px, y down) transform, zoom and pan."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable import Environment

coords_m = st.floats(-1e3, 1e3)
coords_px = st.floats(-1e4, 1e4)


@st.composite
def views(draw) -> Environment:
    """An environment zoomed and panned somewhere."""
    env = Environment()
    env.zoom_about((draw(st.floats(0, 900)), draw(st.floats(0, 788))), draw(st.floats(0.05, 50.0)))
    env.pan((draw(coords_px), draw(coords_px)))
    return env


def test_default_view_shows_10_m_across_with_y_flipped() -> None:
    env = Environment()
    assert env.size_px == (900, 788)
    assert env.px_per_m == pytest.approx(90.0)
    assert env.view_height_m == pytest.approx(8.7556, abs=1e-4)
    np.testing.assert_allclose(env.to_screen((0.0, 0.0)), (0.0, 788.0))  # bottom-left pixel
    np.testing.assert_allclose(env.to_screen((10.0, 0.0)), (900.0, 788.0))
    np.testing.assert_allclose(env.to_screen((0.0, 788 / 90)), (0.0, 0.0), atol=1e-9)  # top-left
    # World y up is screen y down.
    a, b = env.to_screen([(3.0, 1.0), (3.0, 2.0)])
    assert b[1] - a[1] == pytest.approx(-90.0)
    assert b[0] == a[0]


@settings(max_examples=200, deadline=None, derandomize=True)
@given(views(), st.lists(st.tuples(coords_m, coords_m), min_size=1, max_size=20))
def test_world_screen_world_round_trip(env: Environment, points: list[tuple[float, float]]) -> None:
    world = np.array(points)
    back = env.to_world(env.to_screen(world))
    np.testing.assert_allclose(back, world, rtol=1e-9, atol=1e-9)
    one = env.to_world(env.to_screen(world[0]))  # a single (2,) point works too
    assert one.shape == (2,)
    np.testing.assert_allclose(one, world[0], rtol=1e-9, atol=1e-9)


@settings(max_examples=200, deadline=None, derandomize=True)
@given(views(), st.floats(0, 900), st.floats(0, 788), st.floats(0.5, 2.0))
def test_zoom_about_keeps_the_point_under_the_cursor(env: Environment, x: float, y: float, factor: float) -> None:
    under = env.to_world((x, y))
    zoom = env.zoom
    env.zoom_about((x, y), factor)
    np.testing.assert_allclose(env.to_world((x, y)), under, rtol=1e-9, atol=1e-9)
    assert env.zoom == pytest.approx(np.clip(zoom * factor, 0.05, 200.0))


def test_zoom_in_doubles_lengths() -> None:
    env = Environment()
    env.zoom_about((450, 394), 2.0)
    assert env.length_to_px(1.0) == pytest.approx(180.0)
    a, b = env.to_screen([(5.0, 4.0), (6.0, 4.0)])
    assert b[0] - a[0] == pytest.approx(180.0)


@settings(max_examples=100, deadline=None, derandomize=True)
@given(views(), st.floats(-500, 500), st.floats(-500, 500))
def test_pan_moves_the_world_with_the_drag(env: Environment, dx: float, dy: float) -> None:
    world = np.array([[1.0, 2.0], [-3.0, 7.5]])
    before = env.to_screen(world)
    env.pan((dx, dy))
    np.testing.assert_allclose(env.to_screen(world) - before, [[dx, dy], [dx, dy]], atol=1e-6)


def test_reset_restores_the_default_view() -> None:
    env = Environment()
    env.zoom_about((100, 200), 3.0)
    env.pan((40, -25))
    env.reset()
    assert env.zoom == 1.0
    np.testing.assert_allclose(env.to_screen((0.0, 0.0)), (0.0, 788.0))
    np.testing.assert_allclose(env.to_screen((10.0, 788 / 90)), (900.0, 0.0), atol=1e-9)


def test_bad_window_size_raises() -> None:
    with pytest.raises(ValueError, match="positive"):
        Environment(size_px=(0, 788))
