"""Held seats, the in-flight budget, the player's outbox and input datagrams, by hand."""

from __future__ import annotations

import socket

import pytest
from hypothesis import given
from hypothesis import strategies as st

from airtable.net import datagrams, pacing
from airtable.net.outbox import Outbox
from airtable.net.seats import HeldSeats

# ----------------------------------------------------------------- held seats


def test_a_held_seat_is_skipped_until_its_hold_runs_out():
    seats = HeldSeats(hold_s=120.0)
    seats.hold(1, now=10.0)
    assert seats.free_number({2}, now=10.0) == 3  # 1 held, 2 taken
    assert seats.is_held(1, now=129.9) and not seats.is_held(1, now=130.0)
    assert seats.free_number({2}, now=130.0) == 1  # the hold ran out: C1 is free again
    assert seats.held(130.0) == []


def test_a_seat_given_back_is_no_longer_held():
    seats = HeldSeats()
    seats.hold(3, now=0.0)
    seats.hold(1, now=0.0)
    assert seats.held(1.0) == [1, 3]
    seats.give_back(1)
    assert seats.held(1.0) == [3] and seats.free_number(set(), now=1.0) == 1


@given(st.sets(st.integers(1, 40)), st.sets(st.integers(1, 40)))
def test_the_free_number_is_the_lowest_neither_taken_nor_held(taken, held):
    seats = HeldSeats()
    for n in held:
        seats.hold(n, now=0.0)
    expected = next(n for n in range(1, 100) if n not in taken and n not in held)  # the oracle: count up
    assert seats.free_number(taken, now=1.0) == expected


# ----------------------------------------------------------------- the in-flight budget


def test_the_budget_is_a_round_trip_of_snapshots():
    # Snapshots of 1000 bytes count as 1250 (SIZE_MARGIN). 200 ms round trip, one every 40 ms: 5 in flight.
    assert pacing.in_flight_budget(0.2, 0.2, 1000, 0.04) == 5 * 1250
    # 600 ms (300 ms one-way), one every 1/30 s: 18.
    assert pacing.in_flight_budget(0.6, 0.59, 100, 1 / 30) == 18 * 125
    # Loopback: one, as the old rule allowed (the next goes while one is unacknowledged).
    assert pacing.in_flight_budget(0.0001, 0.0001, 400, 1 / 30) == 500
    # A 10 s round trip is capped at MAX_IN_FLIGHT snapshots.
    assert pacing.in_flight_budget(10.0, 9.0, 100, 1 / 30) == pacing.MAX_IN_FLIGHT * 125


def test_a_queueing_link_gets_only_what_its_lowest_round_trip_needs():
    # The smoothed round trip is above 2 x the lowest + 30 ms: a queue has built up (a full hotspot).
    # Lowest 90 ms, a snapshot every 40 ms: 2.25 -> 3 snapshots a round trip, less the one about to go.
    assert pacing.in_flight_budget(0.25, 0.09, 1000, 0.04) == 2 * 1250
    # 200 ms, below the line (210 ms): 5 a round trip.
    assert pacing.in_flight_budget(0.2, 0.09, 1000, 0.04) == 5 * 1250
    # On a LAN (lowest 1 ms): nothing, the next snapshot waits for every byte to be acknowledged.
    assert pacing.in_flight_budget(0.05, 0.001, 1000, 1 / 30) == 0


def test_the_rate_a_budget_allows_on_a_simulated_link():
    """An independent little link: a snapshot every 1/30 s is sent if the unacknowledged bytes are within
    the budget, and is acknowledged one round trip after it left. Count what went out over 10 s."""
    for one_way_s, wanted in ((0.05, 298), (0.1, 298), (0.3, 298)):
        rtt, size, period = 2 * one_way_s, 2700, 1 / 30
        in_flight: list[float] = []  # when each unacknowledged snapshot will be acknowledged
        sent = 0
        for tick in range(300):
            now = tick * period
            in_flight = [t for t in in_flight if t > now]
            if len(in_flight) * size <= pacing.in_flight_budget(rtt, rtt, size, period):
                in_flight.append(now + rtt)
                sent += 1
        assert sent >= wanted, (one_way_s, sent)
        old = 2 * 10 / rtt  # the old rule, at most two unacknowledged: about 2 per round trip
        assert old < 0.7 * sent


# ----------------------------------------------------------------- the player's outbox


def _filled_pair():
    a, b = socket.socketpair()
    a.setblocking(False)
    for _ in range(100_000):  # bounded: fill a's send buffer and b's receive buffer
        try:
            a.send(b"\0" * 65536)
        except BlockingIOError:
            break
    return a, b


def test_the_outbox_never_waits_and_keeps_only_the_newest_input():
    a, b = _filled_pair()
    with a, b:
        a.settimeout(0.25)  # as the player's socket: the outbox must not wait for it
        box = Outbox()
        box.put(b"old input", replaceable=True)
        box.flush(a)  # full: nothing goes, nothing waits
        box.put(b"PREDICT", replaceable=False)
        box.put(b"new input", replaceable=True)
        assert [frame for _, frame in box._waiting] == [b"PREDICT", b"new input"]
        b.setblocking(False)
        drained = 0
        for _ in range(100_000):  # bounded: read what was in the way
            try:
                drained += len(b.recv(1 << 20))
            except BlockingIOError:
                break
        box.flush(a)
        assert box.empty
        b.settimeout(5.0)
        got = b""
        for _ in range(100):  # bounded: the two frames, in order
            got += b.recv(65536)
            if got.endswith(b"new input"):
                break
        assert got.endswith(b"PREDICTnew input")


def test_the_outbox_raises_when_the_connection_broke():
    a, b = socket.socketpair()
    b.close()
    with a:
        box = Outbox()
        box.put(b"x" * 100)
        with pytest.raises(OSError):
            for _ in range(10):  # the first send may still succeed; a later one finds the reset
                box.put(b"y" * 100)
                box.flush(a)


# ----------------------------------------------------------------- input datagrams


def test_an_input_datagram_is_signed_and_checked():
    key, other = "00" * 16, "11" * 16
    data = datagrams.encode_input(key, 3, 7, b'{"cursor_m": [1, 2]}')
    # u8 type 11, u32 seat 3, u32 sequence 7, then 16 bytes of MAC, then the payload.
    assert data[:9] == bytes([11, 0, 0, 0, 3, 0, 0, 0, 7]) and data[25:] == b'{"cursor_m": [1, 2]}'
    d = datagrams.parse(data)
    assert (d.kind, d.number, d.sequence) == (datagrams.INPUT_DATAGRAM, 3, 7)
    assert d.verify(key) and not d.verify(other) and not d.verify(None)
    forged = data[:8] + bytes([8]) + data[9:]  # sequence 8 with the MAC of 7
    assert not datagrams.parse(forged).verify(key)
    ack = datagrams.parse(datagrams.encode_ack(key, 3, 7))
    assert ack.kind == datagrams.INPUT_ACK and ack.verify(key) and ack.payload == b""


@given(st.binary(max_size=2000))
def test_any_bytes_parse_to_a_datagram_or_none_without_raising(data):
    d = datagrams.parse(data)
    assert d is None or d.kind in (datagrams.INPUT_DATAGRAM, datagrams.INPUT_ACK)
