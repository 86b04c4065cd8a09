"""Teaching aids: each toggles and changes the frame, and shows the physics' own numbers."""

from __future__ import annotations

import math

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, frames_until, post_key, press

from airtable.app.app import App
from airtable.app.demo_loader import BUILTIN_DIR, discover
from airtable.app.panel_view import ACCENT
from airtable.cli import main
from airtable.model import aids
from airtable.physics.table import AirTable


def make_app(demos, key="1", **kw) -> App:
    app = App(demos, demo_key=key, headless=True, **kw)
    pygame.event.clear()
    return app


def frame_pixels(app: App) -> np.ndarray:
    return pygame.surfarray.array3d(app.window.surface).copy()


def changed_fraction(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.mean(np.any(a != b, axis=2)))


def twin_frames(demos, key: str, toggle: int, setup=None, frames: int = 1):
    """Frames of two identical apps, one with the aid toggled: same physics, different drawing."""
    shots = []
    for with_aid in (False, True):
        app = make_app(demos, key)
        if setup:
            setup(app)
        if with_aid:
            post_key(toggle)
            post_key(toggle, down=False)
        for _ in range(frames):
            app.frame(FRAME_S)
        shots.append(frame_pixels(app))
    return shots


def fling(app: App) -> None:
    rng = np.random.default_rng(3)
    app.table.vel_mps[:] = rng.uniform(-2, 2, app.table.vel_mps.shape)


@pytest.mark.parametrize(
    "key, toggle, setup, frames",
    [
        ("2", pygame.K_e, fling, 30),  # trails
        ("2", pygame.K_v, fling, 2),  # vectors
        ("5", pygame.K_c, None, 30),  # energy chart
        ("1", pygame.K_l, None, 1),  # lecture notes
        ("1", pygame.K_F1, None, 1),  # help
    ],
)
def test_each_aid_changes_the_frame(demos, key, toggle, setup, frames):
    without, with_aid = twin_frames(demos, key, toggle, setup, frames)
    assert changed_fraction(without, with_aid) > 0.002


def test_annotations_draw_at_a_collision(demos):
    shots = []
    for on in (False, True):
        app = make_app(demos, "2p")
        if on:
            press(app, pygame.K_a)
        frames_until(app, lambda app=app: app.table.collision_count, what="the first collision", max_frames=600)
        app.frame(0.0)  # redraw without stepping
        shots.append(frame_pixels(app))
    assert changed_fraction(*shots) > 0.002


def test_annotations_fade_out(demos):
    app = make_app(demos, "2p")
    press(app, pygame.K_a)
    frames_until(app, lambda: app.table.collision_count, what="the first collision", max_frames=600)
    assert len(app.aids.collision_log.live(app.clock_s)) == 1
    app.paused = True
    for _ in range(int(aids.ANNOTATION_LIFE_S / FRAME_S) + 2):
        app.frame(FRAME_S)
    assert app.aids.collision_log.live(app.clock_s) == []


def test_inspector_shows_the_puck_under_the_cursor(demos):
    app = make_app(demos, "1")
    texts: list[str] = []
    original = app.painter.inspector
    app.painter.inspector = lambda point, r, lines: (texts.extend(lines), original(point, r, lines))
    puck = app.table.pucks[0]
    puck.vel_mps = (0.0, 0.0)
    x, y = app.env.to_screen(puck.pos_m)
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=(int(x), int(y)), rel=(0, 0), buttons=(0, 0, 0)))
    post_key(pygame.K_i)
    app.frame(FRAME_S)
    mass = 0.3 * math.pi * 0.25**2
    assert f"mass {mass:.4g} kg   radius 0.25 m" in texts
    assert "speed 0 m/s" in texts
    post_key(pygame.K_i, down=False)
    texts.clear()
    app.frame(FRAME_S)
    assert texts == []


