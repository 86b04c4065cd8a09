"""A teacher's workflow: demo files edited while the app runs, errors in the terminal, the demo
menu, an Esc that never drops a class by accident, and the small things (keypad, screenshots)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, escape_again, press

from airtable.app.app import App
from airtable.app.demo_loader import BUILTIN_DIR, DemoShelf, key_order
from airtable.app.window import GameWindow
from airtable.cli import main
from airtable.physics.table import AirTable


def demo_source(key: str, pucks: int = 1, build_line: str = "", title: str = "Mine") -> str:
    return (
        f"KEY = {key!r}\nTITLE = {title!r}\nNOTES = 'One. Two.'\n\n"
        "def build(table, variation=0):\n"
        f"    for i in range({pucks}):\n"
        "        table.add_puck((1.0 + i, 1.0), 0.2)\n"
        f"{build_line}"
    )


RAISES = "    raise RuntimeError('my mistake')\n"
SYNTAX_ERROR = "KEY = '5'\nTITLE = 'Broken'\ndef build(table, variation=0)\n    pass\n"


def make_app(*folders: Path, key: str = "1") -> App:
    app = App(DemoShelf([BUILTIN_DIR, *folders]), demo_key=key, headless=True)
    pygame.event.clear()
    return app


# ---------------------------------------------------------------- demo files reload


def test_pressing_a_demo_key_reads_its_file_again_after_an_edit(tmp_path, capsys):
    mine = tmp_path / "mine.py"
    mine.write_text(demo_source("5", pucks=2))
    app = make_app(tmp_path, key="5")
    assert len(app.table.pucks) == 2
    mine.write_text(demo_source("5", pucks=3, title="Mine, edited"))
    press(app, pygame.K_5)
    assert len(app.table.pucks) == 3 and "Mine, edited" in app.window.caption

    mine.write_text(SYNTAX_ERROR)
    press(app, pygame.K_5)
    assert app.panels.panel() == "error" and app.build_error.stage == "load"
    # Not the built-in demo 5 in its place: the table that ran stays while the file is mended (a user
    # test: a typo in the running demo's file emptied the table).
    assert len(app.table.pucks) == 3 and "its last run goes on" in app.caption()
    assert f"{mine}:3: syntax error" in capsys.readouterr().err

    press(app, pygame.K_6)
    triangle = app.table.pos_m.copy()
    press(app, pygame.K_5)  # from another demo, too: the error, not the built-in 5, over the table that ran
    assert app.panels.panel() == "error" and np.array_equal(app.table.pos_m, triangle)
    assert app.demo_key == "6" and app.caption() == f"{app.demo.label(0)}; Demo 5: mine.py does not load"
    # The panel says it too: at 640x480 the heading was cut before "goes on" (a user test).
    assert app.panels._error_text()[1][-1] == f"On the table: {app.demo.label(0)} goes on."
    mine.write_text(demo_source("5", pucks=4, build_line=RAISES))
    press(app, pygame.K_5)
    assert app.build_error is not None and app.build_error.stage == "build"
    assert f"{mine}:8: RuntimeError: my mistake" in capsys.readouterr().err

    mine.write_text(demo_source("5", pucks=4))  # fixed: the next press builds it
    press(app, pygame.K_5)
    assert app.build_error is None and app.panels.panel() is None and len(app.table.pucks) == 4


def test_a_demo_that_fails_to_build_leaves_the_lesson_s_table_and_ctrl_s_saves_that_under_its_title(tmp_path):
    """A user test: Jelly ran, a demo file whose build raises was picked: the error, then an empty table;
    after a failed load, Ctrl+S saved the jelly titled "Five pucks" (the first demo)."""
    (tmp_path / "s1.py").write_text(demo_source("s1", pucks=4, build_line=RAISES))
    (tmp_path / "s2.py").write_text(demo_source("s2"))
    app = make_app(tmp_path, key="6p")
    (tmp_path / "s2.py").write_text(SYNTAX_ERROR.replace("'5'", "'s2'"))  # broken while the app runs
    jelly, title, label = len(app.table.pucks), app.demo.title, app.demo.label(app.variation)
    for broken in ("s1", "s2"):
        app.start_demo(broken)
        assert app.panels.panel() == "error" and len(app.table.pucks) == jelly
        assert app.caption().startswith(f"{label}; Demo {broken}")  # the table's demo first
        assert f"Demo {broken} could not be" in app.panels._error_text()[0]
        press(app, pygame.K_ESCAPE)
    saved = app.lessons.save_moment(tmp_path / "saved.py")
    text = saved.read_text()
    assert f"TITLE = '{title}, saved at t = " in text and f"Saved from {label} at" in text and "Five pucks" not in text


def test_a_demo_whose_first_build_fails_leaves_none_of_its_settings(tmp_path):
    """A user test: the app started on a demo whose build turned gravity on and then raised: an empty
    table with gravity on (and its restitution) under "not built"."""
    settings = "".join(
        f"    {line}\n"
        for line in ("table.gravity_on = True", "table.cr_puck = table.cr_wall = 0.3", "table.puck_correction = 'off'")
    )
    (tmp_path / "s1.py").write_text(demo_source("s1", pucks=3, build_line=settings + RAISES))
    app = make_app(tmp_path, key="s1")
    fresh = AirTable()  # (a new table has the settings reset_settings gives)
    assert app.panels.panel() == "error" and "not built" in app.caption() and len(app.table.pucks) == 0
    t = app.table
    assert (t.gravity_on, t.cr_puck, t.cr_wall, t.puck_correction) == (
        fresh.gravity_on,
        fresh.cr_puck,
        fresh.cr_wall,
        fresh.puck_correction,
    )
    assert not t.gravity_on and t.cr_puck == 1.0


def test_page_down_goes_past_a_demo_that_fails_to_build(tmp_path):
    """A user test: from a running demo, PageDown (a presentation clicker) tried the next demo, whose build
    raised, and every further PageDown tried the same one again: the demos after it were out of reach."""
    (tmp_path / "s1.py").write_text(demo_source("s1", pucks=1))
    (tmp_path / "s2.py").write_text(demo_source("s2", pucks=2, build_line=RAISES))
    (tmp_path / "s3.py").write_text(demo_source("s3", pucks=3))
    app = make_app(tmp_path, key="s1")
    keys = list(app.demos)
    assert keys.index("s2") == keys.index("s1") + 1 and keys.index("s3") == keys.index("s2") + 1
    press(app, pygame.K_PAGEDOWN)
    assert app.build_error is not None and app.error_key == "s2" and len(app.table.pucks) == 1
    press(app, pygame.K_ESCAPE)
    press(app, pygame.K_PAGEDOWN)
    assert app.build_error is None and app.demo_key == "s3" and len(app.table.pucks) == 3
    press(app, pygame.K_PAGEUP)  # back: s2 fails again, and PageUp from there goes on to s1
    press(app, pygame.K_ESCAPE)
    press(app, pygame.K_PAGEUP)
    assert app.demo_key == "s1" and len(app.table.pucks) == 1


def test_a_demo_file_broken_while_it_runs_stays_in_the_menu_and_the_heading_says_what_failed(tmp_path):
    """A user test: a syntax error in the running demo s1, then Tab: s1 left the menu, the error was on the
    terminal only, and the heading said "Demo 1: Five pucks" over s1's table. After a failed start and
    Esc, the heading named the built-in demo whose key the broken file had taken."""
    mine = tmp_path / "s1.py"
    mine.write_text(demo_source("s1", pucks=2))
    app = make_app(tmp_path, key="s1")
    mine.write_text(SYNTAX_ERROR.replace("'5'", "'s1'"))
    press(app, pygame.K_TAB)
    assert ("s1", "s1.py: does not load") in app.panels.menu.items
    assert "s1.py, line 3: syntax error" in app.message
    for ch in "s1":
        press(app, pygame.key.key_code(ch), unicode=ch)
    press(app, pygame.K_RETURN)
    heading = "Demo s1: s1.py (does not load: its last run goes on)"  # (its own key: the table stays)
    assert app.panels.panel() == "error" and app.caption() == heading and len(app.table.pucks) == 2
    press(app, pygame.K_ESCAPE)  # hides the error: the heading still says what failed
    assert app.panels.panel() is None and app.caption() == heading
    theirs = tmp_path / "eight.py"
    theirs.write_text(demo_source("8", pucks=2, build_line=RAISES))
    press(app, pygame.K_8)
    press(app, pygame.K_ESCAPE)
    # Not the built-in 8's title; s1's run goes on (its file is still broken: it ran as loaded before).
    assert app.caption() == "Demo s1: Mine; Demo 8: Mine not built" and len(app.table.pucks) == 2
    press(app, pygame.K_1)
    assert app.caption().startswith("Demo 1: ")


def test_a_file_that_failed_at_start_loads_once_fixed(tmp_path):
    broken = tmp_path / "late.py"
    broken.write_text("KEY = 't1'\nTITLE = 'x'\ndef build(table, variation=0)\n")
    app = make_app(tmp_path)
    assert app.panels.panel() == "notice"
    press(app, pygame.K_SPACE)  # any key goes on
    assert app.panels.panel() is None and "t1" not in app.demos
    broken.write_text(demo_source("t1", pucks=2))
    press(app, pygame.K_PAGEUP)  # from demo 1 back round to the last key, now t1
    assert app.demo_key == "t1" and len(app.table.pucks) == 2


def test_the_table_waits_under_a_notice_or_an_error_until_the_teacher_has_read_it(tmp_path):
    """A user test: started with a broken file beside the demos, demo 1's first collision happened under
    the "could not be loaded" notice, out of sight; a demo picked while another ran failed, and the one
    that ran went on under the error."""
    (tmp_path / "late.py").write_text("KEY = 't1'\nTITLE = 'x'\ndef build(table, variation=0)\n")
    (tmp_path / "s2.py").write_text(demo_source("s2", pucks=2, build_line=RAISES))
    app = make_app(tmp_path)
    assert app.panels.panel() == "notice"
    for _ in range(30):
        app.frame(FRAME_S)
    assert app.table.time_s == 0.0
    press(app, pygame.K_SPACE, frames=30)
    running = app.table.time_s
    assert running > 0.0
    app.start_demo("s2")  # (as Tab and its key pick it) its build raises
    assert app.panels.panel() == "error" and app.demo_key == "1"
    for _ in range(30):
        app.frame(FRAME_S)
    assert app.table.time_s == pytest.approx(running, abs=FRAME_S)  # (the frame that opened it may step)
    press(app, pygame.K_ESCAPE, frames=30)
    assert app.table.time_s > running + 0.25


def test_the_first_key_after_a_load_notice_also_does_its_work(tmp_path):
    """A user test: the teacher's first key (3, for demo 3) only closed the "could not load" notice."""
    (tmp_path / "late.py").write_text("KEY = 't1'\nTITLE = 'x'\ndef build(table, variation=0)\n")
    app = make_app(tmp_path)
    assert app.panels.panel() == "notice"
    shown: list = []
    draw_panel = app.window.draw_panel
    app.window.draw_panel = lambda title, rows, **k: (shown.extend(rows), draw_panel(title, rows, **k))
    app.frame(FRAME_S)
    assert any(str(row).startswith("Space or Enter goes on; any other key goes on and does its work") for row in shown)
    press(app, pygame.K_3)
    assert app.panels.panel() is None and app.demo_key == "3"
    app = make_app(tmp_path)
    paused = app.paused
    press(app, pygame.K_SPACE)  # Space, as Enter, only goes on: it does not pause the table as well
    assert app.panels.panel() is None and app.paused == paused and app.demo_key == "1"
    app = make_app(tmp_path)
    press(app, pygame.K_ESCAPE)  # Esc closes the notice, and asks nothing
    assert app.panels.panel() is None and app.running


