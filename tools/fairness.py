"""Per-student snapshot rates on a link of limited bandwidth (Linux network namespaces).

    python -m tools.fairness [--mbit 5 10 20] [--clients 30] [--seconds 5]

creates a private network namespace, brings up its loopback and holds it to
the given rate with a token bucket (`tc qdisc add dev lo root tbf rate
10mbit burst 32kbit latency 50ms`), runs a headless demo 4 table with a
server in it and N load-tool players that drag pucks round, and prints the
snapshots per second each student received. A fair server lets every
student's rate drop evenly when the link cannot carry everything.

Needs root (or CAP_NET_ADMIN) and the `ip` and `tc` tools; `available()` says
why not where they are missing. Only loopback addresses are used, every wait
is bounded, and the namespace is deleted in a `finally`.

Inside the namespace run the load tool's own table server (`python -m
tools.loadtest --serve`) and this module's `measure` subcommand (the
players; prints JSON).
"""

from __future__ import annotations

import argparse
import json
import os
import selectors
import shutil
import statistics
import subprocess
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass

from airtable.processes import stop_process
from tools import ROOT

PORT = 8888
BENCH_MBIT = (5, 10, 20)
START_TIMEOUT_S = 30.0


def _ip(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    return subprocess.run(["ip", *args], capture_output=True, text=True, timeout=20, check=check)


def available() -> str | None:
    """None when namespaces and tc work here, else the reason they do not."""
    if sys.platform != "linux":
        return "network namespaces need Linux"
    for tool in ("ip", "tc"):
        if shutil.which(tool) is None:
            return f"the {tool!r} tool is not installed (iproute2)"
    name = f"airtable-probe-{os.getpid()}"
    try:
        made = _ip("netns", "add", name, check=False)
        if made.returncode != 0:
            return f"cannot create a network namespace ({made.stderr.strip() or 'permission denied'}); run as root"
        shaped = _ip("netns", "exec", name, "tc", "qdisc", "add", "dev", "lo", "root", "tbf", "rate", "10mbit",
                     "burst", "32kbit", "latency", "50ms", check=False)  # fmt: skip
        if shaped.returncode != 0:
            return f"tc cannot shape the namespace's loopback ({shaped.stderr.strip()})"
    finally:
        _ip("netns", "del", name, check=False)
    return None


class Namespace:
    """A private network namespace whose loopback is held to `mbit` Mbit/s."""

    def __init__(self, mbit: float) -> None:
        self.name = f"airtable-net-{os.getpid()}-{int(mbit * 1000)}"
        self.mbit = mbit

    def __enter__(self) -> Namespace:
        _ip("netns", "add", self.name)
        try:
            _ip("-n", self.name, "link", "set", "lo", "up")
            self.run("tc", "qdisc", "add", "dev", "lo", "root", "tbf", "rate", f"{self.mbit:g}mbit",
                     "burst", "32kbit", "latency", "50ms")  # fmt: skip
        except BaseException:
            self.__exit__()
            raise
        return self

    def __exit__(self, *exc) -> None:
        _ip("netns", "del", self.name, check=False)

    def command(self, *args: str) -> list[str]:
        return ["ip", "netns", "exec", self.name, *args]

    def run(self, *args: str, timeout_s: float = 20.0) -> subprocess.CompletedProcess:
        return subprocess.run(
            self.command(*args), capture_output=True, text=True, timeout=timeout_s, check=True, cwd=ROOT
        )


@dataclass
class Rates:
    """What the students got on one link."""

    mbit: float
    rates: list[float]
    mean_bytes: float
    mbit_used: float
    server_fps: float

    @property
    def median(self) -> float:
        return statistics.median(self.rates) if self.rates else 0.0

    def line(self) -> str:
        r = sorted(self.rates)
        if not r:
            return f"{self.mbit:5g} Mbit/s: no student got any snapshot"
        return (
            f"{self.mbit:5g} Mbit/s: {len(r)} students, snapshots/s min {r[0]:.1f}, median {self.median:.1f}, "
            f"max {r[-1]:.1f}; {self.mean_bytes:.0f} B per snapshot, {self.mbit_used:.2f} Mbit/s used, "
            f"server {self.server_fps:.0f} fps"
        )


def _wait_ready(proc: subprocess.Popen, timeout_s: float) -> None:
    """Wait (bounded) for the server's first 'join with:' line: it is listening."""
    sel = selectors.DefaultSelector()
    sel.register(proc.stdout, selectors.EVENT_READ)
    deadline = time.monotonic() + timeout_s
    try:
        while (left := deadline - time.monotonic()) > 0:
            if not sel.select(left):
                break
            line = proc.stdout.readline()
            if not line:
                break
            if line.startswith("join with: "):
                return
    finally:
        sel.close()
    raise RuntimeError("the table server in the namespace did not start")


def measure_rates(mbit: float, clients: int = 30, seconds: float = 5.0, demo: str = "4") -> Rates:
    """Run a demo table and `clients` players in a namespace held to `mbit` Mbit/s."""
    py = sys.executable
    with Namespace(mbit) as ns:
        table = ("--serve", "--host", "127.0.0.1", "--port", str(PORT), "--demo", demo, "--seconds", str(seconds + 60))
        server = subprocess.Popen(
            ns.command(py, "-m", "tools.loadtest", *table),
            cwd=ROOT,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        try:
            _wait_ready(server, START_TIMEOUT_S)
            args = ("measure", "--clients", str(clients), "--seconds", str(seconds))
            done = ns.run(py, "-m", "tools.fairness", *args, timeout_s=seconds + 90)
        finally:
            stop_process(server)
            server.stdout.close()
    result = json.loads(done.stdout.strip().splitlines()[-1])
    return Rates(mbit, result["rates"], result["mean_bytes"], result["mbit"], result["fps"])


# ---------------------------------------------------------------- the players inside the namespace


def measure(clients: int, seconds: float) -> int:
    """Players from the load tool; prints one JSON line with each one's rate."""
    from tools.loadtest import run_load

    result = run_load("127.0.0.1", PORT, clients=clients, seconds=seconds, baseline_s=0.0)  # no baseline read
    fps = statistics.median(result.loaded_fps) if result.loaded_fps else 0.0
    print(
        json.dumps(
            {
                "rates": result.snapshot_rates,
                "mean_bytes": result.mean_snapshot_bytes,
                "mbit": result.mbit_per_s,
                "fps": fps,
                "errors": result.errors[:5],
            }
        )
    )
    return 0


def bench(mbits: Sequence[float] = BENCH_MBIT, clients: int = 30, seconds: float = 5.0) -> list[Rates]:
    """Print per-student rates at each link rate (the `make bench` section); [] where not possible."""
    why = available()
    if why:
        print(f"fairness: skipped: {why}")
        return []
    print(f"fairness: {clients} students on demo 4, loopback held to each rate with a tc token bucket")
    results = []
    for mbit in mbits:
        rates = measure_rates(mbit, clients, seconds)
        print(rates.line(), flush=True)
        results.append(rates)
    return results


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tools.fairness", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command")
    m = sub.add_parser("measure")
    m.add_argument("--clients", type=int, default=30)
    m.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--mbit", type=float, nargs="+", default=list(BENCH_MBIT))
    parser.add_argument("--clients", type=int, default=30)
    parser.add_argument("--seconds", type=float, default=5.0)
    args = parser.parse_args(argv)
    if args.command == "measure":
        return measure(args.clients, args.seconds)
    bench(args.mbit, args.clients, args.seconds)
    return 0


if __name__ == "__main__":
    sys.exit(main())
