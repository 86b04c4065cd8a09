"""The app driven the way a user drives it: real pygame events through its own input handling."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, escape_again, press

from airtable.app.app import App
from airtable.cli import main


@pytest.fixture
def app(demos):
    a = App(demos, demo_key="1", headless=True)
    pygame.event.clear()
    yield a
    pygame.event.clear()


def to_px(app: App, point_m) -> tuple[int, int]:
    x, y = app.env.to_screen(np.asarray(point_m, dtype=float))
    return (int(round(x)), int(round(y)))


def test_digit_keys_switch_demos_and_restart(app):
    press(app, pygame.K_2)
    assert app.demo_key == "2"
    assert len(app.table.pucks) == 8
    assert "Demo 2" in app.window.caption
    start = app.table.pos_m.copy()
    app.table.vel_mps[:] = 1.0
    for _ in range(30):
        app.frame(FRAME_S)
    assert not np.allclose(app.table.pos_m, start)
    press(app, pygame.K_2)  # again: restart
    # one frame of physics ran after the restart, with every puck at rest
    assert np.allclose(app.table.pos_m, start)
    assert np.all(app.table.vel_mps == 0.0)


def test_shift_digit_starts_the_correction_comparison(app):
    press(app, pygame.K_2, mod=pygame.KMOD_LSHIFT)
    assert app.demo_key == "2p"
    assert app.table.puck_correction == "two-step"
    assert app.dt_s == pytest.approx(1 / 20)


def test_variations_and_page_keys(app, demos):
    press(app, pygame.K_0)
    assert app.demo_key == "0"
    n0 = len(app.table.pucks)
    press(app, pygame.K_RIGHT)
    assert app.variation == 1
    assert len(app.table.pucks) > n0
    assert demos["0"].variations[1] in app.window.caption
    press(app, pygame.K_LEFT)
    n_first, t_first = len(app.table.pucks), app.table.time_s
    press(app, pygame.K_LEFT)  # at the first it stays (round the end was the heaviest, 10000 pucks)
    assert app.variation == 0 and len(app.table.pucks) == n_first and app.table.time_s > t_first
    assert app.message == "this is its first variation (Right goes back)"
    press(app, pygame.K_PAGEDOWN)
    keys = list(demos)
    assert app.demo_key == keys[(keys.index("0") + 1) % len(keys)]
    press(app, pygame.K_PAGEUP)
    assert app.demo_key == "0"


def test_a_demo_key_starts_its_default_variation_and_left_right_go_down_and_up_from_it(app, demos):
    """The gas's variations went 2000, 500, 5000, 10000 pucks: Left from the start gave 10000."""
    press(app, pygame.K_0, mod=pygame.KMOD_SHIFT)
    assert app.demo_key == "0p" and len(app.table.pucks) == 2000
    seen = []
    for key in [pygame.K_LEFT] * 2 + [pygame.K_RIGHT] * 4:
        press(app, key)
        seen.append(len(app.table.pucks))
    assert seen == [500, 500, 2000, 5000, 10000, 10000]
    assert app.message == "this is its last variation (Left goes back)"
    press(app, pygame.K_0, mod=pygame.KMOD_SHIFT)  # its key again restarts it as it was
    assert len(app.table.pucks) == 10000 and app.table.time_s < 0.1
    press(app, pygame.K_1)
    press(app, pygame.K_0, mod=pygame.KMOD_SHIFT)  # from another demo: its default
    assert len(app.table.pucks) == 2000


def test_pause_and_single_step(app):
    app.table.vel_mps[:] = (0.5, 0.0)
    press(app, pygame.K_SPACE)
    assert app.paused
    t0 = app.table.time_s
    for _ in range(10):
        app.frame(FRAME_S)
    assert app.table.time_s == t0
    press(app, pygame.K_PERIOD)
    assert app.table.time_s == pytest.approx(t0 + app.dt_s)
    press(app, pygame.K_SPACE)
    assert not app.paused
    app.frame(FRAME_S)
    assert app.table.time_s > t0 + app.dt_s


