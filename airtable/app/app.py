"""The teacher's app: one table, its clients, a window, and the frame that ties them together.

Each frame (`App.frame`): input (controls.py), the network's joins and inputs,
as many fixed physics steps as the frame's time allows (loop.py), a snapshot
for the students, then drawing. `App.run` repeats frames with an IdlingLoop (loop.py),
as the student's window does.
Demo scenes come from demo files (demo_loader.py), read again when they
change; the panels over the table (help, notes, the demo menu, errors) are
opened and closed here.
"""

from __future__ import annotations

import dataclasses
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pygame

from airtable.app import controls, predict, rewind, room, world
from airtable.app.aids_share import shared_aids
from airtable.app.aids_view import draw_aids
from airtable.app.demo_loader import Demo, DemoError, DemoShelf, error_from_exception, key_label
from airtable.app.environment import Environment
from airtable.app.history import History
from airtable.app.lessons import Lessons
from airtable.app.lessons_view import draw_lessons
from airtable.app.loop import FixedStep, FpsCounter, IdlingLoop, signals_end_the_run
from airtable.app.menu import DemoMenu
from airtable.app.overlays import OverlayFlag, Overlays, OverlayValue
from airtable.app.predict_view import draw_predict
from airtable.app.roster_view import ALERT_COLOR, draw_roster, room_alert
from airtable.app.stats import RunStats
from airtable.app.window import AidsPainter, GameWindow, TimelinePainter
from airtable.model import aids
from airtable.model.client import LOCAL_COLOR, Client, cursor_pulls
from airtable.model.scene import STATUS_SEPARATOR, Scene
from airtable.physics.table import TABLE_HEIGHT_M, TABLE_WIDTH_M, AirTable

MESSAGE_S = 4.0
QUIT_CONFIRM_S = 4.0  # the quit question waits this long for a second Esc (or window close)
# Closing the window asks first when leaving would lose at least this much recording.
UNEXPORTED_ASK_S = 2.0
DEFAULT_FPS = 60.0  # when the display does not say its refresh rate
MAX_FPS = 240.0
# A still table (paused, or nothing moving) with nobody at it redraws this often,
# and wakes at once on input: a laptop projecting all lesson stays quiet.
IDLE_FPS = 12.0
IDLE_AFTER_S = 1.0  # input this recent keeps the full frame rate
OUT_OF_VIEW = "the table is out of view: q brings it back"
STILL_PX_PER_S = 0.5  # slower than this on screen, nothing visibly moves: the table idles
ERROR_TITLES = {
    "load": "Demo {key} could not be loaded",
    "build": "Demo {key} could not be built",
    "event": "Demo {key}: a timed event failed",
}

MODIFIER_KEYS = frozenset(
    getattr(pygame, f"K_{side}{name}") for side in "LR" for name in ("SHIFT", "CTRL", "ALT", "META", "SUPER")
)
# Kept importable from here: the key table lives in controls.py.
BINDINGS = controls.BINDINGS


def display_rate_hz() -> float:
    """The refresh rate of the display the app shows on (DEFAULT_FPS if it does not say)."""
    try:
        rates = pygame.display.get_desktop_refresh_rates()
    except (AttributeError, pygame.error):
        rates = []
    rate = max((r for r in rates if r > 0), default=0)
    return float(min(rate, MAX_FPS)) if rate else DEFAULT_FPS


def unused_path(folder: Path, stem: str, suffix: str = ".png") -> Path:
    """`folder/stem.png`, or `stem-2.png`, `stem-3.png`, ... if taken: never overwrites."""
    path, n = folder / f"{stem}{suffix}", 1
    while path.exists():
        n += 1
        path = folder / f"{stem}-{n}{suffix}"
    return path


