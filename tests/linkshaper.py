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
        if cut or self._rng.random() < direction.loss:
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
    path = os.pathsep.join(p for p in sys.path if p and os.path.isdir(p))  # the module is found as here
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
