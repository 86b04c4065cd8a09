"""The command lines: a bad argument is one line and exit status 2 (usage only on --help), and
the teacher's command refuses what the server would refuse, in the same sentence."""

from __future__ import annotations

import os

import pytest

from airtable import cli, client_cli
from airtable.net.server import validate_server_options


@pytest.mark.parametrize(
    "flags, options",
    [
        (["--max-clients", "5000"], {"max_clients": 5000}),
        (["--snapshot-hz", "2000"], {"snapshot_hz": 2000.0}),
    ],
)
def test_the_command_line_refuses_what_the_server_would(flags, options, capsys) -> None:
    with pytest.raises(ValueError) as refused:
        validate_server_options(**options)
    with pytest.raises(SystemExit) as exited:
        cli.main([*flags, "--headless", "--seconds", "0.05"])
    assert exited.value.code == 2
    (err,) = capsys.readouterr().err.strip().splitlines()
    assert str(refused.value).rstrip(".") in err


def test_without_a_server_the_server_options_are_not_checked(capsys) -> None:
    assert cli.main(["--no-server", "--max-clients", "5000", "--headless", "--seconds", "0.05", "--demo", "1"]) == 0


def test_a_shifted_demo_key_is_taken_as_help_and_menu_write_it(capsys):
    assert cli.main(["--no-server", "--headless", "--seconds", "0.05", "--demo", "Shift+1"]) == 0
    assert cli.main(["--no-server", "--headless", "--seconds", "0.05", "--demo", "shift + 2"]) == 0
    assert cli.main(["--list-demos"]) == 0
    listing = capsys.readouterr().out
    assert "1p" in listing and "Shift+1" in listing


def test_the_menu_shows_every_demo_at_720p(demos):
    import pygame
    from conftest import press

    from airtable.app.app import App

    app = App(demos, headless=True, window_size_px=(1280, 720))
    shown = []
    draw_panel = app.window.draw_panel
    app.window.draw_panel = lambda title, rows, **k: (shown.append(rows), draw_panel(title, rows, **k))
    press(app, pygame.K_TAB)
    rows = shown[-1][:-1]
    assert len(rows) == len(app.demos)
    assert any(key.strip().endswith("Shift+1") for key, _ in rows)


BAD_ARGUMENTS = [
    (cli.main, "airtable", ["--bogus"], "unrecognized arguments: --bogus"),
    (cli.main, "airtable", ["--port", "99999"], "'99999' is not a port number"),
    (cli.main, "airtable", ["--demo", "42"], "there is no demo '42'"),
    (cli.main, "airtable", ["--variation", "0"], "'0' is not a positive whole number"),
    (cli.main, "airtable", ["--demo", "5", "--variation", "3"], "demo 5 has variations 1 to 2"),
    (cli.main, "airtable", ["--demo", "1", "--variation", "2"], "demo 1 has no variations"),
    (cli.main, "airtable", ["--password", ""], "--password needs at least one character"),
    (cli.main, "airtable", ["--snapshot-hz", "0.001"], "--snapshot-hz must be 1-1000 a second"),
    (client_cli.main, "airtable-client", [], "the following arguments are required: HOST[:PORT]"),
    (client_cli.main, "airtable-client", ["localhost", "--bogus"], "unrecognized arguments: --bogus"),
    (client_cli.main, "airtable-client", ["localhost", "--seconds"], "--seconds: expected one argument"),
]


@pytest.mark.parametrize(
    ("main", "name", "argv", "problem"), BAD_ARGUMENTS, ids=lambda x: " ".join(x) if isinstance(x, list) else None
)
def test_a_bad_argument_is_one_line_naming_the_command_and_exit_status_2(main, name, argv, problem, capsys) -> None:
    with pytest.raises(SystemExit) as exited:
        main([*argv, "--headless"] if main is cli.main else argv)
    assert exited.value.code == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.count("\n") == 1 and err.endswith("\n"), err
    assert err.startswith(f"{name}: ") and problem in err and "usage" not in err
    assert "--help" in err  # where the options are listed


@pytest.mark.parametrize(
    ("argv", "problem"),
    [
        (["10.0.0.5:9000", "--port", "9001"], "two ports: 9000 in '10.0.0.5:9000' and --port 9001; give one of them"),
        (["10.0.0.5", "--port", "70000"], "--port 70000 is not a port number (1-65535)"),
    ],
)
def test_the_students_port_is_given_once_in_either_form(argv, problem, capsys) -> None:
    assert client_cli.main([*argv, "--headless"]) == 2
    assert capsys.readouterr().err == f"airtable-client: {problem}\n"


