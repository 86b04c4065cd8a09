"""The projector tells the room's state (issue 22, item 3): a busy port, a failed server
and a password-protected table each show on the teacher's window, saying what to do."""

from __future__ import annotations

import socket

import numpy as np
import pygame
from conftest import FRAME_S

from airtable import cli
from airtable.app.app import App
from airtable.app.hud_view import BAND_LINES, fold_lines
from airtable.app.roster_view import ALERT_COLOR
from airtable.net.server import GameServer


def alert_pixels(path) -> int:
    picture = pygame.surfarray.array3d(pygame.image.load(str(path)))
    return int(np.all(picture == ALERT_COLOR, axis=-1).sum())


def test_a_busy_port_shows_on_the_projector_with_the_port_to_use(tmp_path, capsys, demos):
    shot = tmp_path / "projector.png"
    with socket.create_server(("127.0.0.1", 0)) as busy:
        port = busy.getsockname()[1]
        argv = ["--host", "127.0.0.1", "--port", str(port), "--headless", "--seconds", "0.3", "--demo", "1"]
        assert cli.main([*argv, "--screenshot", str(shot)]) == 0
    err = capsys.readouterr().err
    assert f"port {port} is already in use" in err and "start with --port " in err
    suggested = int(err.split("start with --port ")[1].split()[0])
    assert suggested != port
    assert alert_pixels(shot) > 200  # the sentence, in the alert colour, on the picture of the window
    # The port to use is the line's beginning, which even a small window's band keeps.
    problem = next(line for line in err.splitlines() if "already in use" in line).removeprefix("airtable: ")
    app = App(demos, headless=True, server_problem=problem, window_size_px=(640, 480))
    window = app.window
    width = window.surface.get_width() - window.font.get_height()
    assert f"--port {suggested}" in fold_lines(app.hud_lines(), BAND_LINES - 1, window.font, width)[0][0]


def test_the_alert_is_the_servers_sentence_and_stays_until_it_starts(demos):
    app = App(demos, headless=True, server_problem="students cannot join: port 8888 is already in use")
    app.frame(FRAME_S)
    assert app.room.alert() == "students cannot join: port 8888 is already in use"
    with GameServer(host="127.0.0.1", port=0) as server:
        running = App(demos, headless=True, server=server)
        running.frame(FRAME_S)
        assert running.room.alert() is None
        server.failure = "students can no longer join: the network thread failed"
        assert running.room.alert() == server.failure


def test_the_join_line_says_a_password_is_needed_and_never_shows_it():
    lines = GameServer(host="10.0.0.5", password="tulip").join_lines()
    assert lines == ["join with: airtable-client 10.0.0.5 --password (ask the teacher)"]
    assert GameServer(host="10.0.0.5").join_lines() == ["join with: airtable-client 10.0.0.5"]


def test_the_projector_shows_the_password_join_line(demos):
    with GameServer(host="127.0.0.1", port=0, password="tulip") as server:
        app = App(demos, headless=True, server=server)
        app.frame(FRAME_S)
        assert any("--password (ask the teacher)" in line for line in app.hud_lines())
        assert not any("tulip" in line for line in app.hud_lines())
