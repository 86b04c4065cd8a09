"""Who gets in: a class behind one router, and a door that a flood of slow handshakes cannot hold shut."""

from __future__ import annotations

import logging

from conftest import wait_until
from test_server import RawClient, clients, make_server  # noqa: F401  (fixtures)

from airtable.cli import build_parser
from airtable.net import protocol as proto

NAT = "127.0.0.9"  # the one address a classroom's router shows the server


def test_a_class_behind_one_router_is_turned_away_with_how_to_let_it_in(make_server, clients, caplog):  # noqa: F811
    server = make_server(limit_loopback=True)  # the default: 3 seats per address
    caplog.set_level(logging.INFO, logger="airtable.net")
    for _ in range(3):
        clients(server.port, source=NAT).hello()
    refused = []
    for _ in range(5):
        c = clients(server.port, source=NAT)
        c.send(proto.encode_hello("Bo"))
        refused.append(c.expect_error())
    assert server.player_count == 3
    # The student reads why and what the teacher can do.
    assert "already plays with 3 windows" in refused[0] and "--per-address" in refused[0]
    assert "--password" in refused[0] and "one router" in refused[0]
    # The projector says it under the join lines; the log says it once.
    notice = server.join_lines()[-1]
    assert "5 students at 127.0.0.9 could not join" in notice and "--per-address 40" in notice
    told = [r.getMessage() for r in caplog.records if "could not join" in r.getMessage()]
    assert len(told) == 1 and "--per-address" in told[0] and told[0].startswith("1 student at 127.0.0.9")


def test_eight_students_from_one_address_join_once_the_teacher_allows_it(make_server, clients):  # noqa: F811
    server = make_server(limit_loopback=True, players_per_address=40)
    labels = [clients(server.port, source=NAT).hello(f"S{k}x").label for k in range(8)]
    assert labels == [f"C{k + 1} S{k}x" for k in range(8)]
    assert len(server.join_lines()) == 1  # no notice: nobody was turned away


def test_with_a_password_the_per_address_limit_does_not_apply(make_server, clients):  # noqa: F811
    server = make_server(limit_loopback=True, password="kepler")
    assert [clients(server.port, source=NAT).hello(password="kepler").client for _ in range(8)] == [
        f"C{k}" for k in range(1, 9)
    ]
    wrong = clients(server.port, source=NAT)
    wrong.send(proto.encode_hello(password="newton"))
    assert "wrong password" in wrong.expect_error()
    wait_until(lambda: server.player_count == 8, what="the eight seats")


def test_the_command_line_sets_the_seats_per_address():
    assert build_parser().parse_args([]).per_address == 3
    assert build_parser().parse_args(["--per-address", "40"]).per_address == 40
