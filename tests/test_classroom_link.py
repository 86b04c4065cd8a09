"""A classroom on a real link (issue 23): the rate at long round trips, seats through cuts and closed lids.

The shaped-link tests run in a private network namespace (tests/linkshaper.py: a TUN device that
delays and drops packets, so TCP sees the real round trip); the `_in_*` functions run in that
child process and return plain numbers, which the tests below check. They skip with the reason
where the machine cannot make such a link. Outcomes are asserted, not speeds: a rate is compared
with what the teacher's loop published in the same seconds, and every wait is a generous bound.
"""

from __future__ import annotations

import json
import socket
import time

import linkshaper
import pytest
from conftest import wait_until

from airtable.net import pacing
from airtable.net import protocol as proto
from airtable.net import server as server_module
from airtable.net.server import IN_USE, GameServer

needs_link = pytest.mark.skipif(linkshaper.isolation_problem() is not None, reason=str(linkshaper.isolation_problem()))


# ----------------------------------------------------------------- run in the namespace


def _in_rate(shaper, delay_s: float, students: int = 3, seconds: float = 4.0) -> dict:
    shaper.shape(delay_s)
    room = linkshaper.Classroom(students)
    try:
        time.sleep(1.0 + 4 * delay_s)  # past the first round trips
        seq = room.server._snapshot_seq
        rates = room.rates(seconds)
        return {"rates": rates, "published": (room.server._snapshot_seq - seq) / seconds}
    finally:
        room.close()


def _in_cut(shaper, students: int = 4, cut: int = 3, cut_s: float = 7.0) -> dict:
    shaper.shape(0.03)
    room = linkshaper.Classroom(students)
    try:
        before = room.seats()
        ports = [room.port_of(net) for net in room.students[:cut]]
        shaper.cut(ports)
        time.sleep(cut_s)
        counts = [net.snapshots for net in room.students]
        shaper.restore()
        back = linkshaper.wait_for(
            lambda: all(n.snapshots > c + 5 for n, c in zip(room.students, counts, strict=True)), 20.0
        )
        return {"before": before, "after": room.seats(), "back": back, "names": room.server.player_names()}
    finally:
        room.close()


def _in_lid(shaper, lid_s: float = 20.0, timeout_s: float = 10.0) -> dict:
    """One student's link is dead for `lid_s` (a closed lid); a newcomer joins during the outage."""
    shaper.shape(0.02)
    room = linkshaper.Classroom(2, timeout_s=timeout_s)
    try:
        before = room.seats()
        lid = room.students[0]
        shaper.cut([room.port_of(lid)])
        cut_at = time.monotonic()
        dropped = linkshaper.wait_for(lambda: len(room.server.player_names()) == 1, timeout_s + 5.0)
        newcomer = room.join(1, prefix="New")[0]
        time.sleep(max(0.0, lid_s - (time.monotonic() - cut_at)))  # the rest of the outage
        shaper.restore()
        back = linkshaper.wait_for(lambda: lid.state == lid.CONNECTED and lid.snapshots > 0, 15.0)
        linkshaper.wait_for(lambda: len(room.server.player_names()) == 3, 5.0)
        return {
            "before": before,
            "dropped": dropped,
            "back": back,
            "lid_after": room.seats()[0],
            "newcomer": None if newcomer.welcome is None else newcomer.welcome.client,
            "names": room.server.player_names(),
        }
    finally:
        room.close()


def _in_input(shaper, delay_s: float = 0.1, loss: float = 0.1, block_udp: bool = False, moves: int = 120) -> dict:
    """A student moves their cursor right step by step; for each step, the time until the teacher's
    table had it or a later one."""
    shaper.shape(delay_s, loss=loss)
    shaper.block_udp = block_udp
    room = linkshaper.Classroom(1)
    try:
        net = room.students[0]
        room.still = net
        sent = {}
        for k in range(moves):
            x = round(1.0 + 0.01 * k, 4)
            sent[x] = time.monotonic()
            net.update_input((x, 2.0))
            time.sleep(1 / 30)
        for _ in range(60):  # the hand rests; the window still calls update_input every frame
            net.update_input((x, 2.0))
            time.sleep(1 / 30)
        with room.lock:
            seen = dict(room.effects.get(f"{net.welcome.client} {net.name}", {}))
        delays = []
        for x, at in sent.items():
            later = [t for y, t in seen.items() if y >= x]
            if later:
                delays.append(min(later) - at)
        return {"delays": sorted(delays), "sent": len(sent)}
    finally:
        room.close()


def _in_bad_join(shaper, students: int = 6) -> dict:
    shaper.shape(0.3, 0.09, loss=0.2)
    room = linkshaper.Classroom(students)
    try:
        linkshaper.wait_for(lambda: all(n.welcome is not None for n in room.students), 40.0)
        return {"joined": sum(n.welcome is not None for n in room.students), "errors": [n.error for n in room.students]}
    finally:
        room.close()


