"""Record and export, for lab reports: the table's run streamed to two CSV files as it goes (no pygame).

`Recorder(path)` opens `NAME.csv` (one row per puck per sample) and
`NAME_energy.csv` (one row per sample) and `sample(table)` writes the table
into them; the app calls it after every physics step (and once when a demo
starts), so the samples are `dt` apart in simulated time, whatever the frame
rate or slow motion. Rows wait in a small buffer of at most `BUFFER_ROWS`
rows and go to disk when it fills, so memory stays the same however long the
run: an hour of demo 4 (54 pucks, 240 steps a second) is 47 million rows.

Times are written to the microsecond (`13.279167`): the steps are `dt`
apart, and the sum of steps carries round-off below that. The other floats
are written as Python's repr, the shortest text that reads back as the very
same number, so sums recomputed from the puck file match the energy file to
round-off. Pucks are numbered from 1, as everywhere in the app.

`drop_after(t_s)` forgets what was recorded after `t_s` (the table was
rewound and runs on): the files are cut back, reading them backwards only as
far as the rows it drops.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from airtable.model.momenta import FIRST_PUCK_NUMBER
from airtable.physics.table import AirTable

PUCK_COLUMNS = ("t_s", "puck", "mass_kg", "radius_m", "x_m", "y_m", "vx_mps", "vy_mps")
ENERGY_COLUMNS = ("t_s", "kinetic_J", "spring_J", "gravity_J", "total_J", "px_Ns", "py_Ns")
ENERGY_SUFFIX = "_energy"
BUFFER_ROWS = 8192  # rows (of either file) held before they are written: about 1 MB of text
TIME_FORMAT = "{:.6f}"  # to the microsecond
# A row written at t_s reads back within half a microsecond of it.
TIME_SLACK_S = 1e-6
READ_BACK_BYTES = 1 << 16  # drop_after reads the files backwards in blocks of this size


def energy_row(table: AirTable) -> tuple[float, float, float, float, float, float]:
    """The energy file's numbers for the table now (ENERGY_COLUMNS[1:]): J and N s."""
    ke, se, ge = table.kinetic_energy_J(), table.spring_energy_J(), table.gravity_energy_J()
    p = table.momentum_Ns()
    return ke, se, ge, ke + se + ge, float(p[0]), float(p[1])


class RowText:
    """The puck rows' text after the time, kept from sample to sample: a row is formatted again only where
    its numbers changed (floats' repr is most of a recording's cost; resting and sleeping pucks cost none)."""

    def __init__(self) -> None:
        self.fixed: np.ndarray | None = None  # (N, 2) mass, radius of the texts in `heads`
        self.heads: list[str] = []  # "k,mass,radius," with k from 1
        self.moving: np.ndarray | None = None  # (N, 4) x, y, vx, vy of the texts in `tails`
        self.tails: list[str] = []  # "x,y,vx,vy\n"

    def rows(self, table: AirTable, t: str) -> str:
        """Every puck's row at time text `t`."""
        fixed = np.column_stack((table.mass_kg, table.radius_m))
        if self.fixed is None or not np.array_equal(fixed, self.fixed):
            self.fixed = fixed
            self.heads = [f"{k},{m!r},{r!r}," for k, (m, r) in enumerate(fixed.tolist(), FIRST_PUCK_NUMBER)]
        moving = np.column_stack((table.pos_m, table.vel_mps))
        if self.moving is None or self.moving.shape != moving.shape:
            self.tails = [""] * len(moving)
            changed = np.arange(len(moving))
        else:
            changed = np.flatnonzero(np.any(moving != self.moving, axis=1))
        for k, (x, y, vx, vy) in zip(changed.tolist(), moving[changed].tolist(), strict=True):
            self.tails[k] = f"{x!r},{y!r},{vx!r},{vy!r}\n"
        self.moving = moving
        return "".join([f"{t},{h}{e}" for h, e in zip(self.heads, self.tails, strict=True)])