def test_the_demo_menu_takes_letters_of_any_layout_by_their_key(tmp_path):
    """A user test: Cyrillic typed into the Tab menu was ignored. On a Russian layout the T key types "е";
    demo keys are Latin, so the menu reads the key where it sits, as the table's keys do."""
    for key in ("t1", "t2"):
        (tmp_path / f"{key}.py").write_text(demo_source(key, pucks=3))
    app = make_app(tmp_path)
    press(app, pygame.K_TAB)
    t_key = 4 + ord("t") - ord("a")  # the T key's scancode
    for key, text, scancode in ((ord("е"), "е", t_key), (pygame.K_2, "2", 0)):
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=key, mod=0, unicode=text, scancode=scancode))
        app.frame(FRAME_S)
    assert app.demo_key == "t2" and len(app.table.pucks) == 3 and app.panels.panel() is None
    press(app, pygame.K_TAB)
    for ch in "жq":  # a letter that is no key on this layout's keyboard, and one no demo key starts with
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=ord(ch), mod=0, unicode=ch, scancode=0))
        app.frame(FRAME_S)
    assert app.panels.menu.footer().endswith("; no demo key starts with жq (Backspace)")


def test_demo_keys_sort_naturally_everywhere(tmp_path, capsys):
    for key in ("t10", "t2", "t1"):
        (tmp_path / f"demo_{key}.py").write_text(demo_source(key))
    keys = sorted(["t10", "1p", "t2", "0", "1", "t1"], key=key_order)
    assert keys == ["1", "0", "1p", "t1", "t2", "t10"]
    app = make_app(tmp_path)
    assert list(app.demos)[-3:] == ["t1", "t2", "t10"]
    assert main(["--list-demos", "--demos", str(tmp_path)]) == 0
    listed = [line.split()[0] for line in capsys.readouterr().out.splitlines()]
    assert listed[-3:] == ["t1", "t2", "t10"]


