"""The lesson tools of the teacher's app: record and export, save the moment, momenta, changing the world live.

`Lessons` holds their state beside the App (`app.lessons`); the app calls
`start(table)` when a demo starts and `after_step(table)` after every physics
step. The actions below are functions of the app alone, `action(app)`, bound
to keys in controls.py.
"""

from __future__ import annotations

import shutil
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

from airtable.app.demo_loader import BUILTIN_DIR
from airtable.app.overlays import OverlayFlag, Overlays
from airtable.app.recorder import Recorder, csv_pair, free_csv_pair
from airtable.app.saved_demo import demo_source, free_key, save_folder, write_demo
from airtable.model.momenta import MomentaLog
from airtable.physics.table import AirTable

if TYPE_CHECKING:
    from airtable.app.app import App

RECORDINGS_DIR = Path("recordings")  # where the export key writes, created on demand
# The recording kept for x formats every puck's row every step (about 2 us a row): a table bigger than
# this is not recorded for x, so that a crowd of pucks keeps its frame rate; --record records any table.
SPOOL_MAX_PUCKS = 200
# ... and it stops at this size on disk (demo 4 in motion writes about 100 MB a minute).
SPOOL_MAX_BYTES = 4 * 2**30


class Lessons:
    """The state of the lesson tools: the recording, the latest collision's momenta, which panels show.

    Every demo start begins a recording streamed to disk (recorder.py): by default a
    spool file in a folder of its own that goes when the app ends, which the export
    key (x) copies, so x gives the demo from its start and a later x the later part
    too; with `--record FILE.csv` (`record_into`) the recording is the file itself, and
    a demo started later records to FILE-2.csv, FILE-3.csv, ...
    """

    show_momenta = OverlayFlag("momenta")  # the momenta diagram (d)
    show_values = OverlayFlag("values")  # the values panel (t)

    def __init__(self, overlays: Overlays | None = None) -> None:
        self.overlays = Overlays() if overlays is None else overlays  # the app's, where its panels live
        self._spool = tempfile.TemporaryDirectory(prefix="airtable-recording-")  # removed when the app ends
        self.record_to: Path | None = None  # --record's NAME.csv: recordings are kept there
        self.recorded: list[Recorder] = []  # the --record recordings of this run, the current one last
        self.recorder: Recorder | None = None
        self.exported_to_s = -1.0  # the recording's time up to which it was exported
        self.show_numbers = False  # each puck's number drawn on it (k); kept from demo to demo
        self.momenta = MomentaLog()
        self._hits_seen = 0  # the table's collision count when last looked at
        self.painter = None  # the LessonsPainter, made on the first draw (lessons_view.py)

    def start(self, table: AirTable) -> None:
        """A demo (re)started: a new recording from its first moment, no collision seen yet."""
        self._begin_recording(table)
        self.exported_to_s = table.time_s
        self.momenta.clear()
        self._hits_seen = table.collision_count
        if self.painter is not None:
            self.painter.new_demo()

    def record_into(self, path: Path, table: AirTable) -> None:
        """Keep the recordings in `path` (--record): the demo on the table records there from now, afresh."""
        self.record_to = Path(path)
        self._begin_recording(table)

    def _begin_recording(self, table: AirTable) -> None:
        if self.recorder is not None:
            self.recorder.close()
            if self.recorder not in self.recorded:
                for p in (self.recorder.puck_path, self.recorder.energy_path):
                    p.unlink(missing_ok=True)  # a spool: the old demo's recording is not kept
        if self.record_to is None:
            self.recorder = Recorder(Path(self._spool.name) / "demo.csv")
        else:
            first = not self.recorded
            path = self.record_to if first else free_csv_pair(self.record_to.parent, self.record_to.stem)
            self.recorder = Recorder(path)
            self.recorded.append(self.recorder)
        self._sample(table)

    def _sample(self, table: AirTable) -> None:
        rec = self.recorder
        if rec not in self.recorded and not rec.closed:
            too = f"over {SPOOL_MAX_PUCKS} pucks" if len(table.pos_m) > SPOOL_MAX_PUCKS else None
            too = f"{SPOOL_MAX_BYTES / 2**30:.3g} GB written" if rec.nbytes > SPOOL_MAX_BYTES else too
            if too is not None:
                rec.flush()
                rec.stop(f"{too}; --record records all")
        rec.sample(table)

    def finish(self) -> list[Recorder]:
        """The run ends: close the recording; returns the --record recordings (the spool goes with the app)."""
        if self.recorder is not None:
            self.recorder.close()
        return list(self.recorded)

    def drop_after(self, t_s: float) -> None:
        """The table was rewound to `t_s` and runs on: what the recording and the diagram saw later did not happen."""
        self.recorder.drop_after(t_s)
        if self.momenta.latest is not None and self.momenta.latest.t_s > t_s:
            self.momenta.clear()

    def unexported_s(self) -> float:
        """Seconds of the recording that quitting now would lose: none with --record (it is all in its file),
        else the demo's recording since the last export (x)."""
        rec = self.recorder
        if rec is None or rec in self.recorded or rec.newest_s is None:
            return 0.0
        return max(0.0, rec.newest_s - max(rec.first_s, self.exported_to_s))

    def after_step(self, table: AirTable) -> None:
        self._sample(table)
        if table.collision_count != self._hits_seen:  # the momenta of the latest collision, shown or not
            self._hits_seen = table.collision_count
            self.momenta.observe(table)


