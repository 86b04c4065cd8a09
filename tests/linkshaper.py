"""A shaped link for tests and the classroom-link bench: delay, jitter, loss and cuts that TCP really sees.

This machine's kernel has no netem, and a relay that reads a socket and writes it on later would
acknowledge every byte at once, so the server's pacing (which reads the kernel's round trip and
unacknowledged bytes) would see a link with no delay at all. So the link is made one level down:
in a private network namespace (`unshare -n`, deleted with the process), a TUN device carries the
packets of two local addresses through this program, which holds each packet for the one-way delay
(plus jitter, so packets reorder), drops some, and drops all of a cut flow's. TCP then measures the
real round trip, retransmits what was lost and recovers after a cut, as on a school's Wi-Fi.

The two ends are two addresses of the namespace: the server listens on SERVER_HOST (10.77.1.1);
students connect to SERVER_VIA (10.77.1.2) and their packets leave from CLIENT_HOST (10.77.0.1).
The shaper turns "10.77.0.1 -> 10.77.1.2" into "10.77.0.2 -> 10.77.1.1" and back (each address's
last byte 1 <-> 2: the source goes up by one and the destination down by one, so the IP and TCP
checksums stay right without being worked out again).

`run_isolated(module, function, **kwargs)` runs `function(shaper, **kwargs)` from `module` in such a
namespace (a child process, bounded in time) and returns what it returned (JSON); `isolation_problem()`
says why the machine cannot (not root, no unshare, no /dev/net/tun), for a skip.
"""

from __future__ import annotations

import fcntl
import heapq
import importlib
import json
import os
import random
import select
import shutil
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path

CLIENT_HOST = "10.77.0.1"
SERVER_HOST = "10.77.1.1"
SERVER_VIA = "10.77.1.2"
DEVICE = "atshape0"
_TUNSETIFF = 0x400454CA
_IFF_TUN, _IFF_NO_PI = 0x0001, 0x1000
ROOT = Path(__file__).resolve().parent.parent


class Direction:
    """How one direction of the link treats packets: delay and jitter (s), loss (0-1)."""

    def __init__(self, delay_s: float = 0.0, jitter_s: float = 0.0, loss: float = 0.0) -> None:
        self.delay_s, self.jitter_s, self.loss = delay_s, jitter_s, loss

    def hold_s(self, rng: random.Random) -> float:
        return max(0.0, self.delay_s + rng.uniform(-self.jitter_s, self.jitter_s))


class Shaper:
    """The TUN device and the thread that carries its packets (see the module docstring)."""

    def __init__(self, seed: int = 1) -> None:
        self.up = Direction()  # student -> teacher
        self.down = Direction()  # teacher -> student
        self.cut_ports: set[int] = set()  # students' local TCP/UDP ports whose packets are all dropped
        self.cut_all = False
        self.block_udp = False  # as a school firewall that lets only TCP through
        self.dropped = 0
        self._rng = random.Random(seed)
        self._lock = threading.Lock()
        self._queue: list[tuple[float, int, bytes]] = []
        self._count = 0
        self._fd = os.open("/dev/net/tun", os.O_RDWR)
        fcntl.ioctl(self._fd, _TUNSETIFF, struct.pack("16sH", DEVICE.encode(), _IFF_TUN | _IFF_NO_PI))
        _configure()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="link-shaper", daemon=True)
        self._thread.start()

    def shape(self, delay_s: float, jitter_s: float = 0.0, loss: float = 0.0) -> None:
        """The same delay, jitter and loss each way."""
        self.up = Direction(delay_s, jitter_s, loss)
        self.down = Direction(delay_s, jitter_s, loss)

    def cut(self, ports=(), everyone: bool = False) -> None:
        """Drop every packet of these students' connections (by their local port), or of everyone."""
        with self._lock:
            self.cut_ports |= set(ports)
            self.cut_all = self.cut_all or everyone

    def restore(self) -> None:
        with self._lock:
            self.cut_ports.clear()
            self.cut_all = False

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)
        os.close(self._fd)

    def _run(self) -> None:
        while not self._stop.is_set():
            now = time.monotonic()
            wait = 0.05
            if self._queue:
                wait = max(0.0, min(wait, self._queue[0][0] - now))
            ready, _, _ = select.select([self._fd], [], [], wait)
            if ready:
                for _ in range(256):  # a bounded batch, then the due packets go out
                    try:
                        self._take(os.read(self._fd, 65536))
                    except BlockingIOError:
                        break
                    if not select.select([self._fd], [], [], 0)[0]:
                        break
            self._deliver(time.monotonic())

    def _take(self, packet: bytes) -> None:
        if len(packet) < 24 or packet[0] >> 4 != 4:
            return  # only IPv4 is carried
        upward = packet[14] == 0  # from 10.77.0.x: a student's packet
        ihl = (packet[0] & 15) * 4
        port = struct.unpack_from("!H", packet, ihl if upward else ihl + 2)[0]
        direction = self.up if upward else self.down
        with self._lock:
            cut = self.cut_all or port in self.cut_ports
        if cut or (self.block_udp and packet[9] == 17) or self._rng.random() < direction.loss:
            self.dropped += 1
            return
        pkt = bytearray(packet)
        pkt[15], pkt[19] = pkt[15] + 1, pkt[19] - 1  # see the module docstring: checksums unchanged
        self._count += 1
        heapq.heappush(self._queue, (time.monotonic() + direction.hold_s(self._rng), self._count, bytes(pkt)))

    def _deliver(self, now: float) -> None:
        while self._queue and self._queue[0][0] <= now:
            _, _, pkt = heapq.heappop(self._queue)
            try:
                os.write(self._fd, pkt)
            except OSError:
                pass  # the kernel refused one packet: as if the link lost it