def test_the_demo_menu_lists_every_demo_and_starts_the_one_picked(tmp_path):
    for key in ("t1", "t2", "t10"):
        (tmp_path / f"demo_{key}.py").write_text(demo_source(key, pucks=int(key[1:])))
    app = make_app(tmp_path)
    press(app, pygame.K_TAB)
    assert app.panels.panel() == "menu"
    assert [key for key, _ in app.panels.menu.items] == list(app.demos)
    press(app, pygame.K_t, unicode="t")
    press(app, pygame.K_2, unicode="2")  # "t2": no other key starts so, it starts at once
    assert app.panels.panel() is None and app.demo_key == "t2" and len(app.table.pucks) == 2
    press(app, pygame.K_TAB)
    press(app, pygame.K_t, unicode="t")
    press(app, pygame.K_1, unicode="1")  # "t1" or "t10": wait for Enter
    assert app.panels.panel() == "menu" and app.demo_key == "t2"
    press(app, pygame.K_RETURN)
    assert app.demo_key == "t1"
    press(app, pygame.K_TAB)
    press(app, pygame.K_DOWN)
    press(app, pygame.K_RETURN)
    assert app.demo_key == "t2"
    press(app, pygame.K_TAB)
    press(app, pygame.K_ESCAPE)  # closes the menu, quits nothing
    assert app.panels.panel() is None and app.running and app.demo_key == "t2"
    press(app, pygame.K_TAB)
    press(app, pygame.K_TAB)  # Tab again closes it too
    assert app.panels.panel() is None


