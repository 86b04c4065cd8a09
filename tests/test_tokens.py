"""Seat tokens that a program on the teacher's port cannot reuse: the token is proven, never sent again."""

from __future__ import annotations

import hashlib
import hmac
import secrets
import socket
import threading

import pytest
from conftest import WAIT_S, wait_until
from test_server import RawClient, clients, make_server  # noqa: F401  (fixtures)

from airtable.net import protocol as proto
from airtable.net.identity import SeatTokens, seat_proof, token_seat
from airtable.net.player import NetPlayer, PlayerState
from airtable.net.server import GameServer


def proof_by_hand(token: str, nonce: str) -> str:
    """docs/protocol.md's PROOF: HMAC-SHA256, key the token's bytes, message the label and the nonce."""
    return hmac.new(token.encode("ascii"), b"airtable seat proof\n" + nonce.encode("ascii"), hashlib.sha256).hexdigest()


def test_the_proof_is_the_documented_hmac_and_only_the_right_token_and_nonce_make_it():
    tokens = SeatTokens(b"k" * 32)
    token, nonce = tokens.make(7, "Ann"), "0123456789abcdef" * 2
    assert seat_proof(token, nonce) == proof_by_hand(token, nonce)
    assert len(seat_proof(token, nonce)) == 64
    docs_example = "5d5a8f1e5bad2a1718286f7ecf5ad3da153025f35a062a0b03baa8f71b369bbc"  # docs/protocol.md
    assert seat_proof("7-" + "0" * 32, "0123456789abcdef" * 2) == docs_example
    hello = b'\x00\x00\x00\x25\x01{"protocol":2,"name":"Ann","seat":2}'  # docs/protocol.md, byte by byte
    assert proto.encode_hello("Ann", seat=2) == hello
    assert proto.encode_challenge("0" * 32)[:5] == b"\x00\x00\x00\x2d\x0d"
    assert proto.encode_proof("0" * 64)[:5] == b"\x00\x00\x00\x4d\x0e"
    assert tokens.proves(7, "Ann", nonce, proof_by_hand(token, nonce))
    assert not tokens.proves(7, "Bo", nonce, proof_by_hand(token, nonce))  # the token is the name's
    assert not tokens.proves(6, "Ann", nonce, proof_by_hand(token, nonce))
    assert not tokens.proves(7, "Ann", "f" * 32, proof_by_hand(token, nonce))  # another nonce
    assert not SeatTokens(b"x" * 32).proves(7, "Ann", nonce, proof_by_hand(token, nonce))  # another key
    assert (token_seat(token), token_seat("junk"), token_seat(None)) == (7, None, None)


def claim(port: int, seat: int, name: str, token: str | None) -> tuple[proto.Welcome, str]:
    """Ask for `seat` as `name`, answering the CHALLENGE with `token`'s proof (a wrong one if None)."""
    c = RawClient(port)
    try:
        c.send(proto.encode_hello(name, seat=seat))
        kind, payload = c.next_frame()
        assert kind == proto.CHALLENGE, proto.FRAME_NAMES[kind]
        nonce = proto.parse_challenge(payload)
        c.send(proto.encode_proof(proof_by_hand(token, nonce) if token else "0" * 64))
        return proto.parse_welcome(c.next_of(proto.WELCOME)), nonce
    finally:
        c.close()


def test_a_proven_seat_comes_back_and_a_wrong_proof_asks_for_nothing(make_server, clients):  # noqa: F811
    server = make_server(token_key=b"k" * 32)
    bo, ann = clients(server.port), clients(server.port)
    bo.hello("Bo")
    token = ann.hello("Ann").token
    clients(server.port).hello("Cy")
    assert token is not None and token_seat(token) == 2
    for c in (bo, ann):
        c.send(proto.encode_bye())
    wait_until(lambda: server.player_names() == ["C3 Cy"], what="C1 and C2 to be given up")
    mallory, nonce = claim(server.port, 2, "Mal", None)  # (dropped at once: her seat and name are held)
    assert mallory.client != "C2"  # a wrong proof is no claim: some free seat, not Ann's
    back, again = claim(server.port, 2, "Ann", token)
    assert (back.client, back.label) == ("C2", "C2 Ann")
    assert nonce != again  # a new nonce for every challenge


def test_a_student_away_keeps_her_name_and_a_newcomer_of_that_name_is_numbered(make_server, clients):  # noqa: F811
    """A user test: Ann's laptop was away; a newcomer typed "Ann" and got "C5 Ann"; Ann came back to
    her seat as "C1 Ann 2". A held seat holds its name too."""
    server = make_server(token_key=b"k" * 32)
    ann = clients(server.port)
    token = ann.hello("Ann").token
    ann.close()  # a drop, no goodbye: the seat is held
    wait_until(lambda: server.player_names() == [], what="Ann's drop to be noticed")
    newcomer = clients(server.port).hello("Ann")
    assert (newcomer.client, newcomer.label) == ("C2", "C2 Ann 2")
    back, _ = claim(server.port, 1, "Ann", token)
    assert (back.client, back.label) == ("C1", "C1 Ann")


