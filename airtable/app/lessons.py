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

from airtable.app.recorder import DEFAULT_BUDGET_BYTES, Recorder, free_csv_pair
from airtable.physics.table import AirTable

if TYPE_CHECKING:
    from airtable.app.app import App

RECORDINGS_DIR = Path("recordings")  # where the export key writes, created on demand


class Lessons:
    """The state of the lesson tools: the recording, and which of their panels show."""

    def __init__(self, budget_bytes: int = DEFAULT_BUDGET_BYTES) -> None:
        self.recorder = Recorder(budget_bytes)

    def start(self, table: AirTable) -> None:
        """A demo (re)started: a new recording from its first moment."""
        self.recorder.clear()
        self.recorder.sample(table)

    def after_step(self, table: AirTable) -> None:
        self.recorder.sample(table)


def export_recording(app: App) -> None:
    """Write the recording so far to recordings/demo<key>-<time>.csv (and _energy.csv); say where."""
    stem = f"demo{app.demo_key}-{time.strftime('%Y%m%d-%H%M%S')}"
    try:
        RECORDINGS_DIR.mkdir(parents=True, exist_ok=True)
        pucks, energy = app.lessons.recorder.write(free_csv_pair(RECORDINGS_DIR, stem))
    except OSError as exc:
        app.say(f"could not write the recording: {exc}")
        return
    app.say(f"recorded {app.lessons.recorder.summary()} to {pucks.resolve()} and {energy.name}")
