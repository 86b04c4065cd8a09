"""The teacher's app: one table, its clients, a window, its features, and the frame that ties them together.

Each frame (`App.frame`): input (the features first, then the key table of
controls.py and the mouse), the network's joins and inputs, as many fixed
physics steps as the frame's time allows (loop.py), a snapshot for the
students, then drawing. Everything else is a feature (feature.py) in one
list, `features`, whose hooks the frame calls in turn: the panels, the room,
predict-then-reveal, rewind, the lessons, the teaching aids and live edits.
The app keeps the demo on the table, the clock, the view and the mouse.
`App.run` repeats frames with an IdlingLoop (loop.py), as the student's window does.
Demo scenes come from demo files (demo_loader.py), read again when they change.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pygame

from airtable.app.aids_share import shared_aids, shared_lessons
from airtable.app.controls import KeyTable, by_position, demo_key_for, help_rows
from airtable.app.demo_loader import Demo, DemoError, DemoShelf, error_from_exception, key_label
from airtable.app.environment import Environment
from airtable.app.feature import Binding, Feature
from airtable.app.lessons import Lessons
from airtable.app.loop import FixedStep, FpsCounter, IdlingLoop, signals_end_the_run
from airtable.app.overlays import Overlays, OverlayValue
from airtable.app.panels import Panels
from airtable.app.predict import Predict
from airtable.app.rewind import Rewind
from airtable.app.room import Room
from airtable.app.stats import RunStats
from airtable.app.teaching_aids import Aids
from airtable.app.window import AidsPainter, GameWindow
from airtable.app.world import LiveEdits, gravity_label
from airtable.model import aids
from airtable.model.client import LOCAL_COLOR, Client, cursor_pulls
from airtable.model.scene import STATUS_SEPARATOR, Scene
from airtable.physics import state
from airtable.physics.table import TABLE_HEIGHT_M, TABLE_WIDTH_M, AirTable

MESSAGE_S = 4.0
# What the table or a demo says (a softened spring, the pi demo's count) stays this long.
NOTICE_S = 12.0
# A click this far (px at 720 px tall) beside a puck's edge grabs it.
GRAB_WITHIN_PX = 8.0
# Closing the window asks first when leaving would lose at least this much recording.
UNEXPORTED_ASK_S = 2.0
# A frame's physics that takes longer than this (s) in real time pauses the table (_pause_if_stalled).
STALL_PAUSE_S = 1.0
DEFAULT_FPS = 60.0  # when the display does not say its refresh rate
MAX_FPS = 240.0
# A still table (paused, or nothing moving) with nobody at it redraws this often,
# and wakes at once on input: a laptop projecting all lesson stays quiet.
IDLE_FPS = 12.0
# A frame's physics steps stop after this share of the frame period (the rest is for
# drawing): a table too heavy to step in real time runs in slow motion, not at a few frames a second.
PHYSICS_SHARE = 0.6
# Below this share of the steps asked for over the last second, the status line says the physics is
# behind, until it runs above CAUGHT_UP_SHARE again.
SLOW_SHARE = 0.9
CAUGHT_UP_SHARE = 0.97
IDLE_AFTER_S = 1.0  # input this recent keeps the full frame rate
OUT_OF_VIEW = "the table is out of view: q brings it back"
STILL_PX_PER_S = 0.5  # slower than this on screen, nothing visibly moves: the table idles
ZOOM_RATE_PER_S = 1.5  # held h / n: zoom factor e**1.5 per second
WHEEL_ZOOM = 1.1
MOUSE_EVENTS = (pygame.MOUSEMOTION, pygame.MOUSEBUTTONDOWN, pygame.MOUSEBUTTONUP, pygame.MOUSEWHEEL)


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
    """The teacher's table: one AirTable, its clients, a window, the features and the loop."""

    build_error = OverlayValue("error")  # the demo's DemoError, shown instead of the demo while set

    def __init__(
        self,
        demos: dict[str, Demo] | DemoShelf,
        *,
        demo_key: str = "1",
        variation: int | None = None,
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
        self.local = Client(name="teacher", color=LOCAL_COLOR)  # its cursor is labelled so, for the class
        # The loop owns the clients (index 0 is the local user); the server adds the students.
        self.clients: list[Client] = [self.local]
        self.window = GameWindow(self.env, headless=headless, size_px=window_size_px, fullscreen=fullscreen)
        self.window.show_fps = show_fps  # --stats: the frame rate in a corner too
        self.painter = AidsPainter(self.window)
        if not headless:
            pygame.mouse.set_visible(False)  # the local client's arrow is the pointer
        self.server = server
        self.stats = RunStats()  # frames, steps and their cost, for --stats
        self._init_state()
        self._init_features(server_problem)
        self.errors: list[DemoError] = []  # every error reported, in order
        for error in [*demo_errors, *self.shelf.errors]:
            self.report(error)
        self.panels.notice = [f"could not load {e}" for e in self.errors]
        self.start_demo(demo_key if demo_key in self.demos else next(iter(self.demos)), variation)

    def _init_state(self) -> None:
        self.overlays = Overlays()  # what shows over the table, in one stack (overlays.py)
        self.running = True
        self.paused = False
        self.speed = 1.0
        self._notices_seen = 0  # how many of table.notices were said
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
        self._said_behind = False  # the status line says the physics is behind (_behind)
        self.last_input_s = 0.0  # clock_s of the last input, local or a student's
        self._students_seen: tuple = ()  # the students' cursors when last looked at
        self.loop: IdlingLoop | None = None  # while run() runs
        self.demo_key = ""  # the demo on the table
        self.running_demo: Demo | None = None  # the demo whose run is on the table (its file may be broken since)
        self.error_key = ""  # the demo whose start failed last (the error panel's), while build_error is set
        self.failed_start: str | None = None  # the heading while the demo last started failed (caption)
        self.goes_on: str | None = None  # then, the run that goes on on the table (None: the table is empty)
        self.demo_path: Path | None = None
        self.variation = 0

    def _init_features(self, server_problem: str | None) -> None:
        """The features, in the order they see events and write the status line; each draws in its draw_order."""
        self.panels = Panels(self, BINDINGS)  # help, notes, the demo menu, errors, the quit question
        self.room = Room(self, server_problem)  # the roster, hands off, the floor, anonymous names
        self.predict = Predict(self, self.room)  # predict, then reveal
        self.rewind = Rewind(self, self.predict)  # the table's recent moments, and the way back
        self.aids = Aids(self)  # trails, vectors, annotations, the chart, the inspector
        self.lessons = Lessons(self, self.aids)  # recording, momenta, values, saving the moment
        self.live_edits = LiveEdits(self)  # gravity, restitution, correction, a puck's mass and radius
        self.features: list[Feature] = [
            self.panels,
            self.room,
            self.predict,
            self.rewind,
            self.lessons,
            self.aids,
            self.live_edits,
        ]
        self._drawn = sorted(self.features, key=lambda f: f.draw_order)
        self.keys = KeyTable([self, *self.features])

    # ------------------------------------------------------------ demos

    @property
    def demos(self) -> dict[str, Demo]:
        return self.shelf.demos

    @property
    def demo(self) -> Demo:
        return self.demos.get(self.demo_key) or self.running_demo or next(iter(self.demos.values()))

    @property
    def dt_s(self) -> float:
        return self.stepper.dt_s

    def report(self, error: DemoError) -> None:
        """Note a demo error and print it to the terminal as `file:line: message`."""
        self.errors.append(error)
        print(error.one_line(), file=sys.stderr, flush=True)

    def start_demo(self, key: str, variation: int | None = None) -> None:
        """Clear the table and build demo `key` (its `variation`; None: the demo's default), re-reading
        demo files that changed on disk.

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
        # A demo that fails to load or build leaves the table that ran, whichever demo it was (a user test:
        # the lesson's table emptied), and the app goes on as that demo (Ctrl+S saves it under its title).
        ran = (self.demo_key, self.demo_path, self.variation) if self.running_demo is not None else None
        running = state.capture(self.table) if ran is not None else None
        self.demo_key, self.demo_path, self.error_key = key, (demo.path if demo else broken.path), key
        if variation is None:
            variation = demo.default_variation if demo else 0
        self.variation = variation % len(demo.variations) if demo and demo.variations else 0
        self._clear_table()
        self.build_error = broken
        if demo is not None:
            self._build(demo)
        # The heading names what failed until another start, also once Esc hid the error (it named the
        # built-in demo whose key the broken file had taken, over an empty table).
        self.failed_start = None if self.build_error is None else self._failed_caption(demo, ran)
        if self.build_error is None:
            if ran is not None and ran[0] != key:
                self.env.reset()  # another demo: the whole table (zoomed on a puck, it was one giant puck)
            self.running_demo = demo
        elif running is not None:
            state.restore(self.table, running)
            self.demo_key, self.demo_path, self.variation = ran
            demo = self.demo
        else:
            self.running_demo = None  # an empty table
        self.stepper.reset(demo.dt_s if demo else self.stepper.dt_s)
        self.aids.trails = demo.trails if demo else False
        for feature in self.features:
            feature.on_demo_start(self.table)
        self.window.set_caption(f"Air Table - {self.caption()}")

    def _build(self, demo: Demo) -> None:
        """Build `demo` on the cleared table; an exception becomes the demo's error (build_error)."""
        try:
            demo.build(self.table, self.variation)
        except Exception as exc:  # a teacher's demo may fail in any way; the app goes on
            self._demo_failed(exc, "build")
            # Nothing of it stays: an empty table with the settings its build had set so far (gravity on) was
            # the failed demo's half, under the caption "not built".
            self.table.clear()
            self.table.reset_settings()

    def _clear_table(self) -> None:
        self.table.clear()
        self.table.reset_settings()
        for client in self.clients:
            client.held = None
        self.window.clear_trails()

    def _demo_failed(self, exc: BaseException, stage: str) -> None:
        path = self.demo_path or Path(f"demo {self.demo_key}")
        self.build_error = error_from_exception(path, exc, stage)
        self.report(self.build_error)

    def caption(self) -> str:
        return self.failed_start or self.demo.label(self.variation)

    def _failed_caption(self, demo: Demo | None, ran: tuple | None) -> str:
        """The heading after a failed start; `ran`: (key, path, variation) of the demo whose run goes on.
        It names the demo on the table first, then the one that failed: a narrow window cuts the end, and
        at 640x480 the heading named the failed demo over the one running (a user test)."""
        self.goes_on = None if ran is None else self._goes_on(ran)
        if self.build_error.stage == "load" or demo is None:
            failed, what = f"Demo {key_label(self.error_key)}: {self.build_error.path.name}", "does not load"
        else:
            failed, what = demo.label(self.variation), "not built"
        if ran is None:
            return f"{failed} ({what})"
        if ran[0] == self.error_key:  # its own file broke: the same demo goes on
            return f"{failed} ({what}: its last run goes on)"
        return f"{self.goes_on}; {failed} {what}"

    def _goes_on(self, ran: tuple) -> str:
        """What stays on the table after a failed start: `ran` (key, path, variation), the run that goes on."""
        return "its last run" if ran[0] == self.error_key else self.running_demo.label(ran[2])

    def next_variation(self, step: int) -> None:
        """Left/Right: the demo's previous or next variation; at either end it stays (a step round the end
        jumped from the lightest to the heaviest: from a 500-puck gas to 10000)."""
        count = len(self.demo.variations)
        if not count:
            self.say("this demo has no variations")
        elif not 0 <= self.variation + step < count:
            end, back = ("first", "Right") if step < 0 else ("last", "Left")
            self.say(f"this is its {end} variation ({back} goes back)")
        else:
            self.start_demo(self.demo_key, self.variation + step)

    def next_demo(self, step: int) -> None:
        """PageUp/PageDown: the demo before or after this one; after a demo that failed to start, the one
        before or after that (a user test: PageDown tried the same broken demo again and again)."""
        self.shelf.refresh()
        keys = list(self.demos)
        at = self.error_key if self.failed_start is not None and self.error_key in keys else self.demo_key
        here = keys.index(at) if at in keys else -step
        self.start_demo(keys[(here + step) % len(keys)])

    # ------------------------------------------------------------ what the app's own keys do

    def toggle_pause(self) -> None:
        if not self.predict.pause_key():  # a prediction round decides what Space does while it is under way
            self.paused = not self.paused

    def next_slow_motion(self) -> None:
        factors = aids.SLOW_MOTION_FACTORS
        self.speed = factors[(factors.index(self.speed) + 1) % len(factors)] if self.speed in factors else 1.0

    def zoom(self, factor: float) -> None:
        self.env.zoom_about(self.mouse_px, factor)
        self.window.clear_trails()

    def zoom_in(self) -> None:
        self.zoom(math.exp(ZOOM_RATE_PER_S * self.frame_dt_s))

    def zoom_out(self) -> None:
        self.zoom(math.exp(-ZOOM_RATE_PER_S * self.frame_dt_s))

    def reset_view(self) -> None:
        with self._pointer_kept_on_the_table():
            self.env.reset()
        self.window.clear_trails()

    def toggle_fullscreen(self) -> None:
        # The window moves under the pointer (the window manager's own time): a held puck is let go, or the
        # string's end jumped with the pointer's place in the window (a user test: 243 J after F11 and back).
        self.mouse_button = 0
        self.window.toggle_fullscreen()

    @contextlib.contextmanager
    def _pointer_kept_on_the_table(self):
        """While a puck is held, a view that changes under a still pointer (a resize, q) moves the pointer
        with the table: the string's end stays where it was on the table. Left where it was on the screen,
        the pointer came to another point of the table and the string yanked the puck there (a held puck
        left at 217 m/s after resizes)."""
        held = self.mouse_button and self.local.held is not None
        point_m = self.env.to_world(self.mouse_px)
        yield
        if held:
            self.mouse_px = self.window.put_pointer_on(point_m)

    def save_screenshot(self) -> None:
        path = unused_path(Path("screenshots"), time.strftime("airtable-%Y%m%d-%H%M%S"))
        try:
            saved = self.window.save_screenshot(path)
        except (OSError, pygame.error) as exc:
            self.say(f"could not save the screenshot: {exc}")
        else:
            self.say(f"screenshot saved to {saved.resolve()}", lasting=True)

    bindings = (
        Binding("1-9, 0", "start (again: restart) that demo"),
        Binding("Shift+1/2/3", "correction comparison: off, two-step, perfect kiss"),
        Binding(
            "Left / Right",
            "previous / next variation",
            {pygame.K_LEFT: lambda app: app.next_variation(-1), pygame.K_RIGHT: lambda app: app.next_variation(+1)},
        ),
        Binding(
            "PageUp / PageDown",
            "previous / next demo",
            {pygame.K_PAGEUP: lambda app: app.next_demo(-1), pygame.K_PAGEDOWN: lambda app: app.next_demo(+1)},
        ),
        Binding("Space", "pause / resume", {pygame.K_SPACE: toggle_pause}),
        Binding(
            "h / n (hold)", "zoom in / out about the cursor", {pygame.K_h: zoom_in, pygame.K_n: zoom_out}, held=True
        ),
        Binding("mouse wheel", "zoom in / out about the cursor"),
        Binding("Ctrl + mouse drag", "pan the view"),
        Binding("q", "reset the view", {pygame.K_q: reset_view}),
        Binding("mouse buttons 1 / 2 / 3", "grab a puck with the medium / soft / stiff cursor string"),
        Binding("s", "slow motion: 1, 1/2, 1/4, 1/8, 1/16 of real time", {pygame.K_s: next_slow_motion}),
        Binding("F11", "fullscreen on / off", {pygame.K_F11: toggle_fullscreen}),
        Binding("F12", "save a screenshot PNG", {pygame.K_F12: save_screenshot}),
    )

    # ------------------------------------------------------------ what the features may ask

    def say(self, text: str, *, lasting: bool = False, for_s: float = MESSAGE_S) -> None:
        """Show a one-line message on screen for `for_s` seconds. It is about the demo on the table and goes
        when another demo starts, unless `lasting` (it says where a file was written)."""
        self.message = text
        self.message_until = self.clock_s + for_s
        self.message_lasts = lasting

    def student_count(self) -> int:
        return len(self.clients) - 1

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

    def forget_after(self, t_s: float) -> None:
        """The table runs on from `t_s` in the past: every feature forgets what came after it."""
        for feature in self.features:
            feature.forget_after(t_s)

    def escape_features(self) -> bool:
        """Esc with no overlay open: the first feature with something under way ends it; True if one did."""
        return any(feature.on_escape() for feature in self.features)

    # ------------------------------------------------------------ input

    def handle_event(self, event: pygame.event.Event) -> None:
        """The features first (an open panel, the roster, a prediction round), then the key table and the
        demo keys, the mouse, and the window's size."""
        event = by_position(event)  # letters of any layout, where they sit on the keyboard
        if event.type == pygame.KEYUP:
            self.keys_down.discard(event.key)
            return
        if event.type == pygame.KEYDOWN:
            self.keys_down.add(event.key)
        if any(feature.handle_event(event) for feature in self.features):
            return
        if event.type == pygame.KEYDOWN and not self.keys.press(event):
            key = demo_key_for(event)
            if key is not None:  # its key again restarts it as it is (the variation it was at)
                self.start_demo(key, self.variation if key == self.demo_key else None)
        elif event.type in MOUSE_EVENTS:
            self._handle_mouse(event)
        elif event.type in (pygame.VIDEORESIZE, pygame.WINDOWSIZECHANGED):
            with self._pointer_kept_on_the_table():
                self.window.handle_event(event)  # the table and the type follow the new size
        elif event.type in (pygame.WINDOWLEAVE, pygame.WINDOWENTER):
            # The pointer left the window: no "teacher" arrow parked at the table's edge on every screen (a
            # user test), unless a puck is held: a drag goes on outside.
            self.local.active = event.type == pygame.WINDOWENTER or bool(self.mouse_button)

    def _handle_mouse(self, event: pygame.event.Event) -> None:
        if event.type == pygame.MOUSEMOTION:
            self.local.active = True  # (back in the window, whatever said so)
            if self.panning:
                self.env.pan(event.rel)
                self.window.clear_trails()
            self.mouse_px = event.pos
        elif event.type == pygame.MOUSEWHEEL:
            self.zoom(WHEEL_ZOOM**event.y)
        elif event.button in (1, 2, 3):
            self.mouse_px = event.pos
            if event.type == pygame.MOUSEBUTTONUP:
                self.panning = False
                if event.button == self.mouse_button:
                    self.mouse_button = 0
            # Ctrl comes from the key events the app saw, never from a global read.
            elif self.keys_down & {pygame.K_LCTRL, pygame.K_RCTRL}:
                self.panning = True
            else:
                self.mouse_button = event.button
                # Grab where the button went down: a press and a quick move can share one frame. A click
                # just beside a puck takes it too: in a gas of 10000 a puck is a few pixels across.
                within_m = GRAB_WITHIN_PX * self.window.unit / self.env.px_per_m
                self.local.set_input(self.table, self.env.to_world(event.pos), event.button, within_m)

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
        for feature in self.features:
            feature.after_step(self.table)
        return True

    def frame(self, frame_dt_s: float) -> None:
        """One frame: input, clients, as many fixed physics steps as time allows, snapshot, drawing."""
        self.clock_s += frame_dt_s
        self.frame_dt_s = frame_dt_s
        for event in pygame.event.get():
            self.handle_event(event)
            self.last_input_s = self.clock_s
        self.keys.run_held(self.keys_down)
        # Recomputed every frame: zooming moves the world under a still mouse.
        self.local.set_input(self.table, self.env.to_world(self.mouse_px), self.mouse_button)
        if self.server is not None:
            self.server.update_clients(self.clients, self.table)  # joins, leaves and inputs, even while paused
        for feature in self.features:
            feature.before_physics()
        # A notice or a demo's error, which the teacher did not ask for, covers the table: it waits for them
        # (a user test: a demo's first collision happened under the "could not be loaded" notice).
        if not self.paused and self.panels.panel() not in ("notice", "error"):
            self.stepper.run(frame_dt_s, self.speed, self.physics_step)
            self._pause_if_stalled()
        self._say_new_notices()
        for feature in self.features:
            feature.after_physics()
        # An idle loop draws few frames on purpose: the corner says "idle", not a rate that reads as a slow
        # machine, and the rate measured once anything moves again counts none of the idle frames.
        self.window.idle = self.loop is not None and self.loop.idling
        if self.window.idle:
            self._fps_counter.restart()
        self.fps = self._fps_counter.tick(self.clock_s)
        scene = self.scene()
        if self.server is not None:
            shared = dataclasses.replace(scene, status=STATUS_SEPARATOR.join(self.status_parts(for_students=True)))
            shared.aids = self.shared_aids()  # the students see the teacher's aids too
            self.server.publish(shared)
        self.draw(scene)
        self.stats.frame(idle=self.window.idle)

    def shared_aids(self):
        """What the students' windows show of the teacher's aids, notes and lesson panels (aids_share.py)."""
        notes = (self.demo.notes or "(no notes)") if self.panels.show_notes and self.demo is not None else None
        lessons = shared_lessons(self.lessons, self.rewind.timeline_shown(), self.table, self.clients)
        return shared_aids(self.aids, self.table, self.painter, self.clock_s, notes, lessons)

    def _pause_if_stalled(self) -> None:
        """In real time, a frame whose physics took over STALL_PAUSE_S pauses the table: a demo far too heavy
        (a typo's 1e9 m/s, 20000 pucks on top of each other) otherwise answers keys, Esc too, seconds late."""
        took = self.stepper.last_run_s
        if self.stepper.budget_s is not None and took > STALL_PAUSE_S:
            self.paused = True
            self.say(f"paused: one frame's physics took {took:.1f} s, too slow to answer keys (Space runs on)")

    def _say_new_notices(self) -> None:
        """Each sentence the table adds to its notices (a softened spring, say) is said once, here and on stderr."""
        notices = self.table.notices
        if len(notices) < self._notices_seen:  # a new scene started the list again
            self._notices_seen = 0
        for sentence in notices[self._notices_seen :]:
            self.say(sentence, for_s=NOTICE_S)
            print(f"airtable: {sentence}", file=sys.stderr)
        self._notices_seen = len(notices)

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
        for feature in self.features:
            parts.extend(feature.status_parts(for_students))  # hands off, the floor, the round, rewound
        view, blank = self.env.view_note(t.pos_m, t.radius_m)
        if blank:  # (zoomed far in, the window is black: say so, and how to get back, never cut as a hint)
            parts.append(view if for_students else f"{view}: q shows the whole table")
        elif view:
            parts.append(view if for_students else f"{view} (q: the whole table)")
        if self.speed != 1.0:
            parts.append(f"slow motion x1/{round(1 / self.speed)}")
        behind = self._physics_behind() if for_students else ""  # (the teacher's: in the heads-up lines)
        if behind:
            parts.append(f"{behind} (the teacher's computer's most)")
        n, hits, walls = len(t.pos_m), t.collision_count, t.wall_collision_count
        parts.append(f"{hits} collision{'' if hits == 1 else 's'}, {walls} on walls")  # what a class counts along
        parts.append(f"t = {t.time_s:.2f} s")
        parts.append("F1: help")  # the students' windows have their own F1
        parts.append(gravity_label(t))
        parts.append(f"correction: {t.puck_correction}")
        parts.append(f"{n} puck{'' if n == 1 else 's'}")
        if t.cr_puck == t.cr_wall:
            parts.append(f"restitution {t.cr_puck:g}")
        else:
            parts.append(f"restitution: pucks {t.cr_puck:g}, walls {t.cr_wall:g}")
        return parts

    def _physics_behind(self) -> str:
        """ "physics at N% of real time" while the physics falls behind (slow motion's own share taken in),
        else "". Not on an idle window: a still table draws a few frames a second, and a busy computer
        made those look behind ("physics at 72 %" beside "idle", a user test)."""
        if self.paused or self.window.idle or not self._behind():
            return ""
        return f"physics at {self.stepper.real_time_share * self.speed:.0%} of real time"

    def _behind(self) -> bool:
        """Whether the physics fell behind what was asked of it: said below SLOW_SHARE of the steps, and
        unsaid again only above CAUGHT_UP_SHARE (a pace near the line would make the status line flicker)."""
        share = self.stepper.real_time_share
        self._said_behind = share < (CAUGHT_UP_SHARE if self._said_behind else SLOW_SHARE)
        return self._said_behind

    def status_line(self) -> str:
        return STATUS_SEPARATOR.join(self.status_parts())

    def hud_lines(self) -> list:
        """The heads-up lines under the title: the features' (why students cannot join, in red, the join
        line, the student count), whether the physics keeps real time, then the newest message."""
        lines: list = [line for feature in self.features for line in feature.hud_lines()]
        behind = self._physics_behind()  # here, not in the status line: coming and going, it pushed parts off it
        if behind:
            lines.append(f"{behind} (the computer's most)")
        if self.message and self.clock_s < self.message_until:
            lines.append(self.message)
        elif not self.window.wall_rects():
            lines.append(OUT_OF_VIEW)
        return lines

    def draw(self, scene: Scene | None = None) -> None:
        """Draw `scene` (by default the table as it is now), then each feature in its draw_order."""
        projected = self.room.projected(scene or self.scene())  # names hidden if anonymous
        self.window.draw(projected, trails=self.aids.trails, hud=self.hud_lines())
        for feature in self._drawn:
            feature.draw()
        self.window.present()

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
        self.loop = IdlingLoop(
            display_rate_hz(),
            IDLE_FPS,
            self.still,
            self.window.headless,
            stepping=lambda: not self.paused,  # its physics keeps real time: its idle frames stay short
            fixed_dt_s=frame_dt_s,
        )
        # In real time a frame's physics stops after its share of a 60 Hz frame (of a display's slower
        # frame), to leave time to draw it; a faster display draws fewer frames before the physics slows.
        frame_s = 1.0 / min(display_rate_hz(), DEFAULT_FPS)
        self.stepper.budget_s = None if frame_dt_s is not None else PHYSICS_SHARE * frame_s
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


# The key table, in the help's order: F1 and README's table (tools/keytable.py) show it.
BINDINGS = help_rows(
    b for owner in (App, Panels, Room, Predict, Rewind, Lessons, Aids, LiveEdits) for b in owner.bindings
)