def test_the_inspector_follows_the_puck_it_was_pressed_on_and_rings_it(demos):
    """In a gas the puck under a still cursor changed every frame: the inspector named a new one each time."""
    app = make_app(demos, "1")
    shown: list[tuple[str, tuple[float, float]]] = []
    original = app.painter.inspector
    app.painter.inspector = lambda point, r, lines: (shown.append((lines[0], tuple(point))), original(point, r, lines))
    puck = app.table.pucks[0]
    puck.vel_mps = (1.5, 0.0)  # it leaves the still cursor within a few frames
    x, y = app.env.to_screen(puck.pos_m)
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=(int(x), int(y)), rel=(0, 0), buttons=(0, 0, 0)))
    post_key(pygame.K_i)
    for _ in range(30):  # half a second: it moves 0.75 m, three of its radii
        app.frame(FRAME_S)
    assert {name for name, _ in shown} == {"puck 1"}
    assert len(shown) == 30 and shown[-1][1][0] - shown[0][1][0] > 0.5  # followed where it went
    ring = pygame.surfarray.array3d(app.window.surface)
    px = app.env.to_screen(puck.pos_m)
    r_px = int(0.25 * app.env.px_per_m + 2 * app.window.line_px(2))
    edge = ring[int(px[0]) + r_px - 1 : int(px[0]) + r_px + 2, int(px[1])]
    assert any(tuple(c) == ACCENT for c in edge)  # the ring just outside it
    post_key(pygame.K_i, down=False)
    app.frame(FRAME_S)
    assert app.aids.inspected is None  # let go: the next press picks afresh


def test_the_inspectors_words_leave_its_puck_and_the_status_line_in_view_even_in_a_corner_of_a_crowd(demos):
    """Near the bottom right corner of the gas the words covered the puck they describe and the status line."""
    app = make_app(demos, "0p")
    app.paused = True
    rects: list = []
    original = app.painter.label
    app.painter.label = lambda *a, **k: rects.append(original(*a, **k)) or rects[-1]
    px = app.env.to_screen(app.table.pos_m)
    w, h = app.window.surface.get_size()
    for k in np.argsort(np.hypot(px[:, 0] - w, px[:, 1] - h))[:5].tolist():  # the pucks nearest the corner
        at = (int(px[k, 0]), int(px[k, 1]))
        pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=at, rel=(0, 0), buttons=(0, 0, 0)))
        post_key(pygame.K_i)
        rects.clear()
        app.frame(FRAME_S)
        post_key(pygame.K_i, down=False)
        app.frame(FRAME_S)
        box = rects[-1]
        assert box is not None and app.window.surface.get_rect().contains(box)
        assert not box.collidepoint(at)  # its puck in view
        assert box.bottom <= app.window.status_top_px  # the status line too


def test_a_long_velocity_arrow_stops_above_the_status_line_and_below_the_top_band(demos):
    """A user test: the arrow of a fast puck near the table's bottom ran over the status line."""
    for down in (True, False):
        app = make_app(demos, "1")
        app.paused = True
        p = app.table.pucks[0]
        p.pos_m = (app.table.width_m / 2, p.radius_m * 1.01 if down else app.table.height_m - p.radius_m * 1.01)
        p.vel_mps = (0.0, -8.0 if down else 8.0)  # a 2 m/s scale: an arrow longer than the table is high
        press(app, pygame.K_v)
        pixels = frame_pixels(app)  # (x, y, rgb)
        arrow = np.all(pixels == (120, 220, 255), axis=2)
        w = app.window
        x = int(w.env.to_screen(np.array([p.pos_m]))[0, 0])
        column = arrow[x - 2 : x + 3]  # the arrow's shaft, straight up or down from the puck
        assert column.any()
        assert not column[:, w.status_top_px :].any() and not column[:, : w.layout.top_px].any()


def test_slow_motion_runs_fewer_steps_of_the_same_size(demos):
    app = make_app(demos, "1")
    for factor in (0.5, 0.25, 0.125, 0.0625, 1.0):
        press(app, pygame.K_s)
        assert app.speed == factor
        if factor != 1.0:
            assert f"slow motion x1/{round(1 / factor)}" in app.status_line()
        steps0, t0 = app.table.steps, app.table.time_s
        for _ in range(120):
            app.frame(FRAME_S)
        assert app.dt_s == pytest.approx(1 / 240)
        assert app.table.time_s - t0 == pytest.approx(2.0 * factor, abs=2 * app.dt_s)
        assert app.table.steps - steps0 == pytest.approx(480 * factor, abs=2)


def test_collision_counter_on_the_status_line(demos):
    app = make_app(demos, "2p")
    frames_until(app, lambda: app.table.collision_count, what="the first collision", max_frames=600)
    assert app.table.collision_count == 1 and "1 collision, 0 on walls" in app.status_parts()  # singular


