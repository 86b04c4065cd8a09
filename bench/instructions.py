"""The "instructions" section of `make bench`: how many instructions a gas step costs.

Timings on a shared machine move by a fifth from one block of steps to the
next, too much to see a change of a few per cent. A count of instructions does
not move: valgrind's callgrind counts the same total for the same run every
time. This section steps the benchmark's gas (the gas demo's gas_scene) inside a call to
`functools.reduce`, and callgrind counts only what runs inside that C function
(`--toggle-collect`), so neither start-up nor the scene's set-up counts.
Instructions are not seconds (a cache miss costs more than an addition), but
at these sizes the step's time follows them closely.

Needs valgrind (`apt install valgrind`) and a Python whose library keeps its
symbols (pyenv's and python.org's do); otherwise it says so and skips. Run
alone with `python -m bench --only instructions`; `--quick` counts
N=1000 only.
"""

from __future__ import annotations

import argparse
import functools
import os
import re
import shutil
import subprocess
import sys

from bench import ROOT

COUNTS = (1000, 10000)
# Enough steps for some twenty and ten builds of the neighbour list (one every 3.8 and 3.1 steps).
STEPS = {1000: 76, 10000: 31}
WARM_UP_STEPS = 20
DT_S = 1.0 / 120.0
COLLECTED = re.compile(r"Collected : (\d+)")


def instructions_per_step(n: int, steps: int) -> int | None:
    """Instructions per step of the n-puck gas under callgrind; None if valgrind could not count them."""
    cmd = [
        "valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null",
        "--collect-atstart=no", "--toggle-collect=functools_reduce",
        sys.executable, "-m", "bench.instructions", str(n), str(steps),
    ]  # fmt: skip
    env = dict(os.environ, PYTHONHASHSEED="0")  # the same dict layouts, the same count every run
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=900, cwd=ROOT)
    found = COLLECTED.search(done.stderr)
    if done.returncode != 0 or found is None or int(found.group(1)) == 0:
        return None
    return int(found.group(1)) // steps


def instructions_section(args: argparse.Namespace) -> bool:
    """Print instructions per gas step; always True (a count has no target, it is for comparing changes)."""
    print("instructions: per step of the physics section's gas, counted by valgrind's callgrind (same count every run)")
    if shutil.which("valgrind") is None:
        print("  skipped: needs valgrind (apt install valgrind)\n")
        return True
    for n in COUNTS[:1] if args.quick else COUNTS:
        count = instructions_per_step(n, STEPS[n])
        if count is None:
            print("  skipped: callgrind counted nothing (this Python has no symbol for functools_reduce)\n")
            return True
        print(f"  N={n:>6}: {count / 1e6:.3f} M instructions a step (mean of {STEPS[n]} steps)")
    print()
    return True


def _step_inside_reduce(n: int, steps: int) -> None:
    """The child process: the gas, warmed up, then `steps` steps inside functools.reduce."""
    from airtable.demos.demo_0p_gas import gas_scene

    from airtable.memory import keep_freed_memory

    keep_freed_memory()  # as the app and the bench run
    table = gas_scene(n)
    for _ in range(WARM_UP_STEPS):
        table.step(DT_S)
    functools.reduce(lambda _, __: table.step(DT_S), range(steps), None)


if __name__ == "__main__":
    _step_inside_reduce(int(sys.argv[1]), int(sys.argv[2]))
