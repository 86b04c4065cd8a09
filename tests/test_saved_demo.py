"""Save the moment as a demo: Ctrl+S and --save-demo write a demo file that reloads to the same state."""

from __future__ import annotations

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, press

from airtable.app.app import App
from airtable.app.demo_loader import load_demo_file
from airtable.app.saved_demo import check_save_demo_path, free_key
from airtable.cli import main
from airtable.physics.table import AirTable

STATE = (
    "pos_m",
    "vel_mps",
    "radius_m",
    "mass_kg",
    "color_rgb",
    "spring_pairs",
    "spring_length_m",
    "spring_k_Npm",
    "spring_damper_Nspm",
    "spring_width_m",
    "spring_color_rgb",
)
SETTINGS = ("gravity_on", "gravity_mps2", "cr_puck", "cr_wall", "wall_correction", "puck_correction", "puck_collisions")


def assert_same_state(a: AirTable, b: AirTable) -> None:
    for name in STATE:
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and np.array_equal(x, y), name  # bit for bit
    for name in SETTINGS:
        assert getattr(a, name) == getattr(b, name), name


@pytest.fixture
def app(demos, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    a = App(dict(demos), demo_key="6", headless=True)  # the spring triangle: pucks and springs
    pygame.event.clear()
    yield a
    pygame.event.clear()


def test_ctrl_s_saves_a_demo_that_reloads_to_the_same_state(app, tmp_path):
    app.table.gravity_on, app.table.gravity_mps2, app.table.cr_puck, app.table.cr_wall = True, 1.62, 0.7, 0.4
    for _ in range(45):
        app.frame(FRAME_S)
    saved = AirTable(app.table.width_m, app.table.height_m)
    press(app, pygame.K_s, mod=pygame.KMOD_LCTRL)
    path = tmp_path / "my_demos" / "s1.py"
    assert path.is_file() and str(path.resolve()) in app.message and "s1" in app.message
    assert app.speed == 1.0  # Ctrl+S is not s (slow motion)
    assert "s1" in app.demos  # loaded at once from the teacher's folder
    load_demo_file(path).build(saved)  # the file alone, as another run would load it
    app.start_demo("s1")
    assert app.dt_s == 1 / 240
    assert_same_state(app.table, saved)
    assert len(app.table.pucks) == 4 and len(app.table.springs) == 3
    assert app.table.gravity_mps2 == 1.62 and app.table.cr_puck == 0.7 and app.table.cr_wall == 0.4


def test_the_saved_state_is_the_moment_of_the_press(app, tmp_path):
    for _ in range(20):
        app.frame(FRAME_S)
    app.paused = True
    pos, vel = app.table.pos_m.copy(), app.table.vel_mps.copy()
    press(app, pygame.K_s, mod=pygame.KMOD_CTRL)
    press(app, pygame.K_s, mod=pygame.KMOD_CTRL)  # a second save gets the next key
    assert sorted(p.name for p in (tmp_path / "my_demos").iterdir()) == ["s1.py", "s2.py"]
    app.start_demo("s2")
    assert np.array_equal(app.table.pos_m, pos) and np.array_equal(app.table.vel_mps, vel)
    text = (tmp_path / "my_demos" / "s2.py").read_text(encoding="utf-8")
    assert 'KEY = "s2"' in text.replace("'", '"') and "PUCKS = [" in text and "def build(table" in text
    assert repr(float(pos[0, 0])) in text  # the numbers as a teacher reads them


def test_a_saved_demo_runs_on_exactly_as_the_original(app):
    for _ in range(30):
        app.frame(FRAME_S)
    app.paused = True
    press(app, pygame.K_s, mod=pygame.KMOD_CTRL)
    original = app.table
    copy = AirTable(original.width_m, original.height_m)
    app.demos["s1"].build(copy)
    for _ in range(240):
        original.step(app.dt_s)
        copy.step(app.dt_s)
    assert_same_state(original, copy)


def test_save_demo_option_and_list_demos(tmp_path, capsys):
    folder = tmp_path / "mine"
    folder.mkdir()
    path = folder / "moment.py"
    argv = ["--headless", "--no-server", "--demo", "7", "--seconds", "1", "--save-demo", str(path)]
    assert main(argv) == 0
    assert "moment.py" in capsys.readouterr().out
    assert main(["--list-demos", "--demos", str(folder)]) == 0
    out = capsys.readouterr().out
    assert "s1  Newton" in out and "saved at t = 1.00 s" in out
    demo = load_demo_file(path)
    assert demo.key == "s1"
    table = AirTable()
    demo.build(table)
    assert len(table.pucks) == 3


@pytest.mark.parametrize(
    "bad, why",
    [("moment.txt", "must end in .py"), ("no/such/moment.py", "no folder"), ("taken.py", "already exists")],
)
def test_save_demo_bad_paths(bad, why, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "taken.py").write_text("# a teacher's file\n", encoding="utf-8")
    with pytest.raises(ValueError, match=why):
        check_save_demo_path(bad)
    assert main(["--headless", "--no-server", "--seconds", "0.1", "--save-demo", bad]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("airtable: --save-demo") and why in err[0]
    assert (tmp_path / "taken.py").read_text(encoding="utf-8") == "# a teacher's file\n"


def test_free_key_skips_keys_and_files_taken(tmp_path):
    (tmp_path / "s2.py").write_text("", encoding="utf-8")
    assert free_key({"1", "s1"}, tmp_path) == "s3"