def toggle_momenta(app: App) -> None:
    app.lessons.show_momenta = not app.lessons.show_momenta


def toggle_values(app: App) -> None:
    app.lessons.show_values = not app.lessons.show_values


def toggle_numbers(app: App) -> None:
    app.lessons.show_numbers = not app.lessons.show_numbers
    shown = app.lessons.show_numbers
    app.say("puck numbers shown, as values, predict and the CSV name them" if shown else "puck numbers hidden")


def export_recording(app: App) -> None:
    """Copy the demo's recording so far to recordings/demo<key>-<time>.csv (and _energy.csv); say where."""
    rec = app.lessons.recorder
    stem = f"demo{app.demo_key}-{time.strftime('%Y%m%d-%H%M%S')}"
    try:
        RECORDINGS_DIR.mkdir(parents=True, exist_ok=True)
        rec.flush()
        pucks, energy = csv_pair(free_csv_pair(RECORDINGS_DIR, stem))
        shutil.copyfile(rec.puck_path, pucks)
        shutil.copyfile(rec.energy_path, energy)
    except OSError as exc:
        app.say(f"could not write the recording: {exc.strerror or exc}")
        print(f"airtable: could not write the recording: {exc}", file=sys.stderr)
        return
    app.lessons.exported_to_s = app.table.time_s
    stopped = f"; it stopped: {rec.error}" if rec.error else ""
    print(f"recorded {rec.summary()} to {pucks.resolve()} and {energy.name}{stopped}", flush=True)
    if rec.error:
        app.say(f"recorded {rec.span_s:.2f} s to {short_path(pucks)} (stopped: {rec.error})", lasting=True)
    else:
        app.say(f"recorded {rec.span_s:.2f} s to {short_path(pucks)} (and _energy.csv)", lasting=True)


def short_path(path: Path) -> str:
    """`path` relative to the working folder when it is inside it (short enough for the message line)."""
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path.resolve())


def save_moment(app: App, path: Path | None = None) -> Path | None:
    """Write the table as it is now as a new demo file, under a new key; say where (None if it could not).

    Without `path` it goes to the teacher's demo folder (save_folder), which the
    app then loads from, so the new key works at once and `--list-demos` lists it.
    """
    shelf = app.shelf
    folder = save_folder(shelf.directories, BUILTIN_DIR) if path is None else Path(path).parent
    key = free_key(app.demos, folder)
    target = Path(path) if path is not None else folder / f"{key}.py"
    title = f"{app.demo.title}, saved at t = {app.table.time_s:.2f} s"
    source = demo_source(app.table, key=key, title=title, dt_s=app.dt_s, origin=f"from {app.caption()}")
    try:
        write_demo(target, source)
    except OSError as exc:
        app.say(f"could not save the demo: {exc}")
        return None
    if path is None:
        if all(Path(d).resolve() != folder.resolve() for d in shelf.directories):
            shelf.directories.append(folder)
        for error in shelf.refresh():
            app.report(error)
    how = f"Tab, then {key}, starts it" if path is None else f"load it with --demos {target.parent}"
    app.say(f"saved as demo {key} in {target.resolve()} ({how})", lasting=True)
    return target
