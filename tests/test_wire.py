"""Snapshot format 2 through the real server: layouts only when they change, and a
player that read nothing for a while still decodes everything and catches up."""

from __future__ import annotations

import socket
import time

import numpy as np
import pytest
from conftest import wait_until

from airtable.model.scene import Scene
from airtable.net import protocol as proto
from airtable.net.codec import SnapshotDecoder
from airtable.net.server import GameServer


def scene(k: int, color=(255, 255, 255)) -> Scene:
    """400 pucks drifting with a wobble the server cannot predict: each tick about 360 bytes."""
    n = 400
    i = np.arange(n)
    wobble = 0.002 * np.sin(k * (1.0 + i))
    pos = np.column_stack([0.5 + 0.02 * i + 0.01 * k + wobble, 2.0 + 0.001 * k + wobble])
    colors = np.tile(np.array(color, np.uint8), (n, 1))
    return Scene(10.0, 8.7556, pos, np.full(n, 0.1), colors, title="wire test", status=f"k = {k}", time_s=k / 30)


class Player:
    """A raw player that reads only when told to."""

    def __init__(self, port: int, receive_buffer: int | None = None) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        if receive_buffer is not None:  # a small window: the server soon has to skip this player
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, receive_buffer)
        self.sock.settimeout(10)
        self.sock.connect(("127.0.0.1", port))
        self.snapshots = 0
        self.reader = proto.FrameReader(proto.MAX_SERVER_FRAME, sender="the server")
        self.decoder = SnapshotDecoder()
        self.layouts = 0
        self.scene: Scene | None = None
        self.sock.sendall(proto.encode_hello("wire"))

    def read_until(self, done, what: str) -> None:
        """Read and decode (bounded by the socket timeout) until `done(self)`."""
        for _ in range(100_000):
            if done(self):
                return
            data = self.sock.recv(65536)
            assert data, f"the server hung up while waiting for {what}"
            for kind, payload in self.reader.feed(data):
                if kind == proto.LAYOUT:
                    self.layouts += 1
                    self.decoder.feed_layout(payload)
                elif kind == proto.SNAPSHOT:
                    self.scene = self.decoder.feed_tick(payload).scene
                    self.snapshots += 1
        pytest.fail(f"never saw {what}")

    def close(self) -> None:
        self.sock.close()


@pytest.fixture
def server():
    s = GameServer(host="127.0.0.1", port=0, snapshot_hz=1000)
    s.start()
    yield s
    s.stop()


LAST = 40  # ticks: about 14 KB, more than twice what b's small window takes


def _status(k: int):
    return lambda p: p.scene is not None and p.scene.status == f"k = {k}"


def publish_after_a_period(server: GameServer, frame: Scene) -> None:
    """publish() sends at most snapshot_hz a second: let one period pass so this one goes."""
    t = time.monotonic()
    wait_until(lambda: time.monotonic() - t > 2.0 / server.snapshot_hz, what="a snapshot period", poll_s=0.0005)
    server.publish(frame)


def test_a_player_that_reads_slowly_is_skipped_and_catches_up(server):
    a, b = Player(server.port), Player(server.port, receive_buffer=4096)
    try:
        wait_until(lambda: len(server.player_names()) == 2, what="both players")
        for k in range(1, LAST + 1):  # a reads every tick; b reads none: its small window soon fills
            publish_after_a_period(server, scene(k))
            a.read_until(_status(k), f"tick {k}")
        b.read_until(_status(LAST), "the newest tick")
        for p in (a, b):
            assert np.abs(p.scene.pos_m - scene(LAST).pos_m).max() <= 0.5 / 4000 + 1e-12
        assert b.snapshots < a.snapshots  # b was skipped, and its deltas still decoded
        assert (a.layouts, b.layouts) == (1, 1)
        publish_after_a_period(server, scene(LAST + 1, color=(255, 0, 0)))  # new colours: a new layout
        for p in (a, b):
            p.read_until(_status(LAST + 1), "the red tick")
            assert p.layouts == 2 and tuple(p.scene.color_rgb[0]) == (255, 0, 0)
    finally:
        a.close()
        b.close()