def _in_no_route(shaper) -> dict:
    from airtable.net.server import lan_addresses

    return {"addresses": lan_addresses()}


# ----------------------------------------------------------------- shaped-link tests


@needs_link
def test_the_join_line_names_the_classroom_address_where_no_route_leads_out():
    """A classroom network or a hotspot with no internet: no default route. The namespace has only
    its link's addresses; the join line named 127.0.0.1, which no student can reach."""
    addresses = linkshaper.run_isolated("test_classroom_link", "_in_no_route", 30.0)["addresses"]
    # Each interface's first address (the link's device has two).
    assert addresses and set(addresses) <= {linkshaper.CLIENT_HOST, linkshaper.SERVER_HOST}


@needs_link
@pytest.mark.parametrize("delay_s", [0.05, 0.1])
def test_every_student_gets_nearly_every_snapshot_at_a_long_round_trip(delay_s):
    result = linkshaper.run_isolated("test_classroom_link", "_in_rate", 60.0, delay_s=delay_s)
    published = result["published"]
    assert published > 10  # the teacher's loop ran
    # Two unacknowledged snapshots at most gave 17 of 30 a second at 50 ms one-way and 9.6 at 100.
    assert min(result["rates"]) >= 0.85 * published, result


@needs_link
def test_a_seven_second_cut_of_several_students_keeps_every_seat_and_colour():
    result = linkshaper.run_isolated("test_classroom_link", "_in_cut", 60.0)
    assert result["back"], result
    assert result["after"] == result["before"]  # each student back in their own seat, with its colour
    assert sorted(result["names"]) == sorted(f"{seat[0]} Kid{i}" for i, seat in enumerate(result["before"]))


@needs_link
def test_a_closed_lid_returns_to_its_seat_and_a_newcomer_meanwhile_gets_a_free_one():
    result = linkshaper.run_isolated("test_classroom_link", "_in_lid", 90.0)
    assert result["dropped"], result  # the server noticed the dead link
    assert result["back"], result
    assert result["lid_after"] == result["before"][0]  # C1 again, in C1's colour
    assert result["newcomer"] not in (None, result["before"][0][0], result["before"][1][0])
    assert result["newcomer"] == "C3"  # the lid's seat is held for them, the other one plays
    seats = [seat[0] for seat in result["before"]]  # the two joined at once: either may be C1
    assert sorted(result["names"]) == sorted([f"{seats[0]} Kid0", f"{seats[1]} Kid1", "C3 New2"])


