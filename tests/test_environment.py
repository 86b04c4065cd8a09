"""Environment: the world (m, y up) <-> screen (px, y down) transform, zoom and pan."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable import Environment
from airtable.app.environment import fitting_size_px, parse_size

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


# ---------------------------------------------------------------- a window of any size

sizes_px = st.tuples(st.integers(200, 4000), st.integers(150, 2200))


@settings(max_examples=200, deadline=None, derandomize=True)
@given(views(), sizes_px, st.lists(st.tuples(coords_m, coords_m), min_size=1, max_size=20))
def test_round_trip_after_a_resize(env: Environment, size: tuple[int, int], points) -> None:
    env.resize(size)
    world = np.array(points)
    np.testing.assert_allclose(env.to_world(env.to_screen(world)), world, rtol=1e-9, atol=1e-9)
    screen = np.array([[0.0, 0.0], [size[0], size[1]], [size[0] / 3, size[1] / 7]])
    np.testing.assert_allclose(env.to_screen(env.to_world(screen)), screen, rtol=1e-9, atol=1e-6)


@settings(max_examples=100, deadline=None, derandomize=True)
@given(sizes_px)
def test_the_table_fits_any_window_centred_with_its_aspect_kept(size: tuple[int, int]) -> None:
    env = Environment(width_m=10.0, height_m=8.7556)
    env.resize(size)
    w, h = size
    (x0, y0), (x1, y1) = env.to_screen([(0.0, 8.7556), (10.0, 0.0)])  # top-left, bottom-right corners
    assert -1e-6 <= x0 and x1 <= w + 1e-6 and -1e-6 <= y0 and y1 <= h + 1e-6  # all of it shows
    assert (x1 - x0) / (y1 - y0) == pytest.approx(10.0 / 8.7556)  # not stretched
    assert min(x0, y0) == pytest.approx(0.0, abs=1e-6)  # it fills one direction
    assert x0 == pytest.approx(w - x1) and y0 == pytest.approx(h - y1)  # centred


@settings(max_examples=100, deadline=None, derandomize=True)
@given(sizes_px, st.integers(0, 120))
def test_the_table_fits_above_the_band_kept_for_the_status_line(size: tuple[int, int], band: int) -> None:
    env = Environment(width_m=10.0, height_m=8.7556)
    env.resize(size, bottom_px=band)
    w, h = size
    room = h - min(band, h / 2)  # a band of at most half the window
    (x0, y0), (x1, y1) = env.to_screen([(0.0, 8.7556), (10.0, 0.0)])  # top-left, bottom-right corners
    assert -1e-6 <= x0 and x1 <= w + 1e-6 and -1e-6 <= y0 and y1 <= room + 1e-6  # all of it, above the band
    assert (x1 - x0) / (y1 - y0) == pytest.approx(10.0 / 8.7556)  # not stretched
    assert min(x0, y0) == pytest.approx(0.0, abs=1e-6)  # it fills one direction
    assert x0 == pytest.approx(w - x1) and y0 == pytest.approx(room - y1)  # centred in the room left
    np.testing.assert_allclose(env.table_rect_px, (x0, y0, x1 - x0, y1 - y0), atol=1e-6)
    points = np.array([[0.0, 0.0], [3.3, 7.1], [10.0, 8.7556]])
    np.testing.assert_allclose(env.to_world(env.to_screen(points)), points, rtol=1e-9, atol=1e-9)


def test_zoom_and_pan_survive_a_resize() -> None:
    env = Environment(width_m=10.0, height_m=8.7556)
    env.zoom_about((300, 200), 3.0)
    env.pan((40, -25))
    centre_before = env.to_world((450, 394))  # the middle of the 900 x 788 window
    env.resize((1920, 1080))
    assert env.zoom == pytest.approx(3.0)
    np.testing.assert_allclose(env.to_world((960, 540)), centre_before, atol=1e-4)  # same spot in the middle
    assert env.px_per_m == pytest.approx(3.0 * 1080 / 8.7556)
    # Zooming about the cursor still keeps the point under it.
    under = env.to_world((100.0, 900.0))
    env.zoom_about((100.0, 900.0), 1.7)
    np.testing.assert_allclose(env.to_world((100.0, 900.0)), under, atol=1e-9)


def test_a_zoom_from_anywhere_is_clamped() -> None:
    env = Environment()
    env.zoom = 1e9  # e.g. a snapshot's zoom
    assert env.zoom == 200.0
    env.zoom = 0.0
    assert env.zoom == 0.05
    env.zoom = float("nan")
    assert env.zoom == 1.0


@pytest.mark.parametrize(
    ("desktop", "expected"),
    [((1280, 720), (739, 648)), ((1920, 1080), (1110, 972)), ((3840, 2160), (2220, 1944)), ((1000, 2000), (900, 788))],
)
def test_default_window_is_the_tables_shape_in_90_percent_of_the_desktop(desktop, expected) -> None:
    assert fitting_size_px(desktop, 10.0 / 8.7556) == pytest.approx(expected, abs=1)


def test_window_size_from_the_command_line() -> None:
    assert parse_size("1280x720") == (1280, 720)
    assert parse_size("1920X1080") == (1920, 1080)
    for bad in ("big", "1280", "10x10", "1280x720x3"):
        with pytest.raises(ValueError, match="1280x720|at least"):
            parse_size(bad)


def test_the_view_note_says_the_zoom_and_when_the_table_is_out_of_sight() -> None:
    """A user test: zoomed in on empty space the window was plain black, with no hint of the zoom."""
    env = Environment(width_m=10.0, height_m=8.7556)
    assert env.view_note()[0] == ""
    env.zoom_about((450, 394), 4.0)  # about the window's middle: the table fills it
    assert env.view_note()[0] == "zoom x4"
    env.pan((5000, 0))  # 5000 px to the right: the table's left edge is past the window's right
    assert env.view_note()[0] == "zoom x4, the table is out of sight"
    env.reset()
    env.pan((10, 0))  # panned a little, zoom 1: still a moved view
    assert env.view_note()[0] == "zoom x1"


def test_the_view_note_says_when_no_puck_is_in_sight() -> None:
    """A user test: zoomed x200 between the pucks the window was black, and the note said only the zoom."""
    env = Environment(width_m=10.0, height_m=8.7556)
    pos, radius = np.array([[2.0, 2.0], [7.0, 6.0]]), np.array([0.3, 0.5])
    env.zoom_about(env.to_screen((4.5, 4.0)), 200.0)  # 2 m from the nearest edge of a puck
    assert env.view_note(pos, radius)[0] == "zoom x200, no puck in sight"
    env.reset()
    env.zoom_about(env.to_screen((2.35, 2.0)), 200.0)  # 5 cm right of a puck's edge: the window is 4.5 cm wide
    half_width_m = 0.5 * env.size_px[0] / env.px_per_m
    assert half_width_m < 0.05
    assert env.view_note(pos, radius)[0] == "zoom x200, no puck in sight"
    env.zoom_about(env.to_screen((2.35, 2.0)), 0.1)  # x20: the window is 45 cm wide, the edge 5 cm away
    assert env.view_note(pos, radius)[0] == "zoom x20"
    assert env.view_note(np.empty((0, 2)), np.empty(0))[0] == "zoom x20, no puck in sight"