def test_shift_and_a_digit_in_the_demo_menu_picks_the_shifted_demo(tmp_path):
    """A user test: Shift+1 in the menu typed "!" (no demo key starts so), where on the table it starts 1p."""
    (tmp_path / "demo_1p.py").write_text(demo_source("1p", pucks=2))
    (tmp_path / "demo_1.py").write_text(demo_source("1", pucks=1))
    app = make_app(tmp_path, key="1")
    press(app, pygame.K_TAB)
    press(app, pygame.K_1, mod=pygame.KMOD_LSHIFT, unicode="!")
    assert app.panels.panel() is None and app.demo_key == "1p" and len(app.table.pucks) == 2
    press(app, pygame.K_TAB)
    press(app, pygame.K_1, unicode="1")  # "1" alone is demo 1: "1p" is Shift+1, not "1" and more
    assert app.panels.panel() is None and app.demo_key == "1" and len(app.table.pucks) == 1


def test_a_digit_in_the_demo_menu_starts_that_demo_at_once_unless_a_longer_key_is_typed_so(tmp_path):
    """A user test: "2" in the Tab menu waited for Enter, because a demo "2p" exists; but the menu lists
    2p as Shift+2, so nothing more is typed after "2". A two-digit key ("12") still makes "1" wait."""
    (tmp_path / "demo_12.py").write_text(demo_source("12", pucks=12))
    app = make_app(tmp_path, key="1")
    assert "2p" in app.demos
    press(app, pygame.K_TAB)
    press(app, pygame.K_2, unicode="2")
    assert app.panels.panel() is None and app.demo_key == "2"
    press(app, pygame.K_TAB)
    press(app, pygame.K_1, unicode="1")  # "1" or "12": wait
    assert app.panels.panel() == "menu" and app.demo_key == "2"
    press(app, pygame.K_2, unicode="2")
    assert app.panels.panel() is None and app.demo_key == "12" and len(app.table.pucks) == 12
    press(app, pygame.K_TAB)
    press(app, pygame.K_1, unicode="1")
    press(app, pygame.K_RETURN)  # Enter on "1" picks demo 1, as before
    assert app.panels.panel() is None and app.demo_key == "1"