def _configure() -> None:
    for command in (
        "ip link set lo up",
        f"ip link set {DEVICE} up mtu 1500",
        f"ip addr add {CLIENT_HOST}/32 dev {DEVICE}",
        f"ip addr add {SERVER_HOST}/32 dev {DEVICE}",
        f"ip route add 10.77.1.2/32 dev {DEVICE} src {CLIENT_HOST}",
        f"ip route add 10.77.0.2/32 dev {DEVICE} src {SERVER_HOST}",
    ):
        subprocess.run(command.split(), check=True, capture_output=True, timeout=10)
    for name in ("all", "default", DEVICE):
        Path(f"/proc/sys/net/ipv4/conf/{name}/rp_filter").write_text("0")


def isolation_problem() -> str | None:
    """Why a shaped link cannot be made here, or None."""
    if not sys.platform.startswith("linux"):
        return "a shaped link needs Linux network namespaces"
    if os.geteuid() != 0:
        return "a shaped link needs root (a private network namespace and a TUN device)"
    if shutil.which("unshare") is None or shutil.which("ip") is None:
        return "a shaped link needs the unshare and ip commands"
    if not os.path.exists("/dev/net/tun"):
        return "a shaped link needs /dev/net/tun"
    return None


def run_isolated(module: str, function: str, timeout_s: float = 60.0, **kwargs):
    """`function(shaper, **kwargs)` from `module`, run in a private network namespace; its JSON result."""
    code = (
        "import json, sys; sys.path[:0] = [sys.argv[1], sys.argv[1] + '/tests']; "
        "import linkshaper; print(linkshaper.JSON_MARK + json.dumps(linkshaper._child(sys.argv[2], sys.argv[3], "
        "json.loads(sys.argv[4]))))"
    )
    args = ["unshare", "-n", sys.executable, "-c", code, str(ROOT), module, function, json.dumps(kwargs)]
    # The child finds modules as this process does.
    path = os.pathsep.join(os.path.abspath(p or ".") for p in sys.path if os.path.isdir(p or "."))
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy", "PYTHONPATH": path}
    done = subprocess.run(args, capture_output=True, text=True, timeout=timeout_s, env=env)
    for line in done.stdout.splitlines():
        if line.startswith(JSON_MARK):
            return json.loads(line[len(JSON_MARK) :])
    raise RuntimeError(f"the shaped-link run failed (exit {done.returncode}):\n{done.stderr[-3000:]}")


JSON_MARK = "@@result@@ "


def _child(module: str, function: str, kwargs: dict):
    shaper = Shaper()
    try:
        return getattr(importlib.import_module(module), function)(shaper, **kwargs)
    finally:
        shaper.close()


