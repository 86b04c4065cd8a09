"""A student whose client was killed and started again gets their own seat back (seat_memory.py).

A user test: `kill -9` on a student's client, then the same command again: "C3 Rocket" came back as
"C4 Rocket 2" in another colour, and the roster held C3 for someone who never came (2 of 2). The token
lived only in the killed process. Now the student command keeps it in the config folder.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest
from conftest import WAIT_S, wait_until
from test_player import cleanup, player, start_table  # noqa: F401  (fixtures)

from airtable.net.seat_memory import MAX_TABLES, SeatMemory
from airtable.net.server import IN_USE

CLIENT = "import sys; from airtable.client_cli import main; sys.exit(main(sys.argv[1:]))"


def start_client(port: int, name: str, config, port_option: bool = False) -> subprocess.Popen:
    """A student's airtable-client, headless, as its own process (bounded: it quits after 60 s); the
    port as HOST:PORT or (port_option) as --port PORT."""
    env = {**os.environ, "XDG_CONFIG_HOME": str(config), "APPDATA": str(config), "SDL_VIDEODRIVER": "dummy"}
    where = ["127.0.0.1", "--port", str(port)] if port_option else [f"127.0.0.1:{port}"]
    args = [*where, "--name", name, "--headless", "--seconds", "60"]
    return subprocess.Popen([sys.executable, "-c", CLIENT, *args], env=env, stdout=subprocess.PIPE, text=True)


def seat_of(proc: subprocess.Popen) -> str:
    """What the client says it is ("C1 Rocket"), from its first line."""
    line = proc.stdout.readline()  # (the first line comes at the WELCOME, or the client ends)
    assert "; you are " in line, line
    return line.strip().split("; you are ")[1]


def test_a_killed_client_started_again_comes_back_in_its_own_seat(cleanup, tmp_path):  # noqa: F811
    server, _ = start_table(cleanup)
    rocket = start_client(server.port, "Rocket", tmp_path)
    cleanup(rocket.kill)
    assert seat_of(rocket) == "C1 Rocket"
    rocket.kill()  # kill -9: no goodbye; the table holds the seat
    rocket.wait(timeout=WAIT_S)
    wait_until(lambda: [who for who, _ in server.away()] == ["C1 Rocket"], what="the seat held for Rocket")
    anna = player(cleanup, server.port, name="Анна Петрова")  # a classmate joins meanwhile
    assert anna.connect().label == "C2 Анна Петрова"
    again = start_client(server.port, "Rocket", tmp_path)
    cleanup(again.kill)
    assert seat_of(again) == "C1 Rocket"  # not "C3 Rocket 2"
    wait_until(lambda: server.away() == [], what="no seat held any more")
    other = start_client(server.port, "Bo", tmp_path, port_option=True)  # another name here: its own seat
    cleanup(other.kill)
    assert seat_of(other) == "C3 Bo"


def test_the_memory_keeps_a_token_per_table_and_name_and_ignores_what_is_not_one(tmp_path):
    memory = SeatMemory(tmp_path / "seats.json")
    assert memory.recall("127.0.0.1:8921", "Ann") is None  # no file yet
    memory.keep("127.0.0.1:8921", "Ann", "3-" + "a" * 32)
    memory.keep("127.0.0.1:8921", "Bo", "4-" + "b" * 32)
    memory.keep("10.0.0.5:8921", "Ann", "1-" + "c" * 32)
    memory.keep("127.0.0.1:8921", "Cy", "not a token")  # (never kept)
    again = SeatMemory(tmp_path / "seats.json")  # a new process reads the file
    assert again.recall("127.0.0.1:8921", "Ann") == "3-" + "a" * 32
    assert again.recall("127.0.0.1:8921", "Bo") == "4-" + "b" * 32
    assert again.recall("10.0.0.5:8921", "Ann") == "1-" + "c" * 32
    assert again.recall("127.0.0.1:8921", "Cy") is None and again.recall("127.0.0.1:8921", None) is None
    for k in range(MAX_TABLES + 5):  # bounded: the oldest go
        memory.keep(f"10.0.1.{k}:8921", "Ann", f"{k + 1}-" + "d" * 32)
    tokens = json.loads((tmp_path / "seats.json").read_text(encoding="utf-8"))["tokens"]
    assert len(tokens) == MAX_TABLES and again.recall("127.0.0.1:8921", "Ann") is None


@pytest.mark.parametrize(
    "content", ["", "{", "[1, 2]", '{"tokens": [1]}', '{"tokens": {"127.0.0.1:8921 Ann": 7}}', "\x00\xff"]
)
def test_a_damaged_memory_file_is_no_memory_and_is_mended_by_the_next_welcome(tmp_path, content):
    path = tmp_path / "seats.json"
    path.write_text(content, encoding="utf-8", errors="surrogateescape")
    memory = SeatMemory(path)
    assert memory.recall("127.0.0.1:8921", "Ann") is None
    memory.keep("127.0.0.1:8921", "Ann", "2-" + "e" * 32)
    assert SeatMemory(path).recall("127.0.0.1:8921", "Ann") == "2-" + "e" * 32


def test_a_memory_that_cannot_be_written_is_no_memory(tmp_path):
    blocked = tmp_path / "file"
    blocked.write_text("x")
    memory = SeatMemory(blocked / "seats.json")  # its folder is a file
    memory.keep("127.0.0.1:8921", "Ann", "2-" + "e" * 32)  # no exception
    assert memory.recall("127.0.0.1:8921", "Ann") is None


def test_two_live_windows_of_one_student_do_not_take_the_seat_from_each_other(cleanup, tmp_path):  # noqa: F811
    """A user test: the same command twice (a student opened the client twice) shared the kept token, and the
    two took C1 from each other twice a second, without end. Now the second waits, saying why, and takes the
    seat when the first closes."""
    server, _ = start_table(cleanup)
    memory = tmp_path / "seats.json"
    first = player(cleanup, server.port, name="Маша", seat_memory=SeatMemory(memory))
    assert first.connect().label == "C1 Маша"
    second = player(cleanup, server.port, name="Маша", seat_memory=SeatMemory(memory))
    assert second.connect() is None  # not welcomed: waiting
    assert second.waiting_because == IN_USE.format("C1 Маша")
    wait_until(lambda: second.next_try > 0.0, what="the second window to plan its next try")
    assert first.state == first.CONNECTED and first.reconnects == 0 and server.player_names() == ["C1 Маша"]
    first.close()  # the first window closes (BYE): the seat is free
    wait_until(lambda: second.state == second.CONNECTED, what="the second window in")
    assert second.welcome.label == "C1 Маша" and server.player_names() == ["C1 Маша"]


def test_a_student_whose_seat_went_to_another_comes_back_in_a_new_one(cleanup, tmp_path):  # noqa: F811
    """A user test: Zed left (Esc Esc), Quinn joined and got his seat, and Zed started again was told "C1 Quinn
    is playing in another window" for as long as he waited. A kept token proves a seat only while it is the
    token's student's: Zed is a newcomer, in the next free seat; Quinn keeps hers."""
    server, _ = start_table(cleanup)
    memory = tmp_path / "seats.json"
    zed = player(cleanup, server.port, name="Zed", seat_memory=SeatMemory(memory))
    assert zed.connect().label == "C1 Zed"
    zed.close()  # a goodbye: the seat is given up, not held
    wait_until(lambda: server.player_names() == [], what="Zed's seat given up")
    quinn = player(cleanup, server.port, name="Quinn")
    assert quinn.connect().label == "C1 Quinn"
    again = player(cleanup, server.port, name="Zed", seat_memory=SeatMemory(memory))
    welcome = again.connect()
    assert welcome is not None and welcome.label == "C2 Zed", again.waiting_because
    assert sorted(server.player_names()) == ["C1 Quinn", "C2 Zed"] and quinn.reconnects == 0


def test_a_seat_held_for_one_student_is_not_given_to_another_who_once_had_it(cleanup, tmp_path):  # noqa: F811
    """The same with Quinn dropped (her seat held for her return): Zed's old token for it does not take it."""
    server, _ = start_table(cleanup, seat_hold_s=1000.0)
    memory = tmp_path / "seats.json"
    zed = player(cleanup, server.port, name="Zed", seat_memory=SeatMemory(memory))
    assert zed.connect().label == "C1 Zed"
    zed.close()
    wait_until(lambda: server.player_names() == [], what="Zed's seat given up")
    quinn = player(cleanup, server.port, name="Quinn", seat_memory=SeatMemory(tmp_path / "quinn.json"))
    assert quinn.connect().label == "C1 Quinn"
    quinn.close(bye=False)  # her Wi-Fi: no goodbye, the seat is held for her
    wait_until(lambda: server.player_names() == [], what="Quinn's drop noticed")
    again = player(cleanup, server.port, name="Zed", seat_memory=SeatMemory(memory))
    assert again.connect().label == "C2 Zed"