def test_reverse_time_brings_every_puck_back(demos):
    app = make_app(demos, "2")
    t = app.table
    t.cr_puck = t.cr_wall = 1.0
    t.puck_correction = "perfect-kiss"
    rng = np.random.default_rng(0)
    angles = rng.uniform(0, 2 * np.pi, len(t.pucks))
    t.vel_mps[:] = 2.0 * np.stack([np.cos(angles), np.sin(angles)], axis=1)
    start = t.pos_m.copy()
    for _ in range(240):  # 1 s
        app.physics_step()
    hits = t.collision_count
    assert hits >= 4, "the test needs several collisions"
    press_r = pygame.event.Event(pygame.KEYDOWN, key=pygame.K_r, mod=0, unicode="r", scancode=0)
    app.handle_event(press_r)
    for _ in range(240):
        app.physics_step()
    assert t.collision_count >= 2 * hits - 1
    assert np.max(np.hypot(*(t.pos_m - start).T)) < 1e-3


def test_energy_chart_numbers_match_a_hand_computation():
    table = AirTable()
    a = table.add_puck((2.0, 3.0), 0.4, 0.3, vel_mps=(1.0, 0.5))
    b = table.add_puck((4.0, 3.0), 0.5, 0.6, vel_mps=(-0.5, 0.0))
    table.add_spring(a, b, length_m=1.5, k_Npm=20.0, damper_Nspm=0.0)
    table.gravity_on = True
    chart = aids.EnergyChart()
    chart.sample(table)
    m_a, m_b = 0.3 * math.pi * 0.16, 0.6 * math.pi * 0.25
    ke = 0.5 * m_a * (1.0**2 + 0.5**2) + 0.5 * m_b * 0.5**2
    pe_spring = 0.5 * 20.0 * (2.0 - 1.5) ** 2
    pe_gravity = 9.8 * (m_a + m_b) * 3.0
    p = math.hypot(m_a * 1.0 - m_b * 0.5, m_a * 0.5)
    latest = chart.latest()
    assert latest["kinetic_J"] == pytest.approx(ke, rel=1e-12)
    assert latest["spring_J"] == pytest.approx(pe_spring, rel=1e-12)
    assert latest["gravity_J"] == pytest.approx(pe_gravity, rel=1e-12)
    assert latest["total_J"] == pytest.approx(ke + pe_spring + pe_gravity, rel=1e-12)
    assert latest["momentum_Ns"] == pytest.approx(p, rel=1e-12)


def test_demo_5_without_damping_keeps_its_energy(demos):
    app = make_app(demos, "5")
    app.table.spring_damper_Nspm[:] = 0.0
    app.aids.chart.clear()
    for _ in range(20 * 60):  # 20 s
        app.frame(FRAME_S)
    series = app.aids.chart.series(window_s=25.0)
    t, total = series["time_s"], series["total_J"]
    assert t[-1] - t[0] == pytest.approx(20.0, abs=0.01)
    m = 0.3 * math.pi * 0.4**2
    omega = math.sqrt(20.0 / (m / 2))
    # E swings at twice the spring's frequency by about 3 %, so a plain 1 s mean
    # carries up to 0.2 % from the unfinished swing; average over the whole
    # swings that fit in one second instead (5 of them, 0.96 s).
    swing_s = math.pi / omega
    window_s = math.floor(1.0 / swing_s) * swing_s
    first = total[t < t[0] + window_s].mean()
    last = total[t > t[-1] - window_s].mean()
    assert abs(last - first) / first < 1e-3
    # Semi-implicit Euler: E swings with relative amplitude about omega dt / 2.
    expected = omega * app.dt_s / 2
    wiggle = (total.max() - total.min()) / (2 * total.mean())
    assert 0.5 * expected < wiggle < 1.5 * expected
    assert "does not drift" in app.aids.chart.euler_wiggle_note(
        app.table.spring_pairs.size > 0, aids.loses_energy(app.table)
    )  # explained under the chart


@pytest.mark.parametrize("key, mode", [("1p", "off"), ("2p", "two-step"), ("3p", "perfect-kiss")])
def test_annotation_numbers_are_the_physics_numbers(demos, key, mode):
    app = make_app(demos, key)
    assert app.table.puck_correction == mode
    press(app, pygame.K_a)
    shown: list[str] = []
    original = app.painter._text
    app.painter._text = lambda text, *a, **k: (shown.append(text), original(text, *a, **k))
    hit = None
    for _ in range(600):
        app.physics_step()
        if len(app.table.last_collisions):
            hit = app.table.last_collisions
            break
    assert hit is not None
    app.draw()
    note = app.aids.collision_log.items[-1]
    assert note.overlap_m == hit.overlap_m[0]
    assert note.separation_m == hit.separation_m[0]
    assert f"overlap {hit.overlap_m[0] * 1000:.1f} mm" in shown
    assert f"separation {hit.separation_m[0] * 1000:.1f} mm" in shown
    if mode == "two-step":
        assert "ratio 1.0000" in shown
    # Equal masses, target still: the outgoing paths are 90 degrees apart.
    assert "paths 90.00 deg apart" in shown


