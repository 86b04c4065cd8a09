"""The network sections of `make bench`: snapshot bytes and per-student rates on a held link."""

from __future__ import annotations

import argparse

from bench import snapshots
from tools import fairness


def snapshot_section(args: argparse.Namespace) -> bool:
    """Mean SNAPSHOT bytes of format 2 on the four scenes of the targets; True if all are within them."""
    print("\n== snapshots (format 2) ==")
    results = snapshots.snapshot_sizes(quick=args.quick)
    print(snapshots.report(results))
    return all(m.mean_b <= snapshots.TARGETS_B.get(m.name, float("inf")) for m in results)


def link_section(args: argparse.Namespace) -> bool:
    """Per-student snapshot rates with the loopback held to 5, 10 and 20 Mbit/s (skipped where not allowed)."""
    print("\n== a classroom link (30 students on demo 4) ==")
    results = fairness.bench(seconds=3.0 if args.quick else 5.0)
    return all(min(r.rates, default=0.0) >= 25.0 for r in results if r.mbit >= 10.0)