class Classroom:
    """A teacher's table (a headless 60 fps loop publishing 30 snapshots a second) and students built on
    the real client (`NetPlayer`), joined across the shaped link. For tests and the bench, in the child."""

    def __init__(self, students: int = 3, pucks: int = 12, **server_options) -> None:
        from airtable.model.client import Client
        from airtable.net.server import GameServer
        from airtable.physics.table import AirTable

        # Every student comes from one address here: no per-address limit.
        options = {"players_per_address": 1000, "handshakes_per_address": 1000, **server_options}
        self.server = GameServer(host=SERVER_HOST, port=0, **options)
        self.server.start()
        self.table = AirTable()
        for i in range(pucks):  # a row of pucks drifting, so every snapshot carries motion
            self.table.add_puck((0.5 + 0.7 * i % 9.0, 1.0 + 0.6 * (i // 12)), radius_m=0.2, vel_mps=(0.3, 0.2))
        self.clients = [Client(name="local", active=False)]
        self.lock = threading.Lock()
        self.effects: dict[str, dict[float, float]] = {}  # player name -> {cursor x: when the table first had it}
        self.students: list = []
        self._stop = threading.Event()
        self._loop = threading.Thread(target=self._run, name="table-loop", daemon=True)
        self._loop.start()
        self.join(students)
        self._hands = threading.Thread(target=self._move, name="students-hands", daemon=True)
        self._hands.start()

    def join(self, count: int, prefix: str = "Kid") -> list:
        """`count` more students, connected in parallel; returns them."""
        from airtable.net.player import NetPlayer

        first = len(self.students)
        new = [
            NetPlayer(SERVER_VIA, self.server.port, name=f"{prefix}{first + i}", max_backoff_s=1.0)
            for i in range(count)
        ]
        threads = [threading.Thread(target=_connect_quietly, args=(net,), daemon=True) for net in new]
        for t in threads:
            t.start()
        for t in threads:
            t.join(timeout=60.0)
        self.students += new
        return new

    def _run(self) -> None:
        from airtable.model.scene import Scene

        frame_s, next_t = 1 / 60, time.monotonic()
        while not self._stop.is_set():
            with self.lock:
                self.server.update_clients(self.clients, self.table)
                now = time.monotonic()
                for client in self.clients[1:]:
                    seen = self.effects.setdefault(client.name, {})
                    seen.setdefault(round(float(client.cursor_m[0]), 4), now)
                for _ in range(4):
                    self.table.step(frame_s / 4)
                self.server.publish(Scene.from_table(self.table, self.clients, title="link", status=f"{now:.3f}"))
            next_t += frame_s
            time.sleep(max(0.0, next_t - time.monotonic()))

    def _move(self) -> None:
        """Every student's cursor circles slowly, as a hand on a mouse would (5 moves a second: enough
        for the server's one INPUT a second, light enough that 30 students in one process keep up)."""
        import math

        while not self._stop.wait(1 / 5):
            t = time.monotonic()
            for i, net in enumerate(list(self.students)):
                if net is not self.still:
                    angle = 0.5 * t + i
                    net.update_input((5.0 + 2.0 * math.cos(angle), 4.0 + 2.0 * math.sin(angle)))

    still = None  # a student whose cursor the caller drives itself

    def rates(self, seconds: float) -> list[float]:
        """Snapshots a second each student received over the next `seconds`."""
        before = [net.snapshots for net in self.students]
        time.sleep(seconds)
        return [(net.snapshots - b) / seconds for net, b in zip(self.students, before, strict=True)]

    def seats(self) -> list[tuple[str, list[int]] | None]:
        """Each student's seat ("C3") and colour, or None while it has none."""
        return [None if n.welcome is None else (n.welcome.client, list(n.welcome.color)) for n in self.students]

    def port_of(self, net) -> int | None:
        sock = net._sock
        try:
            return None if sock is None else sock.getsockname()[1]
        except OSError:
            return None

    def close(self) -> None:
        self._stop.set()
        self._hands.join(timeout=5.0)
        for net in self.students:
            net.close()
        self._loop.join(timeout=5.0)
        self.server.stop()


def _connect_quietly(net) -> None:
    try:
        net.connect()
    except Exception as e:  # the caller looks at net.state and net.error
        net.error = str(e)


def wait_for(condition, timeout_s: float, poll_s: float = 0.05) -> bool:
    """Poll `condition` until true (True) or `timeout_s` passed (False): a bound, not a measurement."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(poll_s)
    return bool(condition())