BROKEN_SYNTAX = "KEY = 't8'\nTITLE = 'Broken'\ndef build(table, variation=0)\n    pass\n"
BROKEN_BUILD = (
    "KEY = 't9'\nTITLE = 'Throws'\nNOTES = 'x'\n\n"
    "def build(table, variation=0):\n    table.add_puck((1, 1), 0.2)\n    raise RuntimeError('my mistake')\n"
)


def test_broken_teacher_demos_show_their_errors_and_the_app_goes_on(demos, tmp_path):
    (tmp_path / "syntax.py").write_text(BROKEN_SYNTAX)
    (tmp_path / "throws.py").write_text(BROKEN_BUILD)
    found, errors = discover([BUILTIN_DIR, tmp_path])
    assert [(e.path.name, e.line) for e in errors] == [("syntax.py", 3)]
    app = make_app(found, "1", demo_errors=errors)
    app.frame(FRAME_S)
    assert any("syntax.py, line 3: syntax error" in line for line in app.panels.notice)
    press(app, pygame.K_SPACE)  # any key dismisses the notice
    assert app.panels.notice == []
    app.start_demo("t9")
    app.frame(FRAME_S)
    assert app.build_error is not None
    assert str(app.build_error) == "throws.py, line 7: RuntimeError: my mistake"
    assert len(app.table.pucks) == 5 and app.demo_key == "1"  # demo 1's table goes on (a user test: it emptied)
    press(app, pygame.K_3)
    assert app.demo_key == "3" and app.build_error is None and len(app.table.pucks) == 15


def test_new_demo_writes_a_starter_that_runs(tmp_path, capsys):
    path = tmp_path / "mydemos" / "mine.py"  # the folder is made if need be
    assert main(["--new-demo", str(path)]) == 0
    assert "python -m airtable --demos" in capsys.readouterr().out
    found, errors = discover([path.parent])
    assert errors == [] and list(found) == ["t1"]
    table = AirTable()
    for variation in (0, 1):
        table.clear()
        found["t1"].build(table, variation)
        for _ in range(720):  # 3 s: the cue is thrown at 1 s
            table.step(found["t1"].dt_s)
        assert np.isfinite(table.pos_m).all()
        assert table.collision_count >= 1
    with pytest.raises(SystemExit) as exc:
        main(["--new-demo", str(path)])  # never overwrites
    assert exc.value.code == 2
    assert "already exists" in capsys.readouterr().err


def test_a_failing_timed_event_shows_its_error_and_pauses(demos, tmp_path):
    (tmp_path / "late.py").write_text(
        "KEY = 't7'\nTITLE = 'Late'\n\n"
        "def build(table, variation=0):\n    table.add_puck((1, 1), 0.2)\n"
        "    table.schedule(0.5, lambda t: t.no_such_thing())\n"
    )
    (tmp_path / "bad_dt.py").write_text(
        "KEY = 't6'\nTITLE = 'x'\nDT_S = 0\n\ndef build(table, variation=0):\n    pass\n"
    )
    found, errors = discover([BUILTIN_DIR, tmp_path])
    assert [str(e) for e in errors] == ["bad_dt.py: DT_S must be a time step in seconds, above 0 and at most 1, not 0"]
    app = make_app(found, "t7")
    for _ in range(60):
        app.frame(FRAME_S)
    assert app.paused
    assert "late.py, line 6: AttributeError" in str(app.build_error)
    press(app, pygame.K_2)
    assert app.build_error is None and len(app.table.pucks) == 8
    assert not app.paused


# ---------------------------------------------------------------- aids that teach

SHIFT_DEMOS = [("1p", 29.36, 14.48), ("2p", 29.36, 14.48), ("3p", 14.48, 14.48)]