@needs_link
def test_the_newest_input_is_not_held_up_behind_lost_ones():
    result = linkshaper.run_isolated("test_classroom_link", "_in_input", 60.0)
    delays = result["delays"]
    assert len(delays) == result["sent"]  # every step reached the table (or was overtaken by a newer one)
    # 100 ms one-way with 10 % loss, the same link with UDP blocked: over TCP alone a lost input holds up
    # the ones behind it (median 195 ms in the bench, 110 ms by UDP). Compared in one run, not to a clock.
    tcp = linkshaper.run_isolated("test_classroom_link", "_in_input", 60.0, block_udp=True)["delays"]
    assert delays[len(delays) // 2] < tcp[len(tcp) // 2]


@needs_link
def test_where_udp_is_blocked_inputs_still_come_by_tcp():
    result = linkshaper.run_isolated("test_classroom_link", "_in_input", 60.0, loss=0.0, block_udp=True, moves=40)
    assert len(result["delays"]) == result["sent"]


@needs_link
def test_students_join_across_a_slow_lossy_link():
    """300 ms +-90 one-way with 20 % loss: the server's 3 s HELLO deadline and the client's 5 s handshake
    ended some joins for good (27 of 30 in the bench); now a slow handshake is tried again."""
    result = linkshaper.run_isolated("test_classroom_link", "_in_bad_join", 80.0)
    assert result["joined"] == 6, result


def test_a_quick_link_is_not_slow():
    with socket.create_server(("127.0.0.1", 0)) as listener:
        sender = socket.create_connection(listener.getsockname(), timeout=5)
        receiver, _ = listener.accept()
        with sender, receiver:
            sender.sendall(b"x")
            assert receiver.recv(1) == b"x"
            # None where the kernel cannot tell; the byte's acknowledgement may take a moment.
            wait_until(lambda: pacing.link_is_slow(sender) in (False, None), what="a quick link")


# ----------------------------------------------------------------- on 127.0.0.1


class RawPlayer:
    """A client written by hand: HELLO, then whatever the test sends; reads only when asked."""

    def __init__(self, port: int, name: str, token: str | None = None, rcvbuf: int | None = None) -> None:
        self.sock = socket.socket()
        if rcvbuf:
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
        self.sock.settimeout(5.0)
        self.sock.connect(("127.0.0.1", port))
        self.sock.sendall(proto.encode_hello(name, token=token))
        self.reader = proto.FrameReader(proto.MAX_SERVER_FRAME, sender="the server")

    def welcome(self) -> dict:
        for _ in range(100):  # bounded: frames until the WELCOME
            for kind, payload in self.reader.feed(self.sock.recv(65536)):
                if kind == proto.WELCOME:
                    return json.loads(payload)
                assert kind != proto.ERROR, payload
        pytest.fail("no WELCOME")

    def close(self) -> None:
        self.sock.close()


def test_a_dropped_seat_is_held_for_its_token_and_a_newcomer_gets_another():
    with GameServer(host="127.0.0.1", port=0) as server:
        ann = RawPlayer(server.port, "Ann")
        first = ann.welcome()
        ann.close()  # a drop: no BYE
        wait_until(lambda: server.player_count == 0, what="Ann's drop")
        bob = RawPlayer(server.port, "Bob")
        assert bob.welcome()["client"] == "C2"  # C1 is held for Ann
        again = RawPlayer(server.port, "Ann", token=first["token"])
        back = again.welcome()
        assert (back["client"], back["color"]) == ("C1", first["color"])
        bob.close()
        again.close()


def test_a_goodbye_gives_the_seat_up():
    with GameServer(host="127.0.0.1", port=0) as server:
        ann = RawPlayer(server.port, "Ann")
        ann.welcome()
        ann.sock.sendall(proto.encode_bye())
        wait_until(lambda: server.player_count == 0, what="Ann's goodbye")
        assert RawPlayer(server.port, "Bob").welcome()["client"] == "C1"


def test_a_reconnect_with_the_token_takes_over_from_the_stale_connection_at_once(monkeypatch):
    # Ann's old connection has been silent for IN_USE_S (here 0: at once) but no timeout has passed.
    monkeypatch.setattr(server_module, "IN_USE_S", 0.0)
    with GameServer(host="127.0.0.1", port=0) as server:
        ann = RawPlayer(server.port, "Ann")
        first = ann.welcome()
        bob = RawPlayer(server.port, "Bob")
        assert bob.welcome()["client"] == "C2"
        again = RawPlayer(server.port, "Ann", token=first["token"])
        back = again.welcome()
        assert (back["client"], back["color"]) == ("C1", first["color"])
        wait_until(lambda: server.player_names() == ["C1 Ann", "C2 Bob"], what="one C1 Ann")
        ann.sock.settimeout(5.0)
        leftover = b""
        for _ in range(1000):  # bounded: the old connection is closed by the server
            data = ann.sock.recv(65536)
            if not data:
                break
            leftover += data
        else:
            pytest.fail("the stale connection stayed open")
        for client in (ann, bob, again):
            client.close()


def test_a_seat_still_heard_from_is_not_taken_over_the_newcomer_asks_again(monkeypatch):
    """Two live windows of one student (a token they shared, seat_memory.py) took the seat from each other
    twice a second, without end (a user test). A connection heard from within IN_USE_S is in use."""
    monkeypatch.setattr(server_module, "IN_USE_S", 1000.0)  # (Ann's connection is as live as can be)
    with GameServer(host="127.0.0.1", port=0) as server:
        ann = RawPlayer(server.port, "Ann")
        first = ann.welcome()
        again = RawPlayer(server.port, "Ann", token=first["token"])
        refusal = None
        for _ in range(100):  # bounded: frames until the ERROR
            frames = again.reader.feed(again.sock.recv(65536))
            refusal = next((json.loads(p) for kind, p in frames if kind == proto.ERROR), None)
            if refusal is not None:
                break
        assert refusal is not None and refusal.get("retry") is True, refusal
        assert refusal["error"] == IN_USE.format("C1 Ann")
        assert server.player_names() == ["C1 Ann"]  # hers still, on her connection
        for client in (ann, again):
            client.close()


def test_a_client_that_reads_nothing_is_dropped_and_its_seat_held(monkeypatch):
    """It keeps sending INPUT, so only the unread bytes show it is gone (as a frozen window)."""
    from airtable.model.scene import Scene
    from airtable.physics.table import AirTable

    table = AirTable()
    for i in range(40):
        table.add_puck((0.5 + 0.2 * i, 1.0 + 0.15 * i), radius_m=0.05, vel_mps=(0.5, 0.3))
    with GameServer(host="127.0.0.1", port=0, timeout_s=1.0) as server:
        lazy = RawPlayer(server.port, "Lazy", rcvbuf=4096)
        lazy.welcome()
        wait_until(lambda: server.player_count == 1, what="the join")
        deadline = time.monotonic() + 30.0
        k = 0
        while server.player_count and time.monotonic() < deadline:  # bounded
            k += 1
            table.step(1 / 30)
            server.publish(Scene.from_table(table, [], title="x" * (k % 7), status=str(k)))
            lazy.sock.sendall(proto.encode_input((1.0 + 0.001 * (k % 100), 1.0), 0, ()))
            time.sleep(1 / 30)
        assert server.player_count == 0  # dropped although its INPUTs kept coming
        newcomer = RawPlayer(server.port, "New")
        assert newcomer.welcome()["client"] == "C2"  # C1 is held for the one that froze
        newcomer.close()
        lazy.close()
