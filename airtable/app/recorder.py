"""Record and export, for lab reports: the table's recent history written as two CSV files (no pygame).

`Recorder.sample(table)` is called after every physics step (and once when a
demo starts), so the samples are `dt` apart in simulated time, whatever the
frame rate or slow motion. Each sample keeps every puck's mass, radius,
position and velocity and the energy chart's series (kinetic, spring,
gravity and total energy, and the momentum's two components). Memory is
bounded by bytes, not seconds: the oldest samples go first, so a few pucks
keep minutes and ten thousand keep a few dozen steps.

`Recorder.write(path)` writes `NAME.csv` (one row per puck per sample) and
`NAME_energy.csv` (one row per sample). Floats are written as Python's repr,
the shortest text that reads back as the very same number, so sums
recomputed from the puck file match the energy file to round-off.
"""

from __future__ import annotations

import os
from collections import deque
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from airtable.physics.table import AirTable

PUCK_COLUMNS = ("t_s", "puck", "mass_kg", "radius_m", "x_m", "y_m", "vx_mps", "vy_mps")
ENERGY_COLUMNS = ("t_s", "kinetic_J", "spring_J", "gravity_J", "total_J", "px_Ns", "py_Ns")
DEFAULT_BUDGET_BYTES = 32 * 2**20  # 32 MB: 3.6 minutes of five pucks at 240 steps a second
# A sample's Python objects beside its array's data (the Sample, its tuple of six floats, the
# array's header), as tracemalloc measures them: counted against the budget too.
SAMPLE_OVERHEAD_BYTES = 400
ENERGY_SUFFIX = "_energy"


@dataclass(frozen=True, slots=True)
class Sample:
    """The table at one moment: `pucks` is (N, 6) of mass, radius, x, y, vx, vy; `energy` follows ENERGY_COLUMNS[1:]."""

    t_s: float
    pucks: np.ndarray
    energy: tuple[float, float, float, float, float, float]

    @property
    def nbytes(self) -> int:
        return self.pucks.nbytes + SAMPLE_OVERHEAD_BYTES


def sample_of(table: AirTable, out: np.ndarray | None = None) -> Sample:
    """Copy what a recording keeps out of `table` (into `out`, an old sample's (N, 6) array, if given)."""
    ke, se, ge = table.kinetic_energy_J(), table.spring_energy_J(), table.gravity_energy_J()
    p = table.momentum_Ns()
    n = len(table.pos_m)
    pucks = out if out is not None and out.shape == (n, 6) else np.empty((n, 6))
    pucks[:, 0], pucks[:, 1], pucks[:, 2:4], pucks[:, 4:6] = table.mass_kg, table.radius_m, table.pos_m, table.vel_mps
    return Sample(float(table.time_s), pucks, (ke, se, ge, ke + se + ge, float(p[0]), float(p[1])))


class Recorder:
    """The latest samples of the table, at most `budget_bytes` of them (the oldest are dropped first)."""

    def __init__(self, budget_bytes: int = DEFAULT_BUDGET_BYTES) -> None:
        self.budget_bytes = int(budget_bytes)
        self.samples: deque[Sample] = deque()
        self.nbytes = 0
        self.dropped = 0  # samples dropped to stay in budget since the last clear

    def clear(self) -> None:
        self.samples.clear()
        self.nbytes = 0
        self.dropped = 0

    def __len__(self) -> int:
        return len(self.samples)

    def sample(self, table: AirTable) -> None:
        """Keep the table as it is now, dropping the oldest samples to stay in budget (the newest always stays).

        A dropped sample's array is reused for the new one: a full recording allocates nothing."""
        n = len(table.pos_m)
        size = n * 6 * 8 + SAMPLE_OVERHEAD_BYTES
        spare = None
        while self.samples and self.nbytes + size > self.budget_bytes:
            old = self.samples.popleft()
            self.nbytes -= old.nbytes
            self.dropped += 1
            spare = old.pucks if len(old.pucks) == n else spare
        s = sample_of(table, spare)
        self.samples.append(s)
        self.nbytes += s.nbytes

    def drop_after(self, t_s: float) -> int:
        """Forget the samples later than `t_s` (the table was rewound to it and runs on); returns how many."""
        gone = 0
        while self.samples and self.samples[-1].t_s > t_s:
            self.nbytes -= self.samples.pop().nbytes
            gone += 1
        return gone

    @property
    def span_s(self) -> float:
        """Simulated time from the oldest sample kept to the newest."""
        return self.samples[-1].t_s - self.samples[0].t_s if self.samples else 0.0

    def write(self, path: str | os.PathLike) -> tuple[Path, Path]:
        """Write NAME.csv and NAME_energy.csv for `path` (NAME.csv); returns both paths. OSError if it cannot."""
        puck_path, energy_path = csv_pair(path)
        with open(puck_path, "w", encoding="utf-8", newline="") as f:
            f.write(",".join(PUCK_COLUMNS) + "\n")
            for s in self.samples:
                t = repr(s.t_s)
                f.writelines(f"{t},{k},{','.join(map(repr, row))}\n" for k, row in enumerate(s.pucks.tolist()))
        with open(energy_path, "w", encoding="utf-8", newline="") as f:
            f.write(",".join(ENERGY_COLUMNS) + "\n")
            f.writelines(f"{s.t_s!r},{','.join(map(repr, s.energy))}\n" for s in self.samples)
        return puck_path, energy_path

    def summary(self) -> str:
        """'3.00 s (721 steps)', and how much was dropped, for the message line."""
        n = len(self.samples)
        text = f"{self.span_s:.2f} s ({n} step{'' if n == 1 else 's'})"
        return text + (", the oldest dropped to stay in memory" if self.dropped else "")


def csv_pair(path: str | os.PathLike) -> tuple[Path, Path]:
    """NAME.csv and NAME_energy.csv for `path` (".csv" added if its name lacks it)."""
    path = Path(path)
    if path.suffix.lower() != ".csv":
        path = path.with_name(path.name + ".csv")
    return path, path.with_name(path.stem + ENERGY_SUFFIX + path.suffix)


def check_record_path(text: str) -> Path:
    """Where `--record` writes (NAME.csv; NAME_energy.csv beside it); ValueError with a sentence if it cannot."""
    if Path(text).is_dir():
        raise ValueError(f"--record {text}: that is a folder; give a file name like run.csv")
    pair = csv_pair(text)
    folder = pair[0].parent
    if not folder.is_dir():
        raise ValueError(f"--record {pair[0]}: there is no folder {folder}")
    for p in pair:
        if p.is_dir() or not os.access(folder, os.W_OK) or (p.exists() and not os.access(p, os.W_OK)):
            raise ValueError(f"--record {pair[0]}: cannot write {p}; choose a file in a folder you may write to")
    return pair[0]


def free_csv_pair(folder: Path, stem: str) -> Path:
    """`folder/stem.csv`, or `stem-2.csv`, ...: the first whose pair of files are both new."""
    n = 1
    while True:
        path = folder / (f"{stem}.csv" if n == 1 else f"{stem}-{n}.csv")
        if not any(p.exists() for p in csv_pair(path)):
            return path
        n += 1