@pytest.mark.parametrize("key, actual, ideal", SHIFT_DEMOS)
def test_the_target_leaves_at_its_angle_against_the_ideal(demos, key, actual, ideal):
    # By hand: the cue's path misses the target's centre by b = r / 2, so at first
    # contact the centres are 2 r apart and the normal is asin(b / 2r) = asin(1/4)
    # = 14.48 deg off the path. At the coarse step the hit is found 0.4 m along x,
    # where the centres' line is atan(0.225 / 0.4) = 29.36 deg off it.
    app = make_app(demos, key)
    press(app, pygame.K_a)
    shown: list[str] = []
    original = app.painter._text
    app.painter._text = lambda text, *a, **k: (shown.append(text), original(text, *a, **k))
    for _ in range(600):
        app.physics_step()
        if len(app.table.last_collisions):
            break
    app.draw()
    push = app.aids.collision_log.items[-1].target
    assert push.ideal_deg == pytest.approx(math.degrees(math.asin(0.25)), abs=1e-9)
    assert push.actual_deg == pytest.approx(actual, abs=0.01)
    assert push.ideal_deg == pytest.approx(ideal, abs=0.01)
    assert f"target {actual:.1f} deg vs ideal {ideal:.1f} deg" in shown
    # Every label of the frame, the HUD's included, has a box of its own.
    boxes = app.window.label_boxes
    assert len(boxes) >= 6
    for k, a in enumerate(boxes):
        assert a.collidelist(boxes[k + 1 :]) < 0, f"label {a} overlaps another"


def test_labels_placed_around_one_spot_never_overlap():
    from airtable.app.aids_paint import place_box

    screen = pygame.Rect(0, 0, 1280, 720)
    taken: list[pygame.Rect] = []
    for k in range(30):
        taken.append(place_box((120 + 7 * k, 22), (640, 360), 10, taken, screen, 22))
    for k, a in enumerate(taken):
        assert screen.contains(a)
        assert a.collidelist(taken[k + 1 :]) < 0


def test_annotation_lines_are_at_least_2_px_at_720p(demos):
    app = make_app(demos, "1p")
    app.window.resize((1280, 720))
    assert app.window.line_px(2) >= 2
    app.window.resize((3840, 2160))
    assert app.window.line_px(2) == 6  # and thicker on a 4K screen


def test_vector_scale_is_round_fixed_for_the_demo_and_ignores_resting_pucks():
    scale = aids.VectorScale(target_m=1.0)
    assert scale.update(np.array([[2e-8, 0.0]])) == (1.0, 1.0)  # at rest: the default, not "2e-08 m/s"
    assert scale.update(np.array([[1.7, 0.0], [0.0, -0.2]])) == (2.0, 0.5)
    assert scale.update(np.array([[0.3, 0.0]])) == (2.0, 0.5)  # slower later: the same scale
    assert scale.update(np.array([[0.0, 4.2]])) == (5.0, 0.2)  # faster: the next round number
    for largest, unit in ((0.0013, 0.002), (0.04, 0.05), (9.9, 10.0), (10.0, 10.0), (120.0, 200.0)):
        assert aids.nice_scale(largest)[0] == pytest.approx(unit)
    scale.reset()
    assert scale.update(np.zeros((3, 2))) == (1.0, 1.0)


def _simulate(rgb, matrix):
    """Colour seen with a colour-vision deficiency (in linear RGB), back to sRGB 0-255."""
    c = np.asarray(rgb, float) / 255
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    out = np.clip(np.asarray(matrix) @ lin, 0, 1)
    return 255 * np.where(out <= 0.0031308, 12.92 * out, 1.055 * out ** (1 / 2.4) - 0.055)


DEFICIENCIES = {  # Viénot et al. 1999 (protan, deutan); Machado et al. 2009 (tritan, severity 1)
    "normal": np.eye(3),
    "protanopia": [[0.11238, 0.88762, 0.0], [0.11238, 0.88762, 0.0], [0.00401, -0.00401, 1.0]],
    "deuteranopia": [[0.29275, 0.70725, 0.0], [0.29275, 0.70725, 0.0], [-0.02234, 0.02234, 1.0]],
    "tritanopia": [[1.255528, -0.076749, -0.178779], [-0.078411, 0.930809, 0.147602], [0.004733, 0.691367, 0.3039]],
}