def test_f1_in_the_demo_menu_shows_the_help_over_it(tmp_path):
    """A user test: F1 did nothing while the menu was open (the menu took every key)."""
    (tmp_path / "demo_t1.py").write_text(demo_source("t1", pucks=1))
    app = make_app(tmp_path)
    press(app, pygame.K_TAB)
    press(app, pygame.K_t, unicode="t")
    press(app, pygame.K_F1)
    assert app.panels.panel() == "help" and app.panels.menu.typed == "t"
    press(app, pygame.K_ESCAPE)  # the help goes; the menu is as it was
    assert app.panels.panel() == "menu" and app.panels.menu.typed == "t" and app.running


# ---------------------------------------------------------------- errors reach the terminal


def test_a_failing_timed_event_is_reported_and_titled_as_one(tmp_path, capsys):
    late = tmp_path / "late.py"
    late.write_text(demo_source("t7", build_line="    table.schedule(0.5, lambda t: t.no_such_thing())\n"))
    app = make_app(tmp_path, key="t7")
    app.run(seconds=1.0, frame_dt_s=FRAME_S)
    assert app.paused and app.build_error.stage == "event"
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"{late}:8: AttributeError")
    shown: list[str] = []
    app.window.draw_panel = lambda title, *a, **k: shown.append(title)
    app.draw()
    assert shown == ["Demo t7: a timed event failed"]


def test_headless_run_of_a_demo_that_cannot_be_built_exits_1_and_shows_its_error(tmp_path, capsys, monkeypatch):
    folder = tmp_path / "demos"
    folder.mkdir()
    (folder / "throws.py").write_text(demo_source("t9", build_line=RAISES))
    (folder / "syntax.py").write_text("KEY = 't8'\nTITLE = 'x'\ndef build(table, variation=0)\n")
    panels: list[str] = []
    lines_shown: list[list[str]] = []

    def draw_panel(self, title, lines=(), *a, **k):
        panels.append(title)
        lines_shown.append(list(lines))

    monkeypatch.setattr(GameWindow, "draw_panel", draw_panel)
    shot = tmp_path / "shot"
    argv = ["--headless", "--no-server", "--seconds", "0.5", "--demos", str(folder), "--demo", "t9"]
    assert main([*argv, "--screenshot", str(shot)]) == 1
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines == [
        f"{folder / 'syntax.py'}:3: syntax error: expected ':'",
        f"{folder / 'throws.py'}:8: RuntimeError: my mistake",
    ]
    assert (tmp_path / "shot.png").exists()  # .png added
    # Every frame, the last one (the screenshot) included, shows this demo's error,
    # not the list of files that failed to load.
    assert set(panels) == {"Demo t9 could not be built"}
    assert lines_shown[-1][-1] == "The table is empty."  # (the first demo: nothing ran before it)


def test_a_headless_run_that_works_exits_0_in_simulated_time(capsys):
    assert main(["--headless", "--no-server", "--seconds", "10", "--demo", "7"]) == 0  # 10 s of demo, at once
    assert capsys.readouterr().err == ""


# ---------------------------------------------------------------- Esc is safe


@pytest.mark.parametrize("opener", [pygame.K_F1, pygame.K_l, pygame.K_TAB])
def test_esc_closes_an_open_panel_first(demos, opener):
    app = App(demos, headless=True)
    press(app, opener)
    assert app.panels.panel() is not None
    press(app, pygame.K_ESCAPE)
    assert app.panels.panel() is None and app.running
    press(app, pygame.K_ESCAPE)
    assert app.panels.panel() == "quit" and app.running
    escape_again(app)
    assert not app.running


def test_esc_on_a_press_any_key_notice_goes_on_without_quitting(tmp_path):
    (tmp_path / "bad.py").write_text("KEY = 't8'\n")
    app = make_app(tmp_path)
    assert app.panels.panel() == "notice"
    press(app, pygame.K_ESCAPE)
    assert app.running and app.panels.panel() is None