class App:
    """The teacher's table: one AirTable, its clients, a window and the loop."""

    # What shows over the table lives in one stack, `overlays` (overlays.py).
    show_help = OverlayFlag("help")
    show_notes = OverlayFlag("notes")
    show_chart = OverlayFlag("chart")
    menu = OverlayValue("menu")  # a DemoMenu while the menu is open
    build_error = OverlayValue("error")  # the demo's DemoError, shown instead of the demo while set
    notice = OverlayValue("notice", empty=[])  # lines of a "press any key" notice

    def __init__(
        self,
        demos: dict[str, Demo] | DemoShelf,
        *,
        demo_key: str = "1",
        variation: int = 0,
        headless: bool = False,
        server=None,
        server_problem: str | None = None,
        demo_errors=(),
        window_size_px: tuple[int, int] | None = None,
        fullscreen: bool = False,
        show_fps: bool = False,
    ) -> None:
        self.shelf = demos if isinstance(demos, DemoShelf) else DemoShelf.from_demos(demos)
        if not self.shelf.demos:
            raise ValueError("no demos found")
        self.table = AirTable(TABLE_WIDTH_M, TABLE_HEIGHT_M)
        self.env = Environment(width_m=TABLE_WIDTH_M, height_m=TABLE_HEIGHT_M)
        self.local = Client(name="local", color=LOCAL_COLOR)
        # The loop owns the clients (index 0 is the local user); the server adds the students.
        self.clients: list[Client] = [self.local]
        self.window = GameWindow(self.env, headless=headless, size_px=window_size_px, fullscreen=fullscreen)
        self.window.show_fps = show_fps  # --stats: the frame rate in a corner too
        self.painter = AidsPainter(self.window)
        self.timeline_painter = TimelinePainter(self.window)
        if not headless:
            pygame.mouse.set_visible(False)  # the local client's arrow is the pointer
        self.server = server
        self.server_problem = server_problem  # why students cannot join, when the server did not start
        self.stats = RunStats()  # frames, steps and their cost, for --stats
        self._init_state()
        self.errors: list[DemoError] = []  # every error reported, in order
        for error in [*demo_errors, *self.shelf.errors]:
            self.report(error)
        self.notice = [f"could not load {e}" for e in self.errors]
        self.start_demo(demo_key if demo_key in self.demos else next(iter(self.demos)), variation)

    def _init_state(self) -> None:
        self.overlays = Overlays()
        self.running = True
        self.paused = False
        self.trails = False
        self.speed = 1.0
        self.help_page, self.help_pages = 0, 1
        self.show_annotations = False
        self.vectors = 0  # 0 off, 1 velocity, 2 momentum
        self.inspecting = False
        self._notices_seen = 0  # how many of table.notices were said
        self.quit_armed_until = -1.0  # clock_s until which a second Esc quits
        self.collision_log = aids.CollisionLog()
        self.chart = aids.EnergyChart()
        self.lessons = Lessons(overlays=self.overlays)  # recording, momenta, saving the moment (lessons.py)
        self.room = room.Room(overlays=self.overlays)  # the roster, hands off, the floor, anonymous names (room.py)
        self.history = History()  # the table's recent moments, for rewinding (history.py, rewind.py)
        self.predict = predict.PredictRound()  # predict, then reveal (predict.py)
        self.keys_down: set[int] = set()
        self.mouse_px = (self.env.size_px[0] / 2, self.env.size_px[1] / 2)
        self.mouse_button = 0
        self.panning = False
        self.fps = 0.0
        self._fps_counter = FpsCounter()
        self.stepper = FixedStep(1 / 240)
        self.message = ""
        self.message_until = 0.0
        self.message_lasts = False  # the message outlives a demo start (App.say)
        self.clock_s = 0.0  # time the app has run (sum of frame times)
        self.frame_dt_s = 0.0  # the current frame's time (held keys act in proportion)
        self.last_input_s = 0.0  # clock_s of the last input, local or a student's
        self._students_seen: tuple = ()  # the students' cursors when last looked at
        self.loop: IdlingLoop | None = None  # while run() runs
        self.demo_key = ""
        self.demo_path: Path | None = None

    # ------------------------------------------------------------ demos

    @property
    def demos(self) -> dict[str, Demo]:
        return self.shelf.demos

    @property
    def demo(self) -> Demo:
        return self.demos.get(self.demo_key) or next(iter(self.demos.values()))

    @property
    def dt_s(self) -> float:
        return self.stepper.dt_s

    def report(self, error: DemoError) -> None:
        """Note a demo error and print it to the terminal as `file:line: message`."""
        self.errors.append(error)
        print(error.one_line(), file=sys.stderr, flush=True)

    def start_demo(self, key: str, variation: int = 0) -> None:
        """Clear the table and build demo `key`, re-reading demo files that changed on disk.

        A demo whose file does not load, or whose build fails, shows its error instead.
        """
        for error in self.shelf.refresh():
            self.report(error)
        broken = self.shelf.broken(key)  # its file failed since it last loaded: show why
        if broken is None and key not in self.demos:
            self.say(f"no demo on key {key_label(key)}")
            return
        if not self.message_lasts:
            self.message = ""  # it spoke of the demo that is going
        demo = self.demos.get(key) if broken is None else None
        if self.build_error is not None:
            self.paused = False  # the pause came with the error; a new start runs
        self.demo_key, self.demo_path = key, (demo.path if demo else broken.path)
        self.variation = variation % len(demo.variations) if demo and demo.variations else 0
        self._clear_table()
        self.build_error = broken
        if demo is not None:
            try:
                demo.build(self.table, self.variation)
            except Exception as exc:  # a teacher's demo may fail in any way; the app goes on
                self._demo_failed(exc, "build")
                self.table.clear()
        self.stepper.reset(demo.dt_s if demo else self.stepper.dt_s)
        self.trails = demo.trails if demo else False
        self.chart.sample(self.table)
        self.lessons.start(self.table)
        self.history.clear()
        self.history.record(self.table)
        predict.end_round(self)
        self.window.set_caption(f"Air Table - {self.caption()}")

    def _clear_table(self) -> None:
        self.table.clear()
        self.table.reset_settings()
        for client in self.clients:
            client.held = None
        self.window.clear_trails()
        self.collision_log.clear()
        self.chart.clear()
        self.painter.new_demo()  # arrow scales are per demo

    def _demo_failed(self, exc: BaseException, stage: str) -> None:
        path = self.demo_path or Path(f"demo {self.demo_key}")
        self.build_error = error_from_exception(path, exc, stage)
        self.report(self.build_error)

    def caption(self) -> str:
        if self.build_error is not None and self.build_error.stage == "load":
            return f"Demo {self.demo_key}: {self.build_error.path.name}"
        return self.demo.label(self.variation)

    def press_demo_key(self, key: str) -> None:
        self.start_demo(key)

    def next_variation(self, step: int) -> None:
        if not self.demo.variations:
            self.say("this demo has no variations")
            return
        self.start_demo(self.demo_key, self.variation + step)

    def next_demo(self, step: int) -> None:
        self.shelf.refresh()
        keys = list(self.demos)
        here = keys.index(self.demo_key) if self.demo_key in keys else -step
        self.start_demo(keys[(here + step) % len(keys)])

    # ------------------------------------------------------------ panels and keys

    def open_menu(self) -> None:
        for error in self.shelf.refresh():
            self.report(error)
        items = [(key, demo.title) for key, demo in self.demos.items()]
        self.menu = DemoMenu(items, current=self.demo_key)

    def panel(self) -> str | None:
        """Which panel is in the middle of the window now, if any (the quit question lapses)."""
        if self.overlays.shown("quit") and self.clock_s >= self.quit_armed_until:
            self.overlays.close("quit")
        return self.overlays.panel()

    def close_panel(self) -> bool:
        """Close what is on top (a panel, else the chart, values or momenta); False if nothing was open."""
        self.panel()  # a lapsed quit question first
        closing = self.overlays.top()
        if closing == "help":
            self.help_page = 0
        return closing is not None and self.overlays.close(closing)

    def take_key_for_overlay(self, event: pygame.event.Event) -> bool:
        """A panel that waits for a key takes it first; True if it did."""
        panel = self.panel()
        if event.key == pygame.K_ESCAPE or panel not in ("quit", "menu", "notice"):
            return False
        if event.key in MODIFIER_KEYS:
            return True  # Shift or Ctrl alone answers nothing: it starts a key
        if panel == "menu" and event.key == pygame.K_TAB:
            self.menu = None
        elif panel == "menu":
            picked = self.menu.press(pygame.key.name(event.key), getattr(event, "unicode", ""))
            if picked is not None:
                self.menu = None
                self.start_demo(picked)
        else:
            self.close_panel()  # "press any key to go on"; any key but Esc keeps the table running
        return True

    def student_count(self) -> int:
        return len(self.clients) - 1

    def escape(self) -> None:
        """Esc: close what is on top; with nothing open, ask; Esc again while asked quits."""
        if self.panel() == "quit":
            self.quit_now()
        elif not self.close_panel():
            self.ask_to_quit()

    def close_window(self) -> None:
        """The window's close button: quit, asking first while leaving would drop students or
        lose recording; closing again (or Esc) while asked quits."""
        if self.panel() == "quit" or not self.quit_would_lose():
            self.quit_now()
        else:
            self.ask_to_quit()

    def quit_now(self) -> None:
        """Quit after this frame, which is drawn without the question (--screenshot saves it)."""
        self.overlays.close("quit")
        self.running = False

    def ask_to_quit(self) -> None:
        self.quit_armed_until = self.clock_s + QUIT_CONFIRM_S
        self.overlays.open("quit")

    def quit_would_lose(self) -> list[str]:
        """What quitting now drops, one sentence each (empty: nothing)."""
        lost = []
        n = self.student_count()
        if n:
            lost.append(f"{n} student{'' if n == 1 else 's'} will be dropped.")
        unexported = self.lessons.unexported_s()
        if unexported >= UNEXPORTED_ASK_S:
            lost.append(f"{unexported:.0f} s of recording not exported (x exports it).")
        return lost

    def zoom(self, factor: float) -> None:
        self.env.zoom_about(self.mouse_px, factor)
        self.window.clear_trails()

    def save_screenshot(self) -> None:
        path = unused_path(Path("screenshots"), time.strftime("airtable-%Y%m%d-%H%M%S"))
        try:
            saved = self.window.save_screenshot(path)
        except (OSError, pygame.error) as exc:
            self.say(f"could not save the screenshot: {exc}")
        else:
            self.say(f"screenshot saved to {saved.resolve()}", lasting=True)

    def say(self, text: str, *, lasting: bool = False) -> None:
        """Show a one-line message on screen for a few seconds. It is about the demo on the table and goes
        when another demo starts, unless `lasting` (it says where a file was written)."""
        self.message = text
        self.message_until = self.clock_s + MESSAGE_S
        self.message_lasts = lasting

    def handle_event(self, event: pygame.event.Event) -> None:
        controls.handle_event(self, event)

    # ------------------------------------------------------------ the frame

    def physics_step(self) -> bool:
        """One fixed step; False if a demo's timed event failed (the app pauses on it)."""
        try:
            self.table.step(self.dt_s, cursor_pulls(self.clients))
        except Exception as exc:  # a demo's timed event (teacher's code) failed
            self._demo_failed(exc, "event")
            self.paused = True
            return False
        self.stats.steps += 1
        self.chart.sample(self.table)
        self.lessons.after_step(self.table)
        if self.show_annotations:
            self.collision_log.add(self.table, self.clock_s)
        return True

    def frame(self, frame_dt_s: float) -> None:
        """One frame: input, clients, as many fixed physics steps as time allows, snapshot, drawing."""
        self.clock_s += frame_dt_s
        self.frame_dt_s = frame_dt_s
        for event in pygame.event.get():
            self.handle_event(event)
            self.last_input_s = self.clock_s
        controls.run_held(self)
        # Recomputed every frame: zooming moves the world under a still mouse.
        self.local.set_input(self.table, self.env.to_world(self.mouse_px), self.mouse_button)
        if self.server is not None:
            self.server.update_clients(self.clients, self.table)  # joins, leaves and inputs, even while paused
        predict.hands_off(self)  # a reveal plays untouched
        if not self.paused:
            self._run_physics(frame_dt_s)
        self._say_new_notices()
        predict.after_frame(self)  # a reveal freezes once its collision is over
        self.fps = self._fps_counter.tick(self.clock_s)
        scene = self.scene()
        if self.server is not None:
            shared = dataclasses.replace(scene, status=STATUS_SEPARATOR.join(self.status_parts(for_students=True)))
            shared.aids = shared_aids(self)  # the students see the teacher's aids too
            self.server.publish(shared)
        self.draw(scene)
        self.stats.frame()

    def _say_new_notices(self) -> None:
        """Each sentence the table adds to its notices (a softened spring, say) is said once, here and on stderr."""
        notices = self.table.notices
        if len(notices) < self._notices_seen:  # a new scene started the list again
            self._notices_seen = 0
        for sentence in notices[self._notices_seen :]:
            self.say(sentence)
            print(f"airtable: {sentence}", file=sys.stderr)
        self._notices_seen = len(notices)

    def _run_physics(self, frame_dt_s: float) -> None:
        """The frame's physics steps; the table as they left it joins the history."""
        if self.history.in_past:
            rewind.run_on(self)  # running again from a moment in the past: its future is dropped
        steps = self.table.steps
        for _ in range(self.stepper.steps(frame_dt_s, self.speed)):
            if not self.physics_step():
                break
        if self.table.steps != steps:
            self.history.record(self.table)

    def scene(self) -> Scene:
        return Scene.from_table(
            self.table,
            self.clients,
            title=self.caption(),
            status=STATUS_SEPARATOR.join(self.status_parts()),
            fps=self.fps,
            zoom=self.env.zoom,
            origin_m=(float(self.env.origin_m[0]), float(self.env.origin_m[1])),
        )

    def status_parts(self, for_students: bool = False) -> list[str]:
        """The status line in parts, most important first (a narrow window drops the last);
        `for_students`: as the students' windows show it, without the teacher's keys."""
        t = self.table
        parts = ["PAUSED"] if self.paused else []
        parts.extend(room.status_parts(self))  # hands off, the floor
        if self.predict.active:
            parts.append(predict.status_text(self, for_students))
        timeline = self.history.timeline() if self.history.in_past else None
        if timeline is not None:
            parts.append(f"rewound {timeline.newest_s - timeline.view_s:.2f} s")
        if self.speed != 1.0:
            parts.append(f"slow motion x1/{round(1 / self.speed)}")
        parts.append(f"t = {t.time_s:.2f} s")
        parts.append("F1: help")  # the students' windows have their own F1
        parts.append(world.gravity_label(t))
        parts.append(f"correction: {t.puck_correction}")
        n, hits = len(t.pos_m), t.collision_count
        parts.append(f"{n} puck{'' if n == 1 else 's'}")
        parts.append(f"{hits} collision{'' if hits == 1 else 's'}")
        if t.cr_puck == t.cr_wall:
            parts.append(f"restitution {t.cr_puck:g}")
        else:
            parts.append(f"restitution: pucks {t.cr_puck:g}, walls {t.cr_wall:g}")
        return parts

    def status_line(self) -> str:
        return STATUS_SEPARATOR.join(self.status_parts())

    def hud_lines(self) -> list:
        """The heads-up lines under the title: why students cannot join (in red), the join line,
        the student count, then the newest message."""
        alert = room_alert(self)
        lines: list = [(alert, ALERT_COLOR)] if alert else []
        if self.server is not None:
            lines.extend(self.server.join_lines())
            lines.extend(room.hud_lines(self))
        if self.message and self.clock_s < self.message_until:
            lines.append(self.message)
        elif not self.window.wall_rects():
            lines.append(OUT_OF_VIEW)
        return lines

    def draw(self, scene: Scene | None = None) -> None:
        """Draw `scene` (by default the table as it is now), the aids and the panel on top."""
        projected = self.room.projected(scene or self.scene())  # names hidden if anonymous
        self.window.draw(projected, trails=self.trails, hud=self.hud_lines())
        self._draw_timeline()  # first: the lesson panels then stand clear of it
        draw_lessons(self)  # before the aids: their labels then place themselves around its panels
        draw_aids(self)
        draw_predict(self)
        self._draw_panel()
        self.window.present()

    def _draw_timeline(self) -> None:
        """While paused (or in the past), where the view is in the history."""
        timeline = rewind.timeline_shown(self)
        if timeline is not None:
            self.timeline_painter.timeline(timeline)

    def _draw_panel(self) -> None:
        panel, w = self.panel(), self.window
        if panel == "quit":
            w.draw_question("Quit?", [*self.quit_would_lose(), "Esc again to quit; any other key to stay."])
        elif panel == "menu":
            rows = self.menu.rows(visible=w.panel_rows() - 2, label=key_label)  # the footer under them
            w.draw_panel("Demos", [*rows, self.menu.footer()])
        elif panel == "error":
            error = self.build_error
            title = ERROR_TITLES[error.stage].format(key=key_label(self.demo_key))
            label = key_label(self.demo_key)  # "7", "Shift+1"; keys like "t1" have no key of their own
            again = (
                f"press {label} again" if len(self.demo_key) == 1 or label != self.demo_key else "pick it in Tab's menu"
            )
            w.draw_panel(title, [str(error), f"Fix the file, then {again}. Esc hides this."])
        elif panel == "notice":
            w.draw_panel("Some demo files could not be loaded", [*self.notice, "Press any key to go on."])
        elif panel == "help":
            rows = [(key_label(k), d.title) for k, d in self.demos.items()]
            self.help_pages = w.draw_panel(
                "Keys", [(b.label, b.help) for b in BINDINGS], side_title="Demos", side_rows=rows, page=self.help_page
            )
        elif panel == "notes":
            w.draw_panel(self.demo.label(self.variation), [self.demo.notes or "(no notes)"], large=True)
        elif panel == "roster":
            draw_roster(self)

    def still(self) -> bool:
        """Nothing to show that changes quickly: paused or motionless, and no input
        (keys, mouse, or a student's cursor) for a second."""
        students = tuple((*c.cursor_m, c.button, c.active) for c in self.clients[1:])
        if students != self._students_seen:
            self._students_seen, self.last_input_s = students, self.clock_s
        if self.keys_down or self.mouse_button or self.clock_s - self.last_input_s < IDLE_AFTER_S:
            return False
        return self.paused or self.motion_px_per_s() < STILL_PX_PER_S

    def motion_px_per_s(self) -> float:
        """How fast the fastest puck crosses the screen: a settled demo's round-off is far below a pixel."""
        v = self.table.vel_mps
        if not len(v):
            return 0.0
        return float(np.sqrt(np.max(np.einsum("ij,ij->i", v, v)))) * self.env.px_per_m

    def run(
        self,
        seconds: float | None = None,
        max_frames: int | None = None,
        frame_dt_s: float | None = None,
        started: Callable[[], None] | None = None,
    ) -> int:
        """Run until Esc / window close, `seconds` or `max_frames` frames; returns the frames run.

        With `frame_dt_s` every frame is that long and nothing sleeps: `seconds`
        is then simulated time (tests and headless runs use it, so they never
        depend on timing). Without it, frames follow the clock, at most at the
        display's refresh rate, sleeping in between; a still table runs at
        IDLE_FPS and wakes on input. `started` is called once signals end the run (see loop.py).
        """
        self.loop = IdlingLoop(display_rate_hz(), IDLE_FPS, self.still, self.window.headless, fixed_dt_s=frame_dt_s)
        try:
            with signals_end_the_run(self.stop):
                if started is not None:
                    started()
                return self.loop.run(self._frame_running, max_frames=max_frames, max_time_s=seconds)
        finally:
            self.loop = None

    def stop(self) -> None:
        """End the run after this frame, asking nothing (a signal, not a person at the window)."""
        self.running = False

    def _frame_running(self, dt_s: float) -> bool:
        self.frame(dt_s)
        self.loop.after_frame()
        return self.running