@pytest.mark.parametrize("kind", DEFICIENCIES)
def test_chart_colours_stay_distinct_for_colour_blind_viewers(kind):
    from airtable.app.aids_paint import CHART_COLORS

    energies = [CHART_COLORS[k] for k in ("kinetic_J", "spring_J", "gravity_J", "total_J")]
    seen = [_simulate(c, DEFICIENCIES[kind]) for c in energies]
    for a in range(len(seen)):
        for b in range(a + 1, len(seen)):
            assert np.linalg.norm(seen[a] - seen[b]) > 60, f"{kind}: colours {a} and {b} look alike"


def test_the_chart_moves_between_corners_and_shrinks(demos):
    app = make_app(demos, "5")
    press(app, pygame.K_c)
    w, h = app.window.surface.get_size()
    corners = []
    for _ in range(4):
        rect = app.painter.chart_rect()
        corners.append((rect.centerx > w / 2, rect.centery > h / 2))
        app.painter.cycle_chart_corner()
    assert sorted(corners) == [(False, False), (False, True), (True, False), (True, True)]
    big = app.painter.chart_rect()
    app.painter.toggle_chart_size()
    small = app.painter.chart_rect()
    assert small.width < big.width and small.height < big.height
    app.frame(FRAME_S)  # draws in its small size without trouble


def test_demo_5_motion_matches_its_notes(demos):
    # Damper: the bouncing dies within a couple of seconds, the pair drifts on at 0.22 m/s.
    app = make_app(demos, "5")
    start = app.table.center_of_mass_m().copy()
    for _ in range(3 * 60):
        app.frame(FRAME_S)
    (a, b) = app.table.pucks
    assert np.hypot(*(a.pos_m - b.pos_m)) == pytest.approx(1.5, abs=0.02)  # relaxed: no more bouncing
    moved = app.table.center_of_mass_m() - start
    np.testing.assert_allclose(moved / app.table.time_s, (0.2, 0.1), atol=1e-6)  # still drifting
    assert (
        app.aids.chart.euler_wiggle_note(app.table.spring_pairs.size > 0, aids.loses_energy(app.table)) is None
    )  # no "swings without drifting" claim here
    # No damper (Right): the bouncing goes on and the total swings by about 3 % (omega dt / 2).
    press(app, pygame.K_RIGHT)
    assert "no damper" in app.window.caption
    for _ in range(3 * 60):
        app.frame(FRAME_S)
    assert 0.03 < app.aids.chart.total_wiggle(2.0) < 0.04
    assert "does not drift" in app.aids.chart.euler_wiggle_note(
        app.table.spring_pairs.size > 0, aids.loses_energy(app.table)
    )
    # The same swing where something loses energy is not explained away as the integrator's.
    app.table.cr_wall = 0.7  # a landing jelly: its total falls at each bounce
    assert app.aids.chart.euler_wiggle_note(app.table.spring_pairs.size > 0, aids.loses_energy(app.table)) is None
    app.table.cr_wall = 1.0
    app.table.spring_damper_Nspm[:] = 0.1
    assert app.aids.chart.euler_wiggle_note(app.table.spring_pairs.size > 0, aids.loses_energy(app.table)) is None


@pytest.mark.parametrize("key", ["4", "7", "8"])
def test_the_chart_opens_in_the_corner_with_fewest_pucks(demos, key):
    app = make_app(demos, key)
    press(app, pygame.K_c)
    px = app.env.to_screen(app.table.pos_m)

    def covered(rect):
        return int(np.count_nonzero([rect.collidepoint(float(x), float(y)) for x, y in px]))

    counts = [covered(app.painter.chart_rect(corner)) for corner in range(4)]
    assert covered(app.painter.chart_rect()) == min(counts)


def test_labels_never_overlap_in_a_crowd(demos):
    app = make_app(demos, "4")
    app.window.resize((739, 648))  # the default window on a 1280 x 720 projector
    app.table.vel_mps[:] = np.random.default_rng(3).normal(0.0, 2.0, app.table.vel_mps.shape)
    for key in (pygame.K_a, pygame.K_v, pygame.K_c):
        press(app, key)
    most = 0
    for _ in range(240):
        app.frame(FRAME_S)
        boxes = app.window.label_boxes
        most = max(most, len(boxes))
        for k, a in enumerate(boxes):
            assert a.collidelist(boxes[k + 1 :]) < 0, f"label {a} overlaps another"
    # The band, the status bar, the chart and the legend, and the newest annotations' boxes (each clear of
    # the pucks, so in a crowd of 54 some are left out; before, a dozen piled up over the pucks).
    assert most >= 6