# ---------------------------------------------------------------- a quiet laptop


def test_a_still_table_with_nobody_at_it_is_still(demos):
    app = App(demos, demo_key="2", headless=True)  # demo 2 waits for the cue
    app.run(seconds=0.5, frame_dt_s=FRAME_S)
    assert not app.still()  # start-up counts as input for a second
    app.run(seconds=1.0, frame_dt_s=FRAME_S)
    assert app.still()
    app.clients.append(type(app.local)(name="C1", color=(1, 2, 3)))  # a student arrives
    assert not app.still()
    app.run(seconds=1.5, frame_dt_s=FRAME_S)
    assert app.still()  # whose cursor rests
    app.clients[1].cursor_m = app.clients[1].cursor_m + 0.1
    assert not app.still()
    app.run(seconds=1.5, frame_dt_s=FRAME_S)
    press(app, pygame.K_SPACE)
    assert app.paused and not app.still()  # a key was just pressed
    app.run(seconds=1.5, frame_dt_s=FRAME_S)
    assert app.still()
    app.table.vel_mps[0] = (1.0, 0.0)
    press(app, pygame.K_SPACE)
    app.run(seconds=1.5, frame_dt_s=FRAME_S)
    assert not app.paused and not app.still()  # a puck moves


# ---------------------------------------------------------------- small things


def test_keypad_digits_act_like_the_number_row(demos):
    app = App(demos, headless=True)
    press(app, pygame.K_KP_3)
    assert app.demo_key == "3"
    press(app, pygame.K_KP_0)
    assert app.demo_key == "0"
    press(app, pygame.K_KP_2, mod=pygame.KMOD_LSHIFT)
    assert app.demo_key == "2p"


