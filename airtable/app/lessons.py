"""The lesson tools of the teacher's app (`Lessons`): record and export, save the moment, the momenta
diagram, the values panel and the puck numbers.
"""

from __future__ import annotations

import shutil
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

import pygame

from airtable.app.demo_loader import BUILTIN_DIR
from airtable.app.feature import Binding, Feature
from airtable.app.lessons_paint import LessonsPainter, values_hint
from airtable.app.overlays import OverlayFlag
from airtable.app.pucks_view import draw_numbers
from airtable.app.recorder import Recorder, csv_pair, free_csv_pair
from airtable.app.saved_demo import demo_source, free_key, save_folder, write_demo
from airtable.model.momenta import FEW_PUCKS, MomentaLog, MomentaView, values_for
from airtable.physics.table import AirTable

if TYPE_CHECKING:
    from airtable.app.host import Host
    from airtable.app.teaching_aids import Aids

RECORDINGS_DIR = Path("recordings")  # where the export key writes, created on demand
# The recording kept for x formats every puck's row every step (about 2 us a row): a table bigger than
# this is not recorded for x, so that a crowd of pucks keeps its frame rate; --record records any table.
SPOOL_MAX_PUCKS = 200
# ... and it stops at this size on disk (demo 4 in motion writes about 100 MB a minute).
SPOOL_MAX_BYTES = 4 * 2**30
# A demo left (another started, or it restarted) with at least this much recording not exported keeps
# it until x exports it with the demo on the table (a user test lost 20 s of demo 7 by pressing 2); at
# most this many such recordings, the oldest going first.
KEEP_UNEXPORTED_S = 2.0
MAX_KEPT = 20


