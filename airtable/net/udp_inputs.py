"""The player's side of inputs over UDP (datagrams.py says why and how): send, and learn whether UDP gets through."""

from __future__ import annotations

import contextlib
import math
import socket

from airtable.net import datagrams

CONFIRMED_S = 2.0  # UDP counts as getting through for this long after an acknowledgement
MAX_ACKS_READ = 64  # acknowledgements read per call, at most


class UdpInputs:
    """One session's input datagrams to the server at `peer` (the TCP session's address and port)."""

    def __init__(self, peer: tuple, key: str, number: int) -> None:
        self.key, self.number = key, number
        self.sequence = 0  # of the last datagram sent
        self.acked = 0  # the newest sequence the server acknowledged
        self.acked_at = -math.inf
        family = socket.AF_INET6 if ":" in str(peer[0]) else socket.AF_INET
        self.sock = socket.socket(family, socket.SOCK_DGRAM)
        self.sock.setblocking(False)
        try:
            self.sock.connect(peer[:2] if family == socket.AF_INET else peer)
        except OSError:
            self.sock.close()
            raise

    def send(self, payload: bytes) -> None:
        """Send one INPUT's JSON payload as the next datagram; a lost or refused one is just lost."""
        self.sequence = min(self.sequence + 1, datagrams.MAX_SEQUENCE)
        with contextlib.suppress(OSError):
            self.sock.send(datagrams.encode_input(self.key, self.number, self.sequence, payload))

    def confirmed(self, now: float) -> bool:
        """Whether the server acknowledged one of our datagrams in the last CONFIRMED_S."""
        for _ in range(MAX_ACKS_READ):
            try:
                data = self.sock.recv(2048)
            except OSError:  # nothing waiting, or an ICMP "port unreachable": no UDP there
                break
            d = datagrams.parse(data)
            if d is not None and d.kind == datagrams.INPUT_ACK and d.number == self.number and d.verify(self.key):
                self.acked_at, self.acked = now, max(self.acked, d.sequence)
        return now - self.acked_at < CONFIRMED_S

    @property
    def delivered(self) -> bool:
        """Whether the server acknowledged the last datagram sent (as of the last `confirmed`)."""
        return self.acked >= self.sequence

    def close(self) -> None:
        self.sock.close()