def test_fixed_step_does_not_depend_on_frame_rate(demos):
    """Same simulated time at 30 fps and at 144 fps gives the same state."""
    results = []
    for fps, frames in ((30, 60), (144, 288)):
        a = App(demos, demo_key="3", headless=True)
        a.table.pucks[0].vel_mps = (3.0, 1.0)
        a.run(max_frames=frames, frame_dt_s=1 / fps)
        assert a.table.steps == 480
        results.append(a.table.pos_m.copy())
    np.testing.assert_array_equal(results[0], results[1])


def test_stalled_frame_is_capped(app):
    steps0 = app.table.steps
    app.frame(5.0)  # the window was dragged for five seconds
    assert app.table.steps - steps0 == int(0.1 / app.dt_s)


def test_freeze_gravity_and_corrections(app):
    app.table.vel_mps[:] = (1.0, -2.0)
    press(app, pygame.K_f)
    assert np.all(app.table.vel_mps == 0.0)
    press(app, pygame.K_g)
    assert app.table.gravity_on and app.table.cr_puck == 0.9 and app.table.cr_wall == 0.9
    assert app.message == "gravity on (9.8 m/s²); restitution of pucks and walls 0.9 (Shift+g: gravity only)"
    app.frame(FRAME_S)
    assert app.window.surface.get_at((450, 300))[:3] == (20, 20, 70)
    press(app, pygame.K_g)
    assert not app.table.gravity_on and app.table.cr_puck == 1.0
    assert app.message.startswith("gravity off; restitution of pucks and walls 1 ")
    press(app, pygame.K_p)
    assert app.table.puck_correction == "off"
    assert app.window.surface.get_at((450, 300))[:3] == (40, 40, 40)
    press(app, pygame.K_p)
    assert app.table.puck_correction == "two-step"
    press(app, pygame.K_z)
    assert app.table.puck_correction == "perfect-kiss"
    press(app, pygame.K_z)
    assert app.table.puck_correction == "two-step"
    press(app, pygame.K_p)  # p goes round all three
    assert app.table.puck_correction == "perfect-kiss"


def test_zoom_keys_keep_the_point_under_the_cursor(app):
    mouse = (300, 200)
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=mouse, rel=(0, 0), buttons=(0, 0, 0)))
    app.frame(FRAME_S)
    anchor = app.env.to_world(mouse)
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_h, mod=0, unicode="h", scancode=0))
    for _ in range(30):
        app.frame(FRAME_S)
    pygame.event.post(pygame.event.Event(pygame.KEYUP, key=pygame.K_h, mod=0, unicode="h", scancode=0))
    app.frame(FRAME_S)
    assert app.env.zoom == pytest.approx(np.exp(1.5 * 30 * FRAME_S), rel=1e-6)
    np.testing.assert_allclose(app.env.to_world(mouse), anchor, atol=1e-9)
    pygame.event.post(pygame.event.Event(pygame.MOUSEWHEEL, x=0, y=-2, flipped=False, precise_x=0.0, precise_y=-2.0))
    app.frame(FRAME_S)
    assert app.env.zoom == pytest.approx(np.exp(1.5 * 30 * FRAME_S) / 1.21, rel=1e-6)
    press(app, pygame.K_q)
    assert app.env.zoom == 1.0 and np.all(app.env.origin_m == 0.0)


def test_ctrl_drag_pans(app):
    pygame.event.post(
        pygame.event.Event(pygame.KEYDOWN, key=pygame.K_LCTRL, mod=pygame.KMOD_LCTRL, unicode="", scancode=0)
    )
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=(400, 400), button=1))
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=(490, 400), rel=(90, 0), buttons=(1, 0, 0)))
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONUP, pos=(490, 400), button=1))
    app.frame(FRAME_S)
    assert app.env.origin_m[0] == pytest.approx(-90.0 / app.env.px_per_m)  # the world follows 90 px right
    assert app.local.held is None


