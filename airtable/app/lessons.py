"""The lesson tools of the teacher's app: record and export, save the moment, momenta, changing the world live.

`Lessons` holds their state beside the App (`app.lessons`); the app calls
`start(table)` when a demo starts and `after_step(table)` after every physics
step. The actions below are functions of the app alone, `action(app)`, bound
to keys in controls.py.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING

from airtable.app.demo_loader import BUILTIN_DIR
from airtable.app.overlays import OverlayFlag, Overlays
from airtable.app.recorder import DEFAULT_BUDGET_BYTES, Recorder, free_csv_pair
from airtable.app.saved_demo import demo_source, free_key, save_folder, write_demo
from airtable.model.momenta import MomentaLog
from airtable.physics.table import AirTable

if TYPE_CHECKING:
    from airtable.app.app import App

RECORDINGS_DIR = Path("recordings")  # where the export key writes, created on demand


class Lessons:
    """The state of the lesson tools: the recording, the latest collision's momenta, which panels show."""

    show_momenta = OverlayFlag("momenta")  # the momenta diagram (d)
    show_values = OverlayFlag("values")  # the values panel (t)

    def __init__(self, budget_bytes: int = DEFAULT_BUDGET_BYTES, overlays: Overlays | None = None) -> None:
        self.overlays = Overlays() if overlays is None else overlays  # the app's, where its panels live
        self.recorder = Recorder(budget_bytes)
        self.exported_to_s = -1.0  # the recording's time up to which it was exported
        self.momenta = MomentaLog()
        self.painter = None  # the LessonsPainter, made on the first draw (lessons_view.py)

    def start(self, table: AirTable) -> None:
        """A demo (re)started: a new recording from its first moment, no collision seen yet."""
        self.recorder.clear()
        self.recorder.sample(table)
        self.exported_to_s = table.time_s
        self.momenta.clear()
        if self.painter is not None:
            self.painter.new_demo()

    def drop_after(self, t_s: float) -> None:
        """The table was rewound to `t_s` and runs on: what the recording and the diagram saw later did not happen."""
        self.recorder.drop_after(t_s)
        if self.momenta.latest is not None and self.momenta.latest.t_s > t_s:
            self.momenta.clear()

    def unexported_s(self) -> float:
        """Seconds of the recording that quitting now would lose (not exported with x)."""
        samples = self.recorder.samples
        if not samples:
            return 0.0
        return max(0.0, samples[-1].t_s - max(samples[0].t_s, self.exported_to_s))

    def after_step(self, table: AirTable) -> None:
        self.recorder.sample(table)
        if self.show_momenta:  # only then: most steps nobody asks what the collisions did
            self.momenta.observe(table)


def toggle_momenta(app: App) -> None:
    app.lessons.show_momenta = not app.lessons.show_momenta


def toggle_values(app: App) -> None:
    app.lessons.show_values = not app.lessons.show_values


def export_recording(app: App) -> None:
    """Write the recording so far to recordings/demo<key>-<time>.csv (and _energy.csv); say where."""
    stem = f"demo{app.demo_key}-{time.strftime('%Y%m%d-%H%M%S')}"
    try:
        RECORDINGS_DIR.mkdir(parents=True, exist_ok=True)
        pucks, energy = app.lessons.recorder.write(free_csv_pair(RECORDINGS_DIR, stem))
    except OSError as exc:
        app.say(f"could not write the recording: {exc}")
        return
    app.lessons.exported_to_s = app.table.time_s
    app.say(f"recorded {app.lessons.recorder.summary()} to {pucks.resolve()} and {energy.name}")


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
    app.say(f"saved as demo {key} in {target.resolve()} ({how})")
    return target