class Recorder:
    """A recording streamed to a CSV pair; the rows not yet on disk are at most BUFFER_ROWS."""

    def __init__(self, path: str | os.PathLike, buffer_rows: int = BUFFER_ROWS) -> None:
        self.puck_path, self.energy_path = csv_pair(path)
        self.buffer_rows = int(buffer_rows)
        self.error: str | None = None  # why the recording stopped early (the disk refused, say)
        self._files = []
        try:
            for p in (self.puck_path, self.energy_path):
                self._files.append(open(p, "w+b"))  # noqa: SIM115 (kept open while recording)
        except OSError as exc:
            self._fail(exc)
        self._buffers: list[list[bytes]] = [[], []]
        self.buffered_rows = 0  # rows held in memory, not yet written
        self.samples = 0  # samples recorded (one energy row each)
        self.rows = 0  # puck rows recorded
        self.nbytes = 0  # bytes of text recorded, in both files
        self.first_s: float | None = None
        self.newest_s: float | None = None
        self._text = RowText()
        if not self.closed:
            self._write(",".join(PUCK_COLUMNS) + "\n", ",".join(ENERGY_COLUMNS) + "\n", rows=0)

    def __len__(self) -> int:
        return self.samples

    @property
    def closed(self) -> bool:
        return not self._files or self._files[0].closed

    def _fail(self, exc: OSError) -> None:
        """The disk refused (full, removed): say why, keep what was written, record no more."""
        self.stop(exc.strerror or str(exc))

    def stop(self, why: str) -> None:
        """Record no more (`why` says so); what was written stays."""
        self.error = why
        for f in self._files:
            try:
                f.close()
            except OSError:
                pass
        self._files = []
        self._buffers = [[], []]
        self.buffered_rows = 0

    def sample(self, table: AirTable) -> None:
        """Record the table as it is now: one row per puck and one energy row."""
        if self.closed:
            return
        n = len(table.pos_m)
        t = TIME_FORMAT.format(table.time_s)
        pucks = self._text.rows(table, t)
        energy = t + "," + ",".join(map(repr, energy_row(table))) + "\n"
        self._write(pucks, energy, rows=n)
        self.samples += 1
        self.rows += n
        self.first_s = table.time_s if self.first_s is None else self.first_s
        self.newest_s = table.time_s

    def _write(self, pucks: str, energy: str, rows: int) -> None:
        chunks = (pucks.encode(), energy.encode())
        self._buffers[0].append(chunks[0])
        self._buffers[1].append(chunks[1])
        self.nbytes += len(chunks[0]) + len(chunks[1])
        self.buffered_rows += rows + 1
        if self.buffered_rows >= self.buffer_rows:
            self.flush()

    def flush(self) -> None:
        """Write the buffered rows to the files (and the files' own buffers to disk)."""
        if self.closed:
            return
        try:
            for f, buffer in zip(self._files, self._buffers, strict=True):
                f.writelines(buffer)
                buffer.clear()
                f.flush()
        except OSError as exc:
            self._fail(exc)
        self.buffered_rows = 0

    def close(self) -> None:
        self.flush()
        for f in self._files:
            f.close()
        self._files = []

    def drop_after(self, t_s: float) -> int:
        """Forget the samples later than `t_s` (the table was rewound to it and runs on); returns how many."""
        if self.closed or self.newest_s is None or self.newest_s <= t_s:
            return 0
        self.flush()
        limit = t_s + TIME_SLACK_S
        try:
            puck_rows = _cut_after(self._files[0], limit)
            gone = _cut_after(self._files[1], limit)
        except OSError as exc:
            self._fail(exc)
            return 0
        self.samples -= gone
        self.rows -= puck_rows
        self.nbytes = sum(f.tell() for f in self._files)  # each file ends where it was cut
        self.newest_s = None if self.samples == 0 else min(self.newest_s, t_s)
        self.first_s = None if self.samples == 0 else self.first_s
        return gone

    @property
    def span_s(self) -> float:
        """Simulated time from the first sample to the newest."""
        return 0.0 if self.newest_s is None or self.first_s is None else self.newest_s - self.first_s

    def summary(self) -> str:
        """'3.00 s (721 steps)', for the message line."""
        return f"{self.span_s:.2f} s ({self.samples} step{'' if self.samples == 1 else 's'})"


def _cut_after(f, limit_s: float) -> int:
    """Cut the open CSV `f` (binary, flushed) after its last row whose time is at most `limit_s`; returns the
    number of rows cut. Reads backwards from the end, block by block, only as far as the rows it cuts."""
    end = f.seek(0, os.SEEK_END)
    pos, tail, cut = end, b"", 0
    while pos > 0:
        start = max(0, pos - READ_BACK_BYTES)
        f.seek(start)
        block = f.read(pos - start) + tail
        pos = start
        lines = block.split(b"\n")
        tail = lines[0] if pos > 0 else b""  # maybe a part of a line: read with the block before
        for k in range(len(lines) - 1, 0 if pos > 0 else -1, -1):
            line = lines[k]
            if not line:
                continue
            head = line.split(b",", 1)[0]
            if not _is_number(head) or float(head) <= limit_s:  # the header, or a row to keep
                keep = pos + sum(len(x) + 1 for x in lines[: k + 1])
                f.truncate(keep)
                f.seek(keep)
                return cut
            cut += 1
    f.truncate(0)
    f.seek(0)
    return cut


def _is_number(text: bytes) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


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
