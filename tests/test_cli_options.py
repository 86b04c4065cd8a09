"""The command line refuses what the server would refuse, in the same one-line sentence."""

from __future__ import annotations

import pytest

from airtable import cli
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
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].endswith(str(refused.value).rstrip("."))
    assert "Traceback" not in "\n".join(err)


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