def test_help_screen_toggles_and_lists_every_key(app):
    app.frame(FRAME_S)
    before = pygame.surfarray.array3d(app.window.surface).copy()
    press(app, pygame.K_F1)
    assert app.panels.show_help
    after = pygame.surfarray.array3d(app.window.surface)
    assert np.mean(np.any(before != after, axis=2)) > 0.3
    for _ in range(3):  # F1 turns the pages of a help that needs more than one, then closes it
        press(app, pygame.K_F1)
        if not app.panels.show_help:
            break
    assert not app.panels.show_help


def test_mouse_drags_and_flings_a_puck(app):
    press(app, pygame.K_1)
    puck = app.table.pucks[0]  # the small orange one at (2.5, 7.5)
    start = puck.pos_m
    grab = to_px(app, start)
    target_m = start + np.array([2.0, -1.0])
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=grab, rel=(0, 0), buttons=(0, 0, 0)))
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=grab, button=1))
    app.frame(FRAME_S)
    assert app.local.held is puck
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=to_px(app, target_m), rel=(1, 1), buttons=(1, 0, 0)))
    for _ in range(60):
        app.frame(FRAME_S)
    moved = puck.pos_m
    # pulled most of the way to the cursor along the line to it
    assert np.linalg.norm(moved - start) > 1.0
    assert np.linalg.norm(moved - target_m) < np.linalg.norm(start - target_m)
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=to_px(app, (8.0, 7.0)), rel=(1, 1), buttons=(1, 0, 0)))
    for _ in range(6):
        app.frame(FRAME_S)
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONUP, pos=to_px(app, (8.0, 7.0)), button=1))
    app.frame(FRAME_S)
    assert app.local.held is None
    v = puck.vel_mps
    assert np.linalg.norm(v) > 1.0  # flung: it keeps moving after the release
    p0 = puck.pos_m
    app.frame(FRAME_S)
    assert np.linalg.norm(puck.pos_m - p0) > 0.01


@pytest.mark.parametrize("beside_px, grabbed", [(3, True), (7, True), (20, False)])
def test_a_click_just_beside_a_small_puck_grabs_it(app, beside_px, grabbed):
    """In the 10000-puck gas a puck is a few pixels across: a click between pucks grabbed nothing."""
    press(app, pygame.K_1)
    app.paused = True  # nothing moves while we aim
    puck = app.table.pucks[0]  # the small orange one at (2.5, 7.5), its left side clear
    edge_px = app.env.to_screen(puck.pos_m)[0] - puck.radius_m * app.env.px_per_m
    at = (round(edge_px - beside_px * app.window.unit), round(app.env.to_screen(puck.pos_m)[1]))
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=at, button=1))
    app.frame(FRAME_S)
    assert (app.local.held is puck) == grabbed


def test_a_press_and_a_quick_move_in_one_frame_grab_the_puck_under_the_press(app):
    # On a slow frame (or a quick flick) the press and the move arrive together: the grab is where the button went down.
    press(app, pygame.K_1)
    puck = app.table.pucks[0]
    grab = to_px(app, puck.pos_m)
    away = to_px(app, (5.0, 0.3))
    assert app.table.puck_at(app.env.to_world(away)) is None
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=grab, rel=(0, 0), buttons=(0, 0, 0)))
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=grab, button=1))
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=away, rel=(1, 1), buttons=(1, 0, 0)))
    app.frame(FRAME_S)
    assert app.local.held is puck
    np.testing.assert_allclose(app.local.cursor_m, app.env.to_world(away))  # and pulls toward the cursor now


def test_clicking_empty_table_grabs_nothing(app):
    empty = to_px(app, (5.0, 0.3))
    assert app.table.puck_at(app.env.to_world(empty)) is None
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=empty, rel=(0, 0), buttons=(0, 0, 0)))
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=empty, button=3))
    before = app.table.pos_m.copy()
    for _ in range(10):
        app.frame(FRAME_S)
    assert app.local.held is None
    np.testing.assert_array_equal(app.table.pos_m, before)


