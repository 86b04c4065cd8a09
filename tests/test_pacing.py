"""Pacing: round-robin order and the kernel's count of unacknowledged bytes."""

from __future__ import annotations

import socket
import sys

import pytest

from airtable.net import pacing


def test_round_robin_starts_one_place_later_each_time():
    turns = pacing.RoundRobin()
    assert [turns.order("abc") for _ in range(4)] == [list("abc"), list("bca"), list("cab"), list("abc")]
    assert turns.order([]) == []


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the unacknowledged-byte count is Linux only")
def test_a_student_whose_bytes_are_not_taken_is_held_back():
    with socket.create_server(("127.0.0.1", 0)) as listener:
        sender = socket.create_connection(listener.getsockname(), timeout=5)
        receiver, _ = listener.accept()
        with sender, receiver:
            assert pacing.queued_bytes(sender) == 0
            assert pacing.may_send(sender, 1000)
            smoothed, lowest = pacing.round_trip_s(sender)
            assert 0 <= lowest <= smoothed < 1.0
            sender.setblocking(False)
            sent = 0
            for _ in range(10_000):  # bounded: fill both buffers until the socket says stop
                try:
                    sent += sender.send(b"x" * 65536)
                except BlockingIOError:
                    break
            assert sent > 0
            assert pacing.queued_bytes(sender) > 1000  # the receiver reads nothing, so nothing is acknowledged
            assert not pacing.may_send(sender, 1000)
