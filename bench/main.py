"""The sections of `python -m bench` and its command line.

Sections are listed in `SECTIONS`; a new one is a function that takes the
parsed arguments, prints its own report and returns True when every target
it checks is met, registered there. `--only` picks sections by name.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable, Sequence

from airtable.memory import keep_freed_memory
from bench.classroom_link import classroom_section
from bench.cpu import cpu_section
from bench.frames import window_section
from bench.hard import hard_section
from bench.instructions import instructions_section
from bench.net_sections import link_section, snapshot_section
from bench.physics import frames_section, physics_section

SECTIONS: dict[str, Callable[[argparse.Namespace], bool]] = {
    "physics": physics_section,
    "frames": frames_section,
    "cpu": cpu_section,
    "window": window_section,
    "snapshots": snapshot_section,
    "link": link_section,
    "classroom": classroom_section,
    "hard": hard_section,
    "instructions": instructions_section,
}


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m bench",
        description="Time the physics step on a gas of pucks, beside pymunk when it is installed.",
    )
    parser.add_argument("--quick", action="store_true", help="smaller counts and fewer steps (a few seconds)")
    parser.add_argument(
        "--only",
        action="append",
        choices=sorted(SECTIONS),
        metavar="SECTION",
        help=f"run only this section (repeatable; one of: {', '.join(SECTIONS)})",
    )
    parser.add_argument("--no-pymunk", action="store_true", help="skip the pymunk comparison")
    parser.add_argument("--seed", type=int, default=0, help="random seed of the scenes (default 0)")
    args = parser.parse_args(argv)
    keep_freed_memory()  # as the app does (cli.main): a 10000-puck step is 35 % slower without
    t0 = time.perf_counter()
    ok = True
    for name in args.only or list(SECTIONS):
        ok = SECTIONS[name](args) and ok
    print(f"{'all targets met' if ok else 'some targets missed'} ({time.perf_counter() - t0:.0f} s)")
    return 0  # a missed target is a finding, not a failure of the bench