def test_screenshot_key_saves_a_png(app, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    press(app, pygame.K_F12)
    files = list((tmp_path / "screenshots").glob("*.png"))
    assert len(files) == 1
    assert str(files[0].resolve()) in app.message


def test_escape_asks_then_a_second_escape_quits(app):
    press(app, pygame.K_ESCAPE)
    assert app.running and app.panels.panel() == "quit"
    escape_again(app)
    assert not app.running


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--demo", "42"], "there is no demo '42'"),
        (["--seconds", "soon"], "'soon' is not a positive number"),
        (["--port", "99999"], "is not a port number"),
        (["--demo", "5", "--variation", "3"], "variations"),
    ],
)
def test_bad_arguments_exit_2_with_a_message(argv, message, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert message in err
    assert "Traceback" not in err


def test_list_demos(capsys, demos):
    assert main(["--list-demos"]) == 0
    out = capsys.readouterr().out
    for demo in demos.values():
        assert demo.title in out


def test_readme_lists_every_key_of_the_key_table():
    """The help screen and README both come from BINDINGS; keep the README in step."""
    from pathlib import Path

    from airtable.app.app import BINDINGS

    readme = (Path(__file__).resolve().parent.parent / "README.md").read_text(encoding="utf-8")
    for binding in BINDINGS:
        assert f"| {binding.label} |" in readme, f"README's key table lacks {binding.label!r}"


def test_frame_rate_counts_the_frames_of_the_last_second(app):
    for _ in range(90):
        app.frame(1 / 45)
    assert app.fps == pytest.approx(45.0, rel=1e-6)
    assert app.scene().fps == app.fps


def test_importing_the_package_and_the_app_changes_no_environment_variable():
    import subprocess
    import sys

    code = (
        "import os; before = dict(os.environ); import airtable, airtable.cli, airtable.app.app;"
        " print(sorted(set(os.environ.items()) ^ set(before.items())))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().splitlines()[-1] == "[]"


def test_a_table_too_heavy_for_real_time_runs_in_slow_motion_and_says_so(app):
    """Frames whose steps take longer than their budget drop the rest (slow motion, a steady frame
    rate) and the status line says how much of real time the physics keeps up with."""
    clock = [0.0]

    def slow_step() -> bool:  # each step takes 5 ms of the stepper's clock
        clock[0] += 0.005
        return App.physics_step(app)

    app.stepper.clock = lambda: clock[0]
    app.stepper.budget_s = 0.008
    app.physics_step = slow_step
    start = app.table.steps
    for _ in range(60):
        app.frame(FRAME_S)
        clock[0] += 0.002  # drawing the frame
    assert app.table.steps - start == 60 * 2  # 2 of the 4 steps each frame asks for
    assert "physics at 50% of real time (the computer's most)" in app.hud_lines()
    assert "of real time" not in app.status_line()  # (coming and going there, it pushed the last parts off)
    assert "physics at 50% of real time (the teacher's computer's most)" in app.status_parts(for_students=True)
    app.loop = SimpleNamespace(idling=True)  # a still window, at a few frames a second: nothing to say
    app.frame(FRAME_S)
    assert app.window.idle and not any("real time" in line for line in (*app.hud_lines(), *app.status_parts(True)))
    app.loop = None
    app.speed = 0.5  # slow motion x1/2 asks 2 steps a frame, and both fit in the budget
    for _ in range(150):  # (more than a second of the stepper's clock)
        app.frame(FRAME_S)
        clock[0] += 0.002
    assert "slow motion x1/2" in app.status_line() and not any("real time" in line for line in app.hud_lines())
    app.stepper.budget_s = 0.003  # now only one of the two: half of x1/2 is a quarter of real time
    for _ in range(150):  # (more than a second of the stepper's clock)
        app.frame(FRAME_S)
        clock[0] += 0.002
    assert "physics at 25% of real time (the computer's most)" in app.hud_lines()
    app.speed = 1.0
    app.stepper.budget_s = None  # the computer keeps up again
    for _ in range(90):
        app.frame(FRAME_S)
        clock[0] += FRAME_S
    assert not any("real time" in line for line in app.hud_lines())