def test_f12_screenshots_never_overwrite_each_other(demos, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    app = App(demos, headless=True)
    for _ in range(3):  # within one second: the same time stamp
        press(app, pygame.K_F12)
    files = sorted((tmp_path / "screenshots").glob("*.png"))
    assert len(files) == 3
    assert str(files[-1].resolve()) in app.message or any(str(f.resolve()) in app.message for f in files)


def test_the_status_line_puts_what_matters_first(demos):
    app = App(demos, demo_key="1", headless=True)
    press(app, pygame.K_SPACE)
    press(app, pygame.K_s)
    parts = app.status_parts()
    # The collisions a class counts along before the clock: a narrow window keeps them longest.
    assert parts[:4] == ["PAUSED", "slow motion x1/2", "0 collisions, 0 on walls", "t = 0.00 s"]
    assert "5 pucks" in parts
    assert app.scene().status_parts == parts  # the window (and every student) can drop parts from the end


@pytest.mark.parametrize(
    "name, message",
    [
        ("no_folder/shot.png", "there is no folder"),
        (".", "that is a folder"),
    ],
)
def test_an_unwritable_screenshot_path_is_one_line_and_exit_1(name, message, tmp_path, capsys):
    assert main(["--headless", "--no-server", "--seconds", "0.1", "--screenshot", str(tmp_path / name)]) == 1
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_no_display_is_one_line_naming_headless_and_exit_1():
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER")}
    done = subprocess.run(
        [sys.executable, "-m", "airtable", "--no-server"], capture_output=True, text=True, timeout=30, env=env
    )
    assert done.returncode == 1
    (line,) = done.stderr.strip().splitlines()
    assert "--headless" in line and "display" in line


def test_a_settled_spring_demo_idles_though_round_off_never_stops(demos):
    """Demo 6 rings down to velocities of about 1e-16 m/s that never reach 0 exactly: nothing on screen
    moves by half a pixel a second, so the table idles (issue 22: it drew 55 fps at 1080p)."""
    app = App(demos, demo_key="6", headless=True, window_size_px=(1920, 1080))
    app.table.pos_m[3, 0] += 0.8  # the demo starts at rest length: a corner pulled out sets it ringing
    app.run(seconds=1.0, frame_dt_s=FRAME_S)
    assert app.motion_px_per_s() > 10 and not app.still()  # it rings at first
    for _ in range(round(25.0 / app.dt_s)):  # 25 s: rung down, what is left is round-off
        app.table.step(app.dt_s)
    app.run(seconds=1.5, frame_dt_s=FRAME_S)
    assert np.any(app.table.vel_mps) and app.still()
    app.table.vel_mps[0] = (0.01, 0.0)  # a centimetre a second shows: not still
    assert not app.still()


def test_every_demo_starts_the_way_the_help_says(demos):
    """Help listed the pi demo as "t", but t shows the values table: a demo without a key of its own is
    "Tab, t" there (the menu, then its key), and doing what each row says starts that demo."""
    app = App(demos, demo_key="1", headless=True)
    shown: list = []
    app.window.draw_panel = lambda title, rows, **kw: (shown.append(kw.get("side_rows", ())), 1)[1]
    press(app, pygame.K_F1)
    press(app, pygame.K_F1)
    labels = dict((title, label) for label, title in shown[0])
    assert labels["Pi from collisions"] == "Tab, t" and labels["Gas: Maxwell speeds"] == "Shift+0"
    for key, demo in demos.items():
        label = labels[demo.title]
        if label.startswith("Tab, "):
            press(app, pygame.K_TAB)
            for ch in label[5:]:
                press(app, pygame.key.key_code(ch), unicode=ch)
            press(app, pygame.K_RETURN)
        else:
            digit = pygame.key.key_code(label[-1])
            press(app, digit, mod=pygame.KMOD_SHIFT if label.startswith("Shift+") else 0)
        assert app.demo_key == key, label


def test_a_frame_whose_physics_takes_seconds_pauses_the_table_so_esc_still_quits():
    """A user test: a demo file's typo (a puck at 1e9 m/s) or 20000 pucks made each frame's physics take
    seconds; keys acted seconds late and Esc, Esc never quit. Now such a frame pauses the table."""
    app = make_app(key="1")
    clock = iter(range(0, 10**6, 2))  # seconds: every look at the clock finds 2 s gone
    app.stepper.clock, app.stepper.budget_s = lambda: float(next(clock)), 0.01  # as in real time
    app.stepper.reset()
    for _ in range(3):  # (the first frame after a reset spans building the demo)
        app.frame(FRAME_S)
    assert app.paused and app.message.startswith("paused: one frame's physics took 4.0 s")  # (two looks)
    t = app.table.time_s
    app.frame(FRAME_S)
    assert app.table.time_s == t  # no step while paused: frames are quick again
    press(app, pygame.K_ESCAPE)
    assert app.panels.panel() == "quit"
    escape_again(app)
    assert not app.running


def test_in_simulated_frames_slow_physics_never_pauses():
    app = make_app(key="1")
    clock = iter(range(0, 10**6, 2))
    app.stepper.clock = lambda: float(next(clock))  # (no budget: frames of fixed length, tests and headless runs)
    for _ in range(3):
        app.frame(FRAME_S)
    assert not app.paused and app.table.time_s > 0.0


def test_another_demo_starts_on_the_whole_table_and_a_restart_keeps_the_view():
    """A user test: zoomed x10.8 on the grid, key 7 showed Newton's cradle as one giant puck on every screen."""
    app = make_app(key="3")
    whole = app.env.zoom
    app.zoom(10.8)
    press(app, pygame.K_3)  # the same demo again: the teacher's view stays
    assert app.env.zoom == pytest.approx(10.8 * whole)
    press(app, pygame.K_7)
    assert app.env.zoom == whole and "Demo 7" in app.caption()


def test_the_teachers_arrow_goes_when_the_pointer_leaves_the_window_unless_a_drag_goes_on():
    """A user test: the "teacher" arrow stayed parked at the table's edge, on every student's screen too."""
    app = make_app(key="2")

    def names() -> list[str]:
        return [c.name for c in app.scene().cursors]

    teacher = app.local.name
    app.frame(FRAME_S)
    assert teacher in names()
    pygame.event.post(pygame.event.Event(pygame.WINDOWLEAVE))
    app.frame(FRAME_S)
    assert teacher not in names()
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=(300, 300), rel=(1, 1), buttons=(0, 0, 0)))
    app.frame(FRAME_S)
    assert teacher in names()
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=(300, 300), button=1))
    pygame.event.post(pygame.event.Event(pygame.WINDOWLEAVE))  # dragging out of the window: the string holds
    app.frame(FRAME_S)
    assert teacher in names()
