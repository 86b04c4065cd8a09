"""What the keys and the mouse do in the teacher's app.

App-level keys first, demo keys second: `BINDINGS` is the one key table; it
drives both the dispatch and the F1 help screen (and README's table). Each
action is a function of the app alone, `action(app)`; a row with no actions
only documents a key handled elsewhere (the mouse, the demo keys). A key that
the table does not take, typed as a digit or a letter, picks a demo
(`demo_key_for`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import pygame

from airtable.app import lessons, predict, rewind, room, world
from airtable.model import aids
from airtable.physics.pairs import CORRECTION_MODES

if TYPE_CHECKING:
    from airtable.app.app import App

Action = Callable[["App"], None]

ZOOM_RATE_PER_S = 1.5  # held h / n: zoom factor e**1.5 per second
WHEEL_ZOOM = 1.1


@dataclass(frozen=True)
class Binding:
    """One row of the key table: its label and help text, and what each of its keys does."""

    label: str
    help: str
    # A key is a pygame key, or (modifier mask, key) for a key pressed with Ctrl or Shift.
    actions: Mapping[int | tuple[int, int], Action] = field(default_factory=dict)
    held: bool = False  # acts every frame while held, not on the press

    @property
    def keys(self) -> tuple[int, ...]:
        return tuple(self.actions)


# Number row and keypad digits, in the order 1..9, 0.
DIGIT_KEYS = (*(getattr(pygame, f"K_{d}") for d in "1234567890"),)
KEYPAD_KEYS = (*(getattr(pygame, f"K_KP_{d}") for d in "1234567890"),)


# ---------------------------------------------------------------- actions


def toggle_pause(app: App) -> None:
    if not predict.pause_key(app):  # a prediction round decides what Space does while it is under way
        app.paused = not app.paused


def freeze(app: App) -> None:
    app.table.vel_mps[:] = 0.0


def toggle_gravity(app: App) -> None:
    t = app.table
    t.gravity_on = not t.gravity_on
    t.cr_puck = t.cr_wall = 0.9 if t.gravity_on else 1.0


def toggle_correction(app: App) -> None:
    """The next correction mode: off, two-step, perfect kiss, off, ..."""
    modes = CORRECTION_MODES
    t = app.table
    t.puck_correction = modes[(modes.index(t.puck_correction) + 1) % len(modes)]


def toggle_perfect_kiss(app: App) -> None:
    t = app.table
    t.puck_correction = "two-step" if t.puck_correction == "perfect-kiss" else "perfect-kiss"


def zoom_in(app: App) -> None:
    app.zoom(math.exp(ZOOM_RATE_PER_S * app.frame_dt_s))


def zoom_out(app: App) -> None:
    app.zoom(math.exp(-ZOOM_RATE_PER_S * app.frame_dt_s))


def reset_view(app: App) -> None:
    app.env.reset()
    app.window.clear_trails()


def toggle_trails(app: App) -> None:
    app.trails = not app.trails
    app.window.clear_trails()


def next_slow_motion(app: App) -> None:
    factors = aids.SLOW_MOTION_FACTORS
    app.speed = factors[(factors.index(app.speed) + 1) % len(factors)] if app.speed in factors else 1.0


def reverse_time(app: App) -> None:
    app.table.vel_mps[:] *= -1.0
    app.say("time reversed: every velocity flipped")


def toggle_annotations(app: App) -> None:
    app.show_annotations = not app.show_annotations
    app.collision_log.clear()


def next_vectors(app: App) -> None:
    app.vectors = (app.vectors + 1) % 3


def toggle_chart(app: App) -> None:
    app.show_chart = not app.show_chart


def toggle_notes(app: App) -> None:
    app.show_notes = not app.show_notes


def inspect(app: App) -> None:
    app.inspecting = True


def toggle_help(app: App) -> None:
    """F1: help; again for its next page, if it has more than one; then closed."""
    if not app.show_help:
        app.show_help, app.help_page = True, 0
    else:
        app.help_page += 1
        app.show_help = app.help_page < app.help_pages
        app.help_page = app.help_page if app.show_help else 0


def toggle_fullscreen(app: App) -> None:
    app.window.toggle_fullscreen()


def move_chart(app: App) -> None:
    app.show_chart = True
    app.say(f"energy chart: {app.painter.cycle_chart_corner()}")


def resize_chart(app: App) -> None:
    app.show_chart = True
    app.painter.toggle_chart_size()


def open_menu(app: App) -> None:
    app.open_menu()


def screenshot(app: App) -> None:
    app.save_screenshot()


def escape(app: App) -> None:
    app.escape()


def previous_variation(app: App) -> None:
    app.next_variation(-1)


def next_variation(app: App) -> None:
    app.next_variation(+1)


def previous_demo(app: App) -> None:
    app.next_demo(-1)


def next_demo(app: App) -> None:
    app.next_demo(+1)


BINDINGS: tuple[Binding, ...] = (
    Binding("1-9, 0", "start (again: restart) that demo"),
    Binding("Shift+1/2/3", "correction comparison: off, two-step, perfect kiss"),
    Binding("Tab", "demo menu: every demo; arrows and Enter, or type its key", {pygame.K_TAB: open_menu}),
    Binding(
        "Left / Right", "previous / next variation", {pygame.K_LEFT: previous_variation, pygame.K_RIGHT: next_variation}
    ),
    Binding(
        "PageUp / PageDown", "previous / next demo", {pygame.K_PAGEUP: previous_demo, pygame.K_PAGEDOWN: next_demo}
    ),
    Binding("Space", "pause / resume", {pygame.K_SPACE: toggle_pause}),
    Binding(
        ", / .",
        "rewind / on a frame (Shift: 1 s)",
        {
            pygame.K_COMMA: rewind.step_back,
            pygame.K_PERIOD: rewind.step_forward,
            (pygame.KMOD_SHIFT, pygame.K_COMMA): rewind.jump_back,
            (pygame.KMOD_SHIFT, pygame.K_PERIOD): rewind.jump_forward,
        },
    ),
    Binding("f", "freeze: all velocities to zero", {pygame.K_f: freeze}),
    Binding("g", "gravity on/off (restitution 0.9 with gravity, 1.0 without)", {pygame.K_g: toggle_gravity}),
    Binding("p", "correction: off, two-step, perfect kiss in turn", {pygame.K_p: toggle_correction}),
    Binding("z", "perfect kiss on/off", {pygame.K_z: toggle_perfect_kiss}),
    Binding("h / n (hold)", "zoom in / out about the cursor", {pygame.K_h: zoom_in, pygame.K_n: zoom_out}, held=True),
    Binding("mouse wheel", "zoom in / out about the cursor"),
    Binding("Ctrl + mouse drag", "pan the view"),
    Binding("q", "reset the view", {pygame.K_q: reset_view}),
    Binding("mouse buttons 1 / 2 / 3", "grab a puck with the medium / soft / stiff cursor string"),
    Binding("e", "trails: stop erasing, so each frame's pucks stay on screen", {pygame.K_e: toggle_trails}),
    Binding("s", "slow motion: 1, 1/2, 1/4, 1/8, 1/16 of real time", {pygame.K_s: next_slow_motion}),
    Binding("r", "reverse time: flip every velocity", {pygame.K_r: reverse_time}),
    Binding("a", "collision annotations: axes, overlap, separation, angle", {pygame.K_a: toggle_annotations}),
    Binding("v", "vectors: velocity / momentum arrows, forces, centre of mass", {pygame.K_v: next_vectors}),
    Binding("c", "energy and momentum chart", {pygame.K_c: toggle_chart}),
    Binding(
        "m / b", "chart: move to the next corner / big or small", {pygame.K_m: move_chart, pygame.K_b: resize_chart}
    ),
    Binding("i (hold)", "inspect the puck under the cursor", {pygame.K_i: inspect}, held=True),
    Binding("l", "lecture notes for this demo", {pygame.K_l: toggle_notes}),
    Binding(
        "u / w",
        "restitution of pucks / walls down a tenth (with Shift: up)",
        {
            pygame.K_u: world.puck_restitution_down,
            (pygame.KMOD_SHIFT, pygame.K_u): world.puck_restitution_up,
            pygame.K_w: world.wall_restitution_down,
            (pygame.KMOD_SHIFT, pygame.K_w): world.wall_restitution_up,
        },
    ),
    Binding(
        "Shift+g",
        "gravity: off, Moon 1.62, Mars 3.71, Earth 9.8 m/s²",
        {(pygame.KMOD_SHIFT, pygame.K_g): world.cycle_gravity},
    ),
    Binding(
        "- / =, [ / ]",
        "mass, radius of the puck under the cursor: down / up",
        {
            pygame.K_MINUS: world.mass_down,
            pygame.K_KP_MINUS: world.mass_down,
            pygame.K_EQUALS: world.mass_up,
            pygame.K_PLUS: world.mass_up,
            pygame.K_KP_PLUS: world.mass_up,
            pygame.K_LEFTBRACKET: world.radius_down,
            pygame.K_RIGHTBRACKET: world.radius_up,
        },
    ),
    Binding(
        "d / t / k",
        "momenta before / after the latest collision; values of each puck; puck numbers",
        {pygame.K_d: lessons.toggle_momenta, pygame.K_t: lessons.toggle_values, pygame.K_k: lessons.toggle_numbers},
    ),
    Binding(
        "x / Ctrl+S",
        "export the recording as CSV; save the moment as a new demo (s1, s2, ...)",
        {pygame.K_x: lessons.export_recording, (pygame.KMOD_CTRL, pygame.K_s): lessons.save_moment},
    ),
    Binding(
        "F6",
        "predict, then reveal",
        {pygame.K_F6: predict.predict_key, (pygame.KMOD_SHIFT, pygame.K_F6): predict.toggle_names},
    ),
    # F2-F5 share F1's row: the help must fit one page on a 900 x 788 window; the roster panel
    # (F2) and the HUD's "3 students (F2: roster)" name them in full.
    Binding(
        "F1",
        "this help screen (again: next page); F2-F5: the room",
        {
            pygame.K_F1: toggle_help,
            pygame.K_F2: room.toggle_roster,
            pygame.K_F3: room.toggle_hands_off,
            pygame.K_F4: room.next_floor,
            pygame.K_F5: room.toggle_anonymous,
        },
    ),
    Binding("F11", "fullscreen on / off", {pygame.K_F11: toggle_fullscreen}),
    Binding("F12", "save a screenshot PNG", {pygame.K_F12: screenshot}),
    Binding("Esc", "close what is open (the newest first); else asks: Esc again quits", {pygame.K_ESCAPE: escape}),
)

PRESS_ACTIONS: dict[int, Action] = {
    k: a for b in BINDINGS if not b.held for k, a in b.actions.items() if isinstance(k, int)
}
MODIFIED_ACTIONS: dict[tuple[int, int], Action] = {
    k: a for b in BINDINGS for k, a in b.actions.items() if isinstance(k, tuple)
}
HELD_ACTIONS: dict[int, Action] = {k: a for b in BINDINGS if b.held for k, a in b.actions.items()}
# Keys the roster panel takes while it is open (documented in BINDINGS above).
ROSTER_KEYS: dict[int, Action] = {
    pygame.K_UP: lambda app: room.move_selection(app, -1),
    pygame.K_DOWN: lambda app: room.move_selection(app, +1),
    pygame.K_DELETE: room.remove_selected,
    pygame.K_BACKSPACE: room.remove_selected,
}


def demo_key_for(event: pygame.event.Event) -> str | None:
    """The demo key a KEYDOWN names: a digit of the number row or keypad, with Shift adding "p"."""
    digits = DIGIT_KEYS if event.key in DIGIT_KEYS else KEYPAD_KEYS if event.key in KEYPAD_KEYS else None
    if digits is None:
        return None
    key = "1234567890"[digits.index(event.key)]
    return key + "p" if event.mod & pygame.KMOD_SHIFT else key


# ---------------------------------------------------------------- events


def modified_action(event: pygame.event.Event) -> Action | None:
    """The action of a key pressed with Ctrl or Shift (Ctrl+S), if the key table has one."""
    mod = getattr(event, "mod", 0)
    for (mask, key), action in MODIFIED_ACTIONS.items():
        if key == event.key and mod & mask:
            return action
    return None


def handle_key(app: App, event: pygame.event.Event) -> None:
    """A KEYDOWN: an open panel takes it first, then the key table, then the demo keys."""
    app.keys_down.add(event.key)
    if app.take_key_for_overlay(event):
        return
    roster_action = ROSTER_KEYS.get(event.key) if app.panel() == "roster" else None
    if roster_action is not None:
        roster_action(app)
        return
    action = modified_action(event) or PRESS_ACTIONS.get(event.key)
    if action is not None:
        action(app)
        return
    key = demo_key_for(event)
    if key is not None:
        app.press_demo_key(key)


def run_held(app: App) -> None:
    """Every frame: the actions of the keys held down (zoom, inspect)."""
    app.inspecting = False
    for key in list(app.keys_down):
        action = HELD_ACTIONS.get(key)
        if action is not None:
            action(app)


def handle_mouse(app: App, event: pygame.event.Event) -> None:
    if event.type == pygame.MOUSEMOTION:
        if app.panning:
            app.env.pan(event.rel)
            app.window.clear_trails()
        app.mouse_px = event.pos
    elif event.type == pygame.MOUSEWHEEL:
        app.zoom(WHEEL_ZOOM**event.y)
    elif event.button in (1, 2, 3):
        app.mouse_px = event.pos
        if event.type == pygame.MOUSEBUTTONDOWN and app.panel() == "roster" and room.click(app, event.pos):
            return  # a row of the roster was picked, not a puck
        if event.type == pygame.MOUSEBUTTONDOWN:
            # Ctrl comes from the key events the app saw, never from a global read.
            if app.keys_down & {pygame.K_LCTRL, pygame.K_RCTRL}:
                app.panning = True
            else:
                app.mouse_button = event.button
                # Grab where the button went down: a press and a quick move can share one frame.
                app.local.set_input(app.table, app.env.to_world(event.pos), event.button)
        else:
            app.panning = False
            if event.button == app.mouse_button:
                app.mouse_button = 0


MOUSE_EVENTS = (pygame.MOUSEMOTION, pygame.MOUSEBUTTONDOWN, pygame.MOUSEBUTTONUP, pygame.MOUSEWHEEL)


def handle_event(app: App, event: pygame.event.Event) -> None:
    if event.type == pygame.QUIT:
        app.close_window()
    elif event.type == pygame.KEYDOWN:
        handle_key(app, event)
    elif event.type == pygame.KEYUP:
        app.keys_down.discard(event.key)
    elif event.type in MOUSE_EVENTS and not predict.take_mouse(app, event):
        handle_mouse(app, event)
    elif event.type in (pygame.VIDEORESIZE, pygame.WINDOWSIZECHANGED):
        app.window.handle_event(event)  # the table and the type follow the new size