class Lessons(Feature):
    """The lesson tools (`app.lessons`): the recording, the latest collision's momenta, which panels show.

    Every demo start begins a recording streamed to disk (recorder.py): by default a
    spool file in a folder of its own that goes when the app ends, which the export
    key (x) copies, so x gives the demo from its start and a later x the later part
    too; with `--record FILE.csv` (`record_into`) the recording is the file itself, and
    a demo started later records to FILE-2.csv, FILE-3.csv, ... A demo left before x
    exported its recording keeps it (`kept`): the next x exports those too.
    """

    show_momenta = OverlayFlag("momenta")  # the momenta diagram (d)
    show_values = OverlayFlag("values")  # the values panel (t)

    draw_order = 1  # before the aids: their labels then place themselves around its panels

    def __init__(self, host: Host, aids: Aids) -> None:
        super().__init__(host)
        self.aids = aids  # the chart keeps its corner; the values panel shares its energy scale
        self._spool = tempfile.TemporaryDirectory(prefix="airtable-recording-")  # removed when the app ends
        self.record_to: Path | None = None  # --record's NAME.csv: recordings are kept there
        self.recorded: list[Recorder] = []  # the --record recordings of this run, the current one last
        self.recorder: Recorder | None = None
        self.recording_key = ""  # the demo the recording is of
        self.kept: list[tuple[str, Recorder, float]] = []  # demos left unexported: (key, recording, seconds)
        self.exported_to_s = -1.0  # the recording's time up to which it was exported
        self.show_numbers = False  # each puck's number drawn on it (k); kept from demo to demo
        self.momenta = MomentaLog()
        self._hits_seen = 0  # the table's collision count when last looked at
        self.painter: LessonsPainter | None = None  # made on the first draw

    def on_demo_start(self, table: AirTable) -> None:
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
        if self.recorder is not None and self.recorder not in self.recorded:  # (before any step, as --record)
            self.recorder.close()
            self._drop(self.recorder)
            self.recorder = None
        self._begin_recording(table)

    def _begin_recording(self, table: AirTable) -> None:
        if self.recorder is not None:
            self.recorder.close()
            if self.recorder not in self.recorded:  # a spool: kept only if x has not exported it
                self._keep_or_drop(self.recording_key, self.recorder, self._unexported(self.recorder))
        self.recording_key = self.host.demo_key
        if self.record_to is None:
            self.recorder = Recorder(free_csv_pair(Path(self._spool.name), "demo"))
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
                rec.stop(f"{too}: --record FILE.csv records every puck")
        rec.sample(table)

    def finish(self) -> list[Recorder]:
        """The run ends: close the recording; returns the --record recordings (the spool goes with the app)."""
        if self.recorder is not None:
            self.recorder.close()
        return list(self.recorded)

    def momenta_shown(self, table: AirTable) -> MomentaView | None:
        """The latest collision's momenta, unless the table is rewound to before it (a user test: rewound to
        t = 0.45 s, the diagram showed the collision at t = 0.67 s, still to come on screen)."""
        latest = self.momenta.latest
        return None if latest is None or latest.t_s > table.time_s else latest.view

    def forget_after(self, t_s: float) -> None:
        """The table was rewound to `t_s` and runs on: what the recording and the diagram saw later did not happen."""
        self.recorder.drop_after(t_s)
        if self.momenta.latest is not None and self.momenta.latest.t_s > t_s:
            self.momenta.clear()

    def _keep_or_drop(self, key: str, rec: Recorder, unexported_s: float) -> None:
        """A spool recording whose demo was left: kept for x if it holds KEEP_UNEXPORTED_S not exported."""
        if unexported_s >= KEEP_UNEXPORTED_S:
            self.kept.append((key, rec, unexported_s))
            if len(self.kept) <= MAX_KEPT:
                return
            key, rec, unexported_s = self.kept.pop(0)
            self.host.say(f"demo {key}'s recording dropped ({unexported_s:.0f} s): x exports the {MAX_KEPT} kept")
        self._drop(rec)

    @staticmethod
    def _drop(rec: Recorder) -> None:
        """A spool recording's files, gone."""
        for p in (rec.puck_path, rec.energy_path):
            p.unlink(missing_ok=True)

    def _unexported(self, rec: Recorder | None) -> float:
        """Seconds of the demo's recording since the last export (x); none with --record (all in its file)."""
        if rec is None or rec in self.recorded or rec.newest_s is None:
            return 0.0
        return max(0.0, rec.newest_s - max(rec.first_s, self.exported_to_s))

    def unexported_s(self) -> float:
        """Seconds of recording that quitting now would lose: the demo's since the last export, and the
        demos' left before x exported them."""
        return self._unexported(self.recorder) + sum(s for _, _, s in self.kept)

    def after_step(self, table: AirTable) -> None:
        self._sample(table)
        if table.collision_count != self._hits_seen:  # the momenta of the latest collision, shown or not
            self._hits_seen = table.collision_count
            self.momenta.observe(table)

    def toggle_momenta(self) -> None:
        self.show_momenta = not self.show_momenta

    def toggle_values(self) -> None:
        self.show_values = not self.show_values

    def toggle_numbers(self) -> None:
        self.show_numbers = not self.show_numbers
        shown = "puck numbers shown, as values, predict and the CSV name them"
        self.host.say(shown if self.show_numbers else "puck numbers hidden")

    def export_recording(self) -> None:
        """Copy the demo's recording so far to recordings/demo<key>-<time>.csv (and _energy.csv), and those
        of demos left before x exported them; say where."""
        earlier = []
        while self.kept:
            key, rec, _ = self.kept[0]
            pucks = self._copy_out(rec, key)
            if pucks is None:
                return  # (said why; the rest stay kept)
            earlier.append(pucks)
            self.kept.pop(0)
            self._drop(rec)
        self._export_current()
        if earlier:
            print(f"recorded {len(earlier)} earlier demos' runs to {earlier[0].parent.resolve()}", flush=True)
            self.host.say(f"{self.host.message} (and {len(earlier)} earlier demos' runs)", lasting=True)

    def _copy_out(self, rec: Recorder, key: str) -> Path | None:
        """Copy `rec`'s pair of files to recordings/demo<key>-<time>.csv; the puck file's path (None: said why)."""
        stem = f"demo{key}-{time.strftime('%Y%m%d-%H%M%S')}"
        try:
            RECORDINGS_DIR.mkdir(parents=True, exist_ok=True)
            rec.flush()
            pucks, energy = csv_pair(free_csv_pair(RECORDINGS_DIR, stem))
            shutil.copyfile(rec.puck_path, pucks)
            shutil.copyfile(rec.energy_path, energy)
        except OSError as exc:
            self.host.say(f"could not write the recording: {exc.strerror or exc}")
            print(f"airtable: could not write the recording: {exc}", file=sys.stderr)
            return None
        return pucks

    def _export_current(self) -> None:
        rec, say = self.recorder, self.host.say
        if rec.samples == 0:  # no file of headers only: say why there is nothing, and how to get it
            why = f" ({rec.error})" if rec.error else ""
            say(f"nothing recorded yet{why}", lasting=True)
            print(f"airtable: nothing to export: no step was recorded{why}", file=sys.stderr)
            return
        pucks = self._copy_out(rec, self.host.demo_key)
        if pucks is None:
            return
        energy = csv_pair(pucks)[1]
        self.exported_to_s = self.host.table.time_s
        stopped = f"; it stopped: {rec.error}" if rec.error else ""
        print(f"recorded {rec.summary()} to {pucks.resolve()} and {energy.name}{stopped}", flush=True)
        if rec.error:  # why first: a long message is cut at the window's edge
            say(f"the recording stopped ({rec.error}): {rec.span_s:.2f} s to {short_path(pucks)}", lasting=True)
        else:
            say(f"recorded {rec.span_s:.2f} s to {short_path(pucks)} (and _energy.csv)", lasting=True)

    def save_moment(self, path: Path | None = None) -> Path | None:
        """Write the table as it is now as a new demo file, under a new key; say where (None if it could not).

        Without `path` it goes to the teacher's demo folder (save_folder), which the
        app then loads from, so the new key works at once and `--list-demos` lists it.
        """
        host = self.host
        shelf = host.shelf
        folder = save_folder(shelf.directories, BUILTIN_DIR) if path is None else Path(path).parent
        key = free_key(host.demos, folder)
        target = Path(path) if path is not None else folder / f"{key}.py"
        title = f"{host.demo.title}, saved at t = {host.table.time_s:.2f} s"
        source = demo_source(
            host.table, key=key, title=title, dt_s=host.dt_s, origin=f"from {host.demo.label(host.variation)}"
        )
        try:
            write_demo(target, source)
        except OSError as exc:
            host.say(f"could not save the demo: {exc}")
            return None
        if path is None:
            if all(Path(d).resolve() != folder.resolve() for d in shelf.directories):
                shelf.directories.append(folder)
            for error in shelf.refresh():
                host.report(error)
        how = f"Tab, then {key}, starts it" if path is None else f"load it with --demos {target.parent}"
        host.say(f"saved as demo {key} in {target.resolve()} ({how})", lasting=True)
        return target

    def draw(self) -> None:
        """The puck numbers (k), then the momenta diagram (d) and the values panel (t) in free corners."""
        t, env, window = self.host.table, self.host.env, self.host.window
        if self.show_numbers and len(t.pos_m):
            draw_numbers(window.surface, window.label_font, env.to_screen(t.pos_m))
        if not (self.show_momenta or self.show_values):
            return
        if self.painter is None:
            self.painter = LessonsPainter(window)
        paint = self.painter
        points = env.to_screen(t.pos_m) if len(t.pos_m) else t.pos_m
        chart = self.aids.chart_corner(points)  # the chart keeps its corner; the panels take others
        taken = [] if chart is None else [chart]
        if self.show_momenta:
            corner = paint.choose_corner("momenta", points, taken)
            taken.append(corner)
            paint.momenta_diagram(self.momenta_shown(t), corner)
        if self.show_values:
            puck = t.puck_at(env.to_world(self.host.mouse_px)) if len(t.pos_m) > FEW_PUCKS else None
            rows = values_for(t, None if puck is None else puck.index, self.aids.chart.scale)
            colors = [t.color_rgb[r.row] if r.row is not None else None for r in rows]
            paint.values_panel(rows, colors, values_hint(len(t.pos_m)), paint.choose_corner("values", points, taken))

    bindings = (
        Binding(
            "d / t / k",
            "momenta before / after the latest collision; values of each puck; puck numbers",
            {pygame.K_d: toggle_momenta, pygame.K_t: toggle_values, pygame.K_k: toggle_numbers},
        ),
        Binding(
            "x / Ctrl+S",
            "export the recording as CSV; save the moment as a new demo (s1, s2, ...)",
            {pygame.K_x: export_recording, (pygame.KMOD_CTRL, pygame.K_s): save_moment},
        ),
    )


def short_path(path: Path) -> str:
    """`path` relative to the working folder when it is inside it (short enough for the message line)."""
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path.resolve())
