"""The teacher's app: game loop, keys, demo switching, teaching aids (see cli.py for the options).

The loop runs the physics at a fixed step with an accumulator (so results do
not depend on the frame rate) and draws at the display's rate. App-level keys
live in one table, `BINDINGS`, that drives both the dispatch and the F1 help
screen; demo scenes come from the demo files (demo_loader.py).
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pygame

from airtable.app import aids
from airtable.app.client import LOCAL_COLOR, Client, cursor_pulls
from airtable.app.demo_loader import Demo, DemoError, error_from_exception, key_label
from airtable.app.environment import Environment
from airtable.app.scene import Scene
from airtable.app.window import AidsPainter, GameWindow
from airtable.physics.table import AirTable

# A stalled frame (window dragged, laptop busy) runs at most this much
# simulated time; the rest is dropped rather than exploding the physics.
MAX_SIM_PER_FRAME_S = 0.1
MAX_FPS = 120
ZOOM_RATE_PER_S = 1.5  # held h / n: zoom factor e**1.5 per second
WHEEL_ZOOM = 1.1
MESSAGE_S = 4.0
DIM_FORCE = (200, 200, 200)
COM_COLOR = (255, 255, 255)
FORCE_COLORS = {"cursor strings": (255, 120, 80), "springs": (255, 215, 0), "gravity": (90, 160, 255)}


@dataclass(frozen=True)
class Binding:
    """One row of the key table: which keys, what the help screen says, what runs."""

    label: str
    help: str
    keys: tuple[int, ...] = ()
    action: str | None = None  # App method taking the KEYDOWN event
    held: bool = False  # acts every frame while held, not on the press


DIGIT_KEYS = (
    pygame.K_1,
    pygame.K_2,
    pygame.K_3,
    pygame.K_4,
    pygame.K_5,
    pygame.K_6,
    pygame.K_7,
    pygame.K_8,
    pygame.K_9,
    pygame.K_0,
)

BINDINGS: tuple[Binding, ...] = (
    Binding("1-9, 0", "start that demo (press again to restart it)", DIGIT_KEYS, "key_demo"),
    Binding("Shift+1/2/3", "correction comparison: off, two-step, perfect kiss"),
    Binding("Left / Right", "previous / next variation", (pygame.K_LEFT, pygame.K_RIGHT), "key_variation"),
    Binding("PageUp / PageDown", "previous / next demo", (pygame.K_PAGEUP, pygame.K_PAGEDOWN), "key_page"),
    Binding("Space", "pause / resume", (pygame.K_SPACE,), "key_pause"),
    Binding(".", "one step while paused", (pygame.K_PERIOD,), "key_single_step"),
    Binding("f", "freeze: all velocities to zero", (pygame.K_f,), "key_freeze"),
    Binding("g", "gravity on/off (restitution 0.9 with gravity, 1.0 without)", (pygame.K_g,), "key_gravity"),
    Binding("p", "puck penetration correction off / two-step", (pygame.K_p,), "key_correction"),
    Binding("z", "perfect kiss on/off", (pygame.K_z,), "key_perfect_kiss"),
    Binding("h / n (hold)", "zoom in / out about the cursor", (pygame.K_h, pygame.K_n), "hold_zoom", held=True),
    Binding("mouse wheel", "zoom in / out about the cursor"),
    Binding("Ctrl + mouse drag", "pan the view"),
    Binding("q", "reset the view", (pygame.K_q,), "key_reset_view"),
    Binding("mouse buttons 1 / 2 / 3", "grab a puck with the medium / soft / stiff cursor string"),
    Binding("e", "trails: stop erasing, so each frame's pucks stay on screen", (pygame.K_e,), "key_trails"),
    Binding("s", "slow motion: 1, 1/2, 1/4, 1/8, 1/16 of real time", (pygame.K_s,), "key_slow_motion"),
    Binding("r", "reverse time: flip every velocity", (pygame.K_r,), "key_reverse"),
    Binding("a", "collision annotations: axes, overlap, separation, angle", (pygame.K_a,), "key_annotations"),
    Binding("v", "vectors: velocity / momentum arrows, forces, centre of mass", (pygame.K_v,), "key_vectors"),
    Binding("c", "energy and momentum chart", (pygame.K_c,), "key_chart"),
    Binding("i (hold)", "inspect the puck under the cursor", (pygame.K_i,), "hold_inspect", held=True),
    Binding("l", "lecture notes for this demo", (pygame.K_l,), "key_notes"),
    Binding("F1", "this help screen", (pygame.K_F1,), "key_help"),
    Binding("F12", "save a screenshot PNG", (pygame.K_F12,), "key_screenshot"),
    Binding("Esc", "quit", (pygame.K_ESCAPE,), "key_quit"),
)


def _ctrl_held(keys_down: set[int]) -> bool:
    return bool(keys_down & {pygame.K_LCTRL, pygame.K_RCTRL}) or bool(pygame.key.get_mods() & pygame.KMOD_CTRL)


def _shift_held(event: pygame.event.Event) -> bool:
    return bool(getattr(event, "mod", 0) & pygame.KMOD_SHIFT)


class App:
    """The teacher's table: one AirTable, its clients, a window and the loop."""

    def __init__(
        self,
        demos: dict[str, Demo],
        *,
        demo_key: str = "1",
        variation: int = 0,
        headless: bool = False,
        server=None,
        demo_errors: Sequence[DemoError] = (),
    ) -> None:
        if not demos:
            raise ValueError("no demos found")
        self.demos = demos
        self.env = Environment()
        self.table = AirTable(self.env.size_px[0] / self.env.base_px_per_m, self.env.view_height_m)
        self.local = Client(name="local", color=LOCAL_COLOR)
        self.clients = [self.local]  # index 0 is the local user; the server adds players
        self.window = GameWindow(self.env, headless=headless)
        self.painter = AidsPainter(self.window)
        if not headless:
            pygame.mouse.set_visible(False)  # the local client's arrow is the pointer
        self.server = server
        self.running = True
        self.paused = False
        self.show_help = False
        self.trails = False
        self.speed = 1.0
        self.show_annotations = False
        self.vectors = 0  # 0 off, 1 velocity, 2 momentum
        self.show_chart = False
        self.show_notes = False
        self.inspecting = False
        self.collision_log = aids.CollisionLog()
        self.chart = aids.EnergyChart()
        self.notice: list[str] = [f"could not load {e}" for e in demo_errors]
        self.keys_down: set[int] = set()
        self.mouse_px = (self.env.size_px[0] / 2, self.env.size_px[1] / 2)
        self.mouse_button = 0
        self.panning = False
        self.fps = 0.0
        self._frame_times: deque[float] = deque()
        self.accumulator_s = 0.0
        self.message = ""
        self.message_until = 0.0
        self.clock_s = 0.0  # real time the app has run (sum of frame times)
        self._dispatch = {k: b for b in BINDINGS for k in b.keys}
        self.build_error: DemoError | None = None  # shown instead of the demo while set
        self.start_demo(demo_key if demo_key in demos else next(iter(demos)), variation)

    # ------------------------------------------------------------ demos

    @property
    def demo(self) -> Demo:
        return self.demos[self.demo_key]

    def start_demo(self, key: str, variation: int = 0) -> None:
        """Clear the table and build demo `key` (a demo that fails shows its error)."""
        demo = self.demos[key]
        if self.build_error is not None:
            self.paused = False  # the pause came with the error; a new start runs
        self.demo_key = key
        self.variation = variation % len(demo.variations) if demo.variations else 0
        self.table.clear()
        self.table.reset_settings()
        for client in self.clients:
            client.held = None
        self.build_error = None
        try:
            demo.build(self.table, self.variation)
        except Exception as exc:  # a teacher's demo may fail in any way; the app goes on
            self.build_error = self._demo_error(exc)
            self.table.clear()
        self.dt_s = demo.dt_s
        self.trails = demo.trails
        self.accumulator_s = 0.0
        self.window.clear_trails()
        self.collision_log.clear()
        self.chart.clear()
        self.chart.sample(self.table)
        self.window.set_caption(f"Air Table - {demo.label(self.variation)}")

    def _demo_error(self, exc: BaseException) -> DemoError:
        """Where in the current demo's file `exc` happened (its build or a timed event)."""
        return error_from_exception(self.demo.path or Path(f"demo {self.demo_key}"), exc)

    def key_demo(self, event: pygame.event.Event) -> None:
        digit = DIGIT_KEYS.index(event.key)
        key = str((digit + 1) % 10)
        if _shift_held(event):
            key += "p"
        if key in self.demos:
            self.start_demo(key)
        else:
            self.say(f"no demo on key {key_label(key)}")

    def key_variation(self, event: pygame.event.Event) -> None:
        if not self.demo.variations:
            self.say("this demo has no variations")
            return
        step = 1 if event.key == pygame.K_RIGHT else -1
        self.start_demo(self.demo_key, self.variation + step)

    def key_page(self, event: pygame.event.Event) -> None:
        keys = list(self.demos)
        step = 1 if event.key == pygame.K_PAGEDOWN else -1
        self.start_demo(keys[(keys.index(self.demo_key) + step) % len(keys)])

    # ------------------------------------------------------------ controls

    def key_pause(self, event) -> None:
        self.paused = not self.paused

    def key_single_step(self, event) -> None:
        if self.paused:
            self.physics_step()
        else:
            self.say("'.' steps once while paused (Space pauses)")

    def key_freeze(self, event) -> None:
        self.table.vel_mps[:] = 0.0

    def key_gravity(self, event) -> None:
        self.table.gravity_on = not self.table.gravity_on
        restitution = 0.9 if self.table.gravity_on else 1.0
        self.table.cr_puck = self.table.cr_wall = restitution

    def key_correction(self, event) -> None:
        self.table.puck_correction = "two-step" if self.table.puck_correction == "off" else "off"

    def key_perfect_kiss(self, event) -> None:
        self.table.puck_correction = "two-step" if self.table.puck_correction == "perfect-kiss" else "perfect-kiss"

    def hold_zoom(self, key: int, frame_dt_s: float) -> None:
        rate = ZOOM_RATE_PER_S if key == pygame.K_h else -ZOOM_RATE_PER_S
        self.zoom(math.exp(rate * frame_dt_s))

    def zoom(self, factor: float) -> None:
        self.env.zoom_about(self.mouse_px, factor)
        self.window.clear_trails()

    def key_reset_view(self, event) -> None:
        self.env.reset()
        self.window.clear_trails()

    def key_trails(self, event) -> None:
        self.trails = not self.trails
        self.window.clear_trails()

    def key_slow_motion(self, event) -> None:
        factors = aids.SLOW_MOTION_FACTORS
        self.speed = factors[(factors.index(self.speed) + 1) % len(factors)] if self.speed in factors else 1.0

    def key_reverse(self, event) -> None:
        self.table.vel_mps[:] *= -1.0
        self.say("time reversed: every velocity flipped")

    def key_annotations(self, event) -> None:
        self.show_annotations = not self.show_annotations
        self.collision_log.clear()

    def key_vectors(self, event) -> None:
        self.vectors = (self.vectors + 1) % 3

    def key_chart(self, event) -> None:
        self.show_chart = not self.show_chart

    def key_notes(self, event) -> None:
        self.show_notes = not self.show_notes

    def hold_inspect(self, key: int, frame_dt_s: float) -> None:
        self.inspecting = True

    def key_help(self, event) -> None:
        self.show_help = not self.show_help

    def key_screenshot(self, event) -> None:
        path = Path("screenshots") / time.strftime("airtable-%Y%m%d-%H%M%S.png")
        try:
            saved = self.window.save_screenshot(path)
        except (OSError, pygame.error) as exc:
            self.say(f"could not save the screenshot: {exc}")
        else:
            self.say(f"screenshot saved to {saved.resolve()}")

    def key_quit(self, event) -> None:
        self.running = False

    def say(self, text: str) -> None:
        """Show a one-line message on screen for a few seconds."""
        self.message = text
        self.message_until = self.clock_s + MESSAGE_S

    # ------------------------------------------------------------ input

    def handle_event(self, event: pygame.event.Event) -> None:
        if event.type == pygame.QUIT:
            self.running = False
        elif event.type == pygame.KEYDOWN:
            self.notice = []  # any key dismisses the start-up notice
            self.keys_down.add(event.key)
            binding = self._dispatch.get(event.key)
            if binding is not None and not binding.held:
                getattr(self, binding.action)(event)
        elif event.type == pygame.KEYUP:
            self.keys_down.discard(event.key)
        elif event.type == pygame.MOUSEMOTION:
            if self.panning:
                self.env.pan(event.rel)
                self.window.clear_trails()
            self.mouse_px = event.pos
        elif event.type == pygame.MOUSEBUTTONDOWN and event.button in (1, 2, 3):
            self.mouse_px = event.pos
            if _ctrl_held(self.keys_down):
                self.panning = True
            else:
                self.mouse_button = event.button
        elif event.type == pygame.MOUSEBUTTONUP and event.button in (1, 2, 3):
            self.mouse_px = event.pos
            self.panning = False
            if event.button == self.mouse_button:
                self.mouse_button = 0
        elif event.type == pygame.MOUSEWHEEL:
            self.zoom(WHEEL_ZOOM**event.y)

    def _update_local_client(self) -> None:
        # Recomputed every frame: zooming moves the world under a still mouse.
        held = frozenset(pygame.key.name(k) for k in self.keys_down)
        self.local.set_input(self.table, self.env.to_world(self.mouse_px), self.mouse_button, held)

    # ------------------------------------------------------------ loop

    def physics_step(self) -> None:
        if self.server is not None:
            self.server.apply_inputs(self.clients, self.table)
        try:
            self.table.step(self.dt_s, cursor_pulls(self.clients))
        except Exception as exc:  # a demo's timed event (teacher's code) failed
            self.build_error = self._demo_error(exc)
            self.paused = True
            return
        self.chart.sample(self.table)
        if self.show_annotations:
            self.collision_log.add(self.table, self.clock_s)

    def frame(self, frame_dt_s: float) -> None:
        """One frame: input, as many fixed physics steps as time allows, drawing."""
        self.clock_s += frame_dt_s
        for event in pygame.event.get():
            self.handle_event(event)
        self.inspecting = False
        for key in self.keys_down:
            binding = self._dispatch.get(key)
            if binding is not None and binding.held:
                getattr(self, binding.action)(key, frame_dt_s)
        self._update_local_client()
        if not self.paused:
            self.accumulator_s += frame_dt_s * self.speed
            max_steps = max(1, int(MAX_SIM_PER_FRAME_S / self.dt_s))
            steps = 0
            while self.accumulator_s >= self.dt_s and steps < max_steps:
                self.physics_step()
                self.accumulator_s -= self.dt_s
                steps += 1
            if steps == max_steps:
                self.accumulator_s = min(self.accumulator_s, self.dt_s)
        # Frames counted over the last second: steadier than 1 / dt of one frame.
        self._frame_times.append(self.clock_s)
        while self._frame_times[0] < self.clock_s - 1.0:
            self._frame_times.popleft()
        span = self._frame_times[-1] - self._frame_times[0]
        if span > 0:
            self.fps = (len(self._frame_times) - 1) / span
        self.draw()

    def scene(self) -> Scene:
        return Scene.from_table(
            self.table,
            self.clients,
            title=self.demo.label(self.variation),
            status=self.status_line(),
            fps=self.fps,
            zoom=self.env.zoom,
            origin_m=(float(self.env.origin_m[0]), float(self.env.origin_m[1])),
        )

    def status_line(self) -> str:
        t = self.table
        parts = []
        if self.paused:
            parts.append("PAUSED")
        if self.speed != 1.0:
            parts.append(f"slow motion x1/{round(1 / self.speed)}")
        parts.append("gravity on" if t.gravity_on else "gravity off")
        parts.append(f"correction: {t.puck_correction}")
        parts.append(f"restitution: pucks {t.cr_puck:g}, walls {t.cr_wall:g}")
        parts.append(f"{len(t.pos_m)} pucks")
        parts.append(f"{t.collision_count} collisions")
        parts.append(f"t = {t.time_s:.2f} s")
        parts.append("F1: help")
        return "   ".join(parts)

    def hud_lines(self) -> list[str]:
        lines = []
        if self.server is not None:
            lines.extend(self.server.join_lines())
        if self.message and self.clock_s < self.message_until:
            lines.append(self.message)
        return lines

    def draw(self) -> None:
        scene = self.scene()
        self.window.draw(scene, trails=self.trails, hud=self.hud_lines())
        self.draw_aids()
        error = self.build_error
        if self.notice:
            self.window.draw_panel("Some demo files could not be loaded", [*self.notice, "Press any key to go on."])
        elif error is not None:
            self.window.draw_panel(
                f"Demo {self.demo_key} could not be built", [str(error), "Fix the file and press its key again."]
            )
        elif self.show_help:
            self.window.draw_panel(
                "Keys", [(b.label, b.help) for b in BINDINGS], side_title="Demos", side_rows=self._demo_rows()
            )
        elif self.show_notes:
            self.window.draw_panel(self.demo.label(self.variation), [self.demo.notes or "(no notes)"], large=True)
        if self.server is not None:
            self.server.publish(scene)
        self.window.present()

    def draw_aids(self) -> None:
        t, paint = self.table, self.painter
        if self.show_annotations:
            for annotation in self.collision_log.live(self.clock_s):
                paint.annotation(annotation, self.clock_s)
        if self.vectors and len(t.pos_m):
            self._draw_vectors()
        if self.show_chart:
            note = self.chart.euler_wiggle_note(t)
            paint.energy_chart(self.chart.series(), self.chart.latest(), note)
        if self.inspecting:
            puck = t.puck_at(self.env.to_world(self.mouse_px))
            if puck is not None:
                v = puck.vel_mps
                speed = float(np.hypot(*v))
                paint.inspector(
                    puck.pos_m,
                    [
                        f"mass {puck.mass_kg:.4g} kg   radius {puck.radius_m:.4g} m",
                        f"speed {speed:.4g} m/s",
                        f"velocity ({v[0]:.3f}, {v[1]:.3f}) m/s",
                        f"kinetic energy {0.5 * puck.mass_kg * speed**2:.4g} J",
                    ],
                )

    def _draw_vectors(self) -> None:
        t, paint = self.table, self.painter
        if self.vectors == 1:
            name, unit, values, color = "velocity", "m/s", t.vel_mps, (120, 220, 255)
        else:
            name, unit, values, color = "momentum", "N s", t.vel_mps * t.mass_kg[:, None], (230, 120, 230)
        amount, m_per_unit = aids.nice_scale(float(np.hypot(values[:, 0], values[:, 1]).max()), target_m=1.0)
        paint.arrows(t.pos_m, values * m_per_unit, color)
        legend = [(f"{name}: an arrow 1 m long is {amount:g} {unit}", color)]
        # The centre of mass moves in a straight line while no outside force acts.
        com, com_v = t.center_of_mass_m(), t.center_of_mass_vel_mps()
        speed, m_per_mps = aids.nice_scale(float(np.hypot(t.vel_mps[:, 0], t.vel_mps[:, 1]).max()), target_m=1.0)
        paint.arrow(com, com_v * m_per_mps, COM_COLOR, width=3)
        paint.marker(com, COM_COLOR, f"centre of mass, {np.hypot(*com_v):.2f} m/s")
        held = self.local.held
        if held is not None and held.alive:
            forces = t.forces_on(held, self.dt_s, cursor_pulls(self.clients))
            if forces:
                biggest = max(float(np.hypot(*f)) for f in forces.values())
                newtons, m_per_n = aids.nice_scale(biggest, target_m=1.5)
                for source, f in forces.items():
                    c = FORCE_COLORS[source]
                    paint.arrow(held.pos_m, f * m_per_n, c, width=3)
                    legend.append((f"force, {source}: {np.hypot(*f):.3g} N", c))
                legend.append((f"forces: an arrow 1 m long is {newtons / 1.5:.3g} N", DIM_FORCE))
        paint.legend(legend)

    def _demo_rows(self) -> list[tuple[str, str]]:
        rows = []
        for key, demo in self.demos.items():
            rows.append((key_label(key), demo.title))
        return rows

    def run(self, seconds: float | None = None, max_frames: int | None = None, frame_dt_s: float | None = None) -> None:
        """Run until Esc / window close, `seconds` of real time or `max_frames` frames.

        `frame_dt_s` fixes each frame's time step instead of reading the clock
        (tests use it, so they never depend on timing).
        """
        clock = pygame.time.Clock()
        start = time.monotonic()
        frames = 0
        clock.tick()
        while self.running:
            if frame_dt_s is None:
                dt = min(clock.tick(MAX_FPS) / 1000.0, 0.25)
            else:
                dt = frame_dt_s
            self.frame(dt)
            frames += 1
            if max_frames is not None and frames >= max_frames:
                break
            if seconds is not None and time.monotonic() - start >= seconds:
                break