@pytest.mark.parametrize("name", ["", " "])
def test_an_empty_name_says_to_give_one_or_leave_it_out(name, capsys) -> None:
    """A user test: --name "" was refused as "the name is empty" where leaving --name out joins by seat."""
    assert client_cli.main(["10.0.0.5", "--name", name, "--headless"]) == 2
    said = "--name is empty: give a name, like --name Ann, or leave --name out to join by seat"
    assert capsys.readouterr().err == f"airtable-client: {said}\n"


NO_TABLE = ["127.0.0.1:1", "--headless", "--seconds", "0"]  # nobody on port 1: a name that passes waits, then ends


@pytest.mark.parametrize(
    ("name", "said"),
    [
        (
            "Nguyễn",
            "the name has 'ễ' (U+1EC5), which the teacher's screen's font cannot draw; "
            "write 'e' for it, as in \"Nguyen\"",
        ),
        ("Trần Thị Hương", "write 'a' for it, as in \"Tran Thi Huong\""),
        (
            "Ann 😀",
            "the name has '😀' (U+1F600), which the teacher's screen's font cannot draw; leave it out, as in \"Ann\"",
        ),
        ("שלום", "pick a name in Latin, Greek or Cyrillic letters"),
        ("A" * 21, "is over 20 characters; pick a shorter name"),
        ("😀", "has no visible letter or digit"),
    ],
)
def test_a_name_the_teachers_font_cannot_draw_is_a_bad_argument_said_before_joining(name, said, capsys) -> None:
    """A user test: --name "Nguyễn" passed, then the teacher's table refused it and the client ended with status 1
    (and with no table yet, it waited and failed once the table opened). The teacher's table draws names in
    pygame's default font, as this window does: a name it lacks a letter for is refused here, at once."""
    assert client_cli.main([*NO_TABLE, "--name", name]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and err.startswith("airtable-client: ") and said in err, err


@pytest.mark.parametrize("name", ["Иван", "Αλέξης", "Zoë", "Nguyên", "Đan", "Chloe\u0308"])
def test_a_name_the_teachers_font_draws_is_taken(name, capsys) -> None:
    """Cyrillic, Greek and the Latin letters with accents the font has (Vietnamese "ê", "đ") are accepted."""
    assert client_cli.main([*NO_TABLE, "--name", name]) == 0
    assert "connection refused" in capsys.readouterr().out


@pytest.mark.parametrize(("main", "usage"), [(cli.main, "python -m airtable"), (client_cli.main, "airtable-client")])
def test_help_prints_the_usage_and_every_option_and_exits_0(main, usage, capsys) -> None:
    with pytest.raises(SystemExit) as exited:
        main(["--help"])
    assert exited.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith(f"usage: {usage} ")
    assert "--name" in out if main is client_cli.main else "--fullscreen" in out and "--stats" in out


def test_variation_counts_from_1_as_list_demos_lists_them(tmp_path, capsys) -> None:
    assert cli.main(["--list-demos"]) == 0
    (line,) = [row for row in capsys.readouterr().out.splitlines() if row.split()[:1] == ["8"]]
    second = line.split("[variations: ")[1].split(", ")[1]  # the second one --list-demos names
    assert second == "cue 10 % of a radius off the line"
    argv = ["--headless", "--no-server", "--seconds", "0.05", "--demo", "8", "--variation", "2"]
    assert cli.main([*argv, "--save-demo", str(tmp_path / "moment.py")]) == 0
    assert f"Demo 8: Pool line ({second})" in (tmp_path / "moment.py").read_text(encoding="utf-8")


@pytest.mark.parametrize("main", [cli.main, client_cli.main])
def test_both_commands_name_their_window_for_the_taskbar_before_pygame_starts(main, monkeypatch) -> None:
    for var in ("SDL_VIDEO_X11_WMCLASS", "SDL_VIDEO_WAYLAND_WMCLASS"):
        monkeypatch.delenv(var, raising=False)
    with pytest.raises(SystemExit):
        main(["--bogus"])
    assert os.environ["SDL_VIDEO_X11_WMCLASS"] == "Air Table"  # not "__main__.py", the script's name
    assert os.environ["SDL_VIDEO_WAYLAND_WMCLASS"] == "airtable"