@pytest.mark.parametrize(
    "frames, hint",
    [
        ([proto.encode_proof("0" * 64)], "PROOF came without a CHALLENGE"),
        ([proto.encode_hello("Ann", seat=2), proto.encode_hello("Ann", seat=2)], "HELLO was sent twice"),
        ([proto.encode_json(proto.HELLO, {"protocol": proto.PROTOCOL_VERSION, "seat": 0})], '"seat" must be'),
        ([proto.encode_hello("Ann", seat=2), proto.encode_json(proto.PROOF, {"proof": "xyz"})], "64 lowercase hex"),
    ],
)
def test_bad_seat_claims_get_a_sentence(make_server, clients, frames, hint):  # noqa: F811
    server = make_server()
    c = clients(server.port)
    for f in frames:
        c.send(f)
    kinds = []
    for _ in range(3):
        got = c.next_frame()
        assert got is not None, f"closed without an ERROR after {kinds}"
        kinds.append(got[0])
        if got[0] == proto.ERROR:
            break
    assert kinds[-1] == proto.ERROR and set(kinds[:-1]) <= {proto.CHALLENGE}
    assert hint in proto.parse_error(got[1])


class FakeServer:
    """What a program that takes the port after the teacher quits sees: it records every byte of one
    connection, answers HELLO with a CHALLENGE of its own, takes the PROOF, then hangs up."""

    def __init__(self, port: int) -> None:
        self.listener = socket.socket()
        self.listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.listener.bind(("127.0.0.1", port))
        self.listener.listen(4)
        self.listener.settimeout(WAIT_S)
        self.received = bytearray()
        self.frames: list[tuple[int, bytes]] = []
        self.done = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        try:
            sock, _ = self.listener.accept()
        except OSError:
            return
        with sock:
            sock.settimeout(WAIT_S)
            reader = proto.FrameReader(proto.MAX_CLIENT_FRAME, proto.CLIENT_FRAMES)
            for _ in range(100):  # bounded: a HELLO and a PROOF are two frames
                data = sock.recv(4096)
                if not data:
                    break
                self.received += data
                for frame in reader.feed(data):
                    self.frames.append(frame)
                    if frame[0] == proto.HELLO:
                        sock.sendall(proto.encode_challenge(secrets.token_hex(16)))
                if any(t == proto.PROOF for t, _ in self.frames) or not reader.pending and self._told_no_seat():
                    break
            sock.sendall(proto.encode_error("the table is busy", retry=True))
        self.done.set()

    def _told_no_seat(self) -> bool:
        return any(t == proto.HELLO and proto.parse_hello(p).seat is None for t, p in self.frames)

    def close(self) -> None:
        self.listener.close()
        self.thread.join(timeout=WAIT_S)


def test_a_program_on_the_port_after_the_teacher_quits_learns_nothing_that_takes_the_seat():
    key = b"k" * 32
    first = GameServer(host="127.0.0.1", port=0, token_key=key)
    first.start()
    port = first.port
    bo = RawClient(port)
    bo.hello("Bo")  # C1, so Ann is C2
    net = NetPlayer("127.0.0.1", port, name="Ann", max_backoff_s=0.25)
    fake = second = None
    try:
        assert net.connect().client == "C2"
        token = net.welcome.token
        assert token is not None
        bo.close()
        first.stop()  # the teacher quits; Ann's client tries again by itself
        wait_until(lambda: net.state == PlayerState.RETRYING, what="Ann's client to notice")
        fake = FakeServer(port)  # another program takes the port
        wait_until(fake.done.is_set, what="Ann's client to talk to the fake")
        net.close()  # Ann shuts her laptop
        fake.close()
        # What the fake learnt: the seat's number and a proof for its own nonce, not the token.
        assert token.encode() not in fake.received and token.split("-")[1].encode() not in fake.received
        hello = next(proto.parse_hello(p) for t, p in fake.frames if t == proto.HELLO)
        assert (hello.seat, hello.token, hello.name) == (2, None, "Ann")
        captured = b"".join(proto.encode_frame(t, p) for t, p in fake.frames if t in (proto.HELLO, proto.PROOF))
        # The teacher starts the table again (same key, so seats survive); the fake replays all it has.
        second = GameServer(host="127.0.0.1", port=port, token_key=key)
        second.start()
        replay = RawClient(port)
        replay.send(captured)  # HELLO, and the PROOF before the real CHALLENGE even came
        kinds = []
        for _ in range(3):
            got = replay.next_frame()
            if got is None:
                break
            kinds.append(got[0])
            if got[0] == proto.WELCOME:
                assert proto.parse_welcome(got[1]).client != "C2"  # Ann's seat is not the fake's
                break
        assert kinds[0] == proto.CHALLENGE
        replay.close()
        back, _ = claim(port, 2, "Ann", token)  # Ann, with her token, still gets her seat
        assert back.client == "C2"
    finally:
        net.close()
        bo.close()
        first.stop()
        if fake is not None:
            fake.close()
        if second is not None:
            second.stop()
