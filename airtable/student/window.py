"""The student's window: the teacher's table from snapshots, this student's cursor drawn at once.

`PlayerApp` draws the snapshots with the same `GameWindow` as the teacher's
window and draws its own cursor locally, so the student's arrow follows the
mouse without network delay; `NetPlayer` (airtable/net/player.py) brings the
snapshots. A sibling of the teacher's app (airtable/app/app.py).
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time
from collections.abc import Callable, Sequence

import numpy as np

from airtable.app.controls import by_position
from airtable.app.loop import IdlingLoop, signals_end_the_run
from airtable.app.overlays import EscapeBurst
from airtable.app.panel_view import next_page
from airtable.app.predict import StudentGuesses
from airtable.app.predict_view import paint_round
from airtable.app.pucks_view import draw_numbers
from airtable.app.room import student_banner
from airtable.model.scene import CursorView, Scene
from airtable.model.shared_aids import NOTES
from airtable.model.student_aids import LOCAL_KEYS
from airtable.net import protocol as proto
from airtable.net.player import TABLE_CLOSED, NetPlayer, PlayerState, empty_scene

# Once nothing has moved on the table (pucks, cursors) and this window had no input for
# IDLE_AFTER_S, it draws IDLE_FPS frames a second instead of its full rate, waking at once on
# input: a still table leaves a student's laptop quiet, and motion shows within 1 / IDLE_FPS.
IDLE_FPS = 20.0
IDLE_AFTER_S = 1.0
LEAVE_CONFIRM_S = 4.0  # a second Esc within this time leaves the table
LEAVE_QUESTION = "Esc again to leave the table; any other key to stay"
# Drawing budgets for one frame (see fit_drawing_budget).
MAX_PUCK_AREA_SCREENS = 40.0
MAX_PUCK_LOOKS = 1024
MAX_SPRING_SPAN_PX = 20_000_000


def joined_sentence(address: str, welcome: proto.Welcome, back: bool = False) -> str:
    """What the terminal says once a student is at the table (at the start, after a wait, or `back`)."""
    if back:
        return f"airtable-client: back at the table at {address}; you are {welcome.label}"
    return f"airtable-client: connected to {address}; you are {welcome.label}"


def lost_sentence(address: str, closed: bool) -> str:
    """What the terminal says when a student's connection ends and the client tries again."""
    if closed:
        return f"airtable-client: the teacher closed the table at {address}; waiting for it to open again"
    return f"airtable-client: lost the connection to {address}; reconnecting (your seat is kept)"


class PlayerApp:
    """The pygame window of a player: the server's table from snapshots, our cursor drawn locally."""

    def __init__(self, net: NetPlayer, headless: bool = False, fps: float = 60.0) -> None:
        self.net = net
        self.headless = headless
        self.fps = fps
        self.window = None  # the GameWindow, once run() has opened it
        self.env = None
        self.frames = 0
        self.states_seen: set[PlayerState] = set()  # connection states shown, for tests
        self.draw_error: str | None = None  # the first drawing error, reported once
        self.button = 0
        self.keys: set[str] = set()
        self.show_help = False  # F1: the keys of this window, on pages in a small one
        self.help_page, self.help_pages = 0, 1
        # The teacher's notes, while the teacher shows them: on pages in a small window (L turns them), and
        # hidden on this window after the last page, till L again or the teacher's next notes.
        self.show_notes, self.notes_page, self.notes_pages = True, 0, 1
        self._notes: str | None = None  # the notes last shown, to start new ones at their first page
        self.leave_asked_until = -math.inf  # time.monotonic() until which a second Esc leaves
        self._escapes = EscapeBurst()
        self.ended: str | None = None  # why the session ended for good, shown until a key is pressed
        self.status = 0  # what run() returns: 1 once the session ended for good
        self.painter = None  # the AidsPainter, once the window is open
        self.lessons_painter = None  # the LessonsPainter (momenta, values) and
        self.timeline_painter = None  # the TimelinePainter, likewise
        self._drawn_from: tuple = ()  # the restarts and view the trails were drawn in
        self._welcome: proto.Welcome | None = None
        self._last_state: PlayerState | None = None  # the connection's state at the last frame
        self.predicting = StudentGuesses()  # our arrows in a prediction round
        self._motion: tuple = ()  # what moves, as the last frame showed it (see note_motion)
        self._moved_s = -math.inf  # when it last changed
        self._pointer: tuple = ((), (), None)  # the last frame's pointer (px), view and point on the table

    def run(
        self, seconds: float | None = None, screenshot: str | None = None, until: Callable[[], bool] | None = None
    ) -> int:
        """The UI loop; returns the process exit status (1 when the connection failed for good, 2 when
        the table refused our --name).

        Ends after `seconds`, or after the frame in which `until()` is true, or
        when the user quits. Closes the connection when it ends, but leaves
        pygame running (main() quits it)."""
        self._open_window()
        self.status = 0
        loop = IdlingLoop(self.fps, IDLE_FPS, lambda: self.still(time.monotonic()), self.headless)
        try:
            with signals_end_the_run(loop.stop.set):
                loop.run(lambda dt_s: self._frame_running(loop, until), max_time_s=seconds)
        except KeyboardInterrupt:
            pass
        finally:
            if screenshot:
                self.window.save_screenshot(screenshot)
            self.net.close(bye=True)
        return self.status

    def _frame_running(self, loop: IdlingLoop, until: Callable[[], bool] | None) -> bool:
        """One frame of the window's loop; False to end it."""
        import pygame

        if not self._handle_events(pygame.event.get()):
            return False
        if self.net.state == PlayerState.FAILED and self.ended is None:
            print(f"airtable-client: {self.net.error}", file=sys.stderr)
            # A refused argument (a name the teacher's font lacks a letter of) is status 2, as a bad argument is.
            self.status = 2 if self.net.error_about else 1
            self.ended = self.net.error or "the session ended"
            if self.headless:
                return False  # nobody to read it: the line above says it
        self._frame()
        loop.after_frame()
        return until is None or not until()

    def _pointer_on_the_table(self, env) -> np.ndarray:
        """Where our pointer is on the table. While we hold a puck, a view that changed under a still pointer
        (the teacher zoomed or reset the view, our window was resized) moves the pointer with the table:
        left where it was on the screen, it came to another point of the table and the string yanked the
        puck there."""
        import pygame

        pointer = pygame.mouse.get_pos()
        view = (env.zoom, tuple(env.origin_m), tuple(env.size_px), tuple(env.offset_px))
        last_pointer, last_view, last_m = self._pointer
        if self.button and view != last_view and pointer == last_pointer and last_m is not None:
            pointer = self.window.put_pointer_on(last_m)
        cursor_m = env.to_world(np.array(pointer, dtype=float))
        self._pointer = (pointer, view, cursor_m)
        return cursor_m

    def note_motion(self, scene: Scene, cursor_m: np.ndarray, now_s: float) -> None:
        """Remember what moves in this frame: the pucks, every cursor, our own input."""
        motion = (scene.pos_m.tobytes(), scene.cursors, tuple(cursor_m.tolist()), self.button, frozenset(self.keys))
        if motion != self._motion:
            self._motion, self._moved_s = motion, now_s

    def still(self, now_s: float) -> bool:
        """Nothing has moved, and no input came, for IDLE_AFTER_S: the window may draw less often."""
        return now_s - self._moved_s >= IDLE_AFTER_S

    def _open_window(self) -> None:
        import pygame

        from airtable.app.window import GameWindow, LessonsPainter, TimelinePainter

        self._welcome = self.net.welcome
        from airtable.app.aids_paint import AidsPainter

        self.window = GameWindow(self._new_env(), caption=self._caption(), headless=self.headless)
        self.painter = AidsPainter(self.window)
        self.lessons_painter = LessonsPainter(self.window)
        self.timeline_painter = TimelinePainter(self.window)
        if not self.headless:
            pygame.mouse.set_visible(False)  # our arrow, drawn each frame, is the pointer

    def _table_size(self) -> tuple[float, float]:
        w = self._welcome
        return (w.width_m, w.height_m) if w is not None else proto.DEFAULT_TABLE_SIZE_M

    def _new_env(self):
        from airtable.app.environment import DEFAULT_SIZE_PX, Environment

        self.env = Environment(DEFAULT_SIZE_PX, width_m=self._table_size()[0])
        return self.env

    def _caption(self) -> str:
        return f"Air Table - {self._welcome.label}" if self._welcome else "Air Table - joining"

    def _handle_events(self, events) -> bool:
        """Mouse buttons and keys; False when the user quits (window closed or Esc)."""
        import pygame

        for event in map(by_position, events):  # letters of any layout, where they sit on the keyboard
            if event.type == pygame.QUIT:
                return False  # the window's close button: the student meant it
            if self.window.handle_event(event):  # a resize, or F11: fullscreen on or off
                if event.type == pygame.KEYDOWN:  # F11: the window moves under the pointer: let go of the puck
                    self.button = 0
                continue
            if event.type == pygame.KEYDOWN and not self._window_key(event.key):
                return False
            if event.type == pygame.KEYDOWN and (event.key == pygame.K_ESCAPE or self._local_key(event.key)):
                continue  # this window's own keys: the server never hears of them
            if not self._predict_event(event):
                self._table_input(event)
        return True

    def _window_key(self, key: int) -> bool:
        """A key for the window itself first: False to close it (the session ended and was read,
        or Esc twice)."""
        import pygame

        if self.ended is not None:
            return False
        return self._answer_leave(key == pygame.K_ESCAPE)

    def _table_input(self, event) -> None:
        """Keys held and the mouse button: what the server hears."""
        import pygame

        if event.type == pygame.KEYDOWN:
            self.keys.add(pygame.key.name(event.key))
        elif event.type == pygame.KEYUP:
            self.keys.discard(pygame.key.name(event.key))
        elif event.type == pygame.MOUSEBUTTONDOWN and event.button in (1, 2, 3):
            self.button = event.button
        elif event.type == pygame.MOUSEBUTTONUP and event.button == self.button:
            held = pygame.mouse.get_pressed(3)
            self.button = next((b for b in (1, 2, 3) if held[b - 1]), 0)

    def _answer_leave(self, escape: bool) -> bool:
        """A key while the window may be asking whether to leave; False to leave now.

        Esc closes the help or the teacher's notes if open, else asks; Esc again while asked leaves.
        Any other key while asked: stay."""
        asked, now = self.leave_asked_until > time.monotonic(), time.monotonic()
        self.leave_asked_until = -math.inf
        if not escape:
            return True
        deliberate = self._escapes.deliberate(now)  # a burst of Escs does not answer (overlays.py)
        if asked and deliberate:  # (first: the question covers the notes the teacher may have shown since)
            return False
        if self.show_help:
            self.show_help, self.help_page = False, 0
        elif self._notes_shown():
            self.show_notes, self.notes_page = False, 0
        else:
            self.leave_asked_until = now + LEAVE_CONFIRM_S
        return True

    def _local_key(self, key: int) -> bool:
        """F1 and the aids a student turns on or off for their own window; True if `key` was one."""
        import pygame

        name = pygame.key.name(key)
        if name == "f1":
            self.show_help, self.help_page = next_page(self.show_help, self.help_page, self.help_pages)
        elif name == "l" and self._notes is not None:
            self.show_notes, self.notes_page = next_page(self._notes_shown(), self.notes_page, self.notes_pages)
        elif name in LOCAL_KEYS:
            self.net.aids.toggle(name)
            if name == "e":
                self.window.clear_trails()
        else:
            return False
        return True

    def _follow_restarts(self, scene: Scene) -> None:
        """A demo (re)start or another view: trails and arrow scales start afresh, as on the teacher's window."""
        drawn_from = (self.net.aids.restarts, scene.zoom, scene.origin_m)
        if drawn_from != self._drawn_from:
            if self._drawn_from and drawn_from[0] != self._drawn_from[0]:
                self.painter.new_demo()
            self._drawn_from = drawn_from
            self.window.clear_trails()

    def _predict_event(self, event) -> bool:
        """While a round is open, button 1 on a puck drags our arrow; letting go sends PREDICT."""
        import pygame

        if self.env is None or event.type not in (pygame.MOUSEBUTTONDOWN, pygame.MOUSEMOTION, pygame.MOUSEBUTTONUP):
            return False
        info, guesses = self.net.round, self.predicting
        point = self.env.to_world(np.asarray(event.pos, dtype=float))
        if event.type == pygame.MOUSEBUTTONDOWN:
            scene = self.net.latest()
            radius = scene.radius_m if scene is not None else ()
            return event.button == 1 and guesses.press(info, point, radius)
        guessed = guesses.drag(info, point)
        if guessed is not None and event.type == pygame.MOUSEBUTTONUP:
            guesses.dragging = None
            self.net.send_predict(*guessed)
        return guessed is not None

    def _say_when_lost(self) -> None:
        """A connection that ended is said on the terminal too (a user test: it said only "connected" again
        on the way back), once each time."""
        state = self.net.state
        if state is PlayerState.RETRYING and self._last_state is PlayerState.CONNECTED:
            print(lost_sentence(self.net.address, self.net.waiting_because == TABLE_CLOSED), flush=True)
        self._last_state = state

    def _follow_welcome(self) -> None:
        """After a (re)connect: the new name in the caption, the new table size in the view."""
        welcome = self.net.welcome
        if welcome is None or welcome is self._welcome:
            return
        old_width = self._table_size()[0]
        back, self._welcome = self._welcome is not None, welcome
        # The terminal's last word was a wait or a retry (a user test: joined, and it never said so).
        print(joined_sentence(self.net.address, welcome, back), flush=True)
        self.window.set_caption(self._caption())
        if welcome.width_m != old_width:  # the teacher restarted with another table
            self.window.set_env(self._new_env())

    def _frame(self) -> None:
        import pygame

        from airtable.app.environment import MAX_ZOOM, MIN_ZOOM

        net, env = self.net, self.env
        self._say_when_lost()
        self._follow_welcome()
        scene = net.smooth() or empty_scene(*self._table_size())
        # The teacher's view: the student sees what the projector shows.
        env.zoom = min(max(scene.zoom, MIN_ZOOM), MAX_ZOOM)
        env.origin_m = np.array(scene.origin_m, dtype=float)
        cursor_m = self._pointer_on_the_table(env)
        net.update_input(cursor_m, self.button, self.keys)
        self.note_motion(scene, cursor_m, time.monotonic())
        self.states_seen.add(net.state)
        self.frames += 1
        try:
            self._draw(fit_drawing_budget(scene, env), cursor_m, bool(pygame.mouse.get_focused()))
        except Exception as exc:  # a scene this window cannot draw must not end the student's session
            if self.draw_error is None:
                self.draw_error = f"{type(exc).__name__}: {exc}"
                print(f"airtable-client: could not draw a frame ({self.draw_error}); carrying on", file=sys.stderr)

    def _draw(self, scene: Scene, cursor_m: np.ndarray, focused: bool) -> None:
        from airtable.student.aids_view import STUDENT_KEYS, draw_student_aids, draw_student_lessons

        net, win, welcome = self.net, self.window, self._welcome
        me = welcome.label if welcome else ""
        color = welcome.color if welcome else (200, 200, 200)
        others, mine = own_cursor_live(scene.cursors, me, color, cursor_m, self.button, focused)
        self._follow_restarts(scene)
        win.draw(
            dataclasses.replace(scene, cursors=others),
            trails=net.aids.shows("e"),
            hud=(f"You are {me}" if me else "Not at the table yet", net.status_text, *self._view_hint(scene)),
            hud_color=color,
        )
        draw_student_lessons(self.lessons_painter, self.timeline_painter, scene, net.aids, cursor_m)
        draw_student_aids(self.painter, scene, net.aids, time.monotonic(), cursor_m)
        if net.aids.shows("k") and len(scene.pos_m):  # "puck 3" of a reveal's summary, found on the table
            draw_numbers(win.surface, win.label_font, win.env.to_screen(scene.pos_m))
        self._draw_round(color)
        if mine is not None:  # over the aids (a user test: our name lay under the chart)
            win.draw_cursor_view(scene, mine)
        banner = net.banner_text or student_banner(scene, me)
        if banner:  # over our cursor too: "reconnecting ..." must read whole
            win.draw_banner(banner)
        if self.ended is not None:
            win.draw_panel("The session has ended", [self.ended, "Press any key to close this window."])
        elif self.leave_asked_until > time.monotonic():
            win.draw_question("Leave the table?", [LEAVE_QUESTION])
        elif self.show_help:
            self.help_pages = win.draw_panel("Keys", list(STUDENT_KEYS), page=self.help_page, page_key="F1")
        elif self._notes_shown():
            self.notes_pages = win.draw_panel(
                scene.title, [net.aids.notes], large=True, page=self.notes_page, page_key="L"
            )
        win.present()

    def _notes_shown(self) -> bool:
        """Whether this window shows the teacher's notes: while the teacher shows them, unless the student
        hid them (L after their last page, or Esc); new notes show again, at their first page."""
        aids = self.net.aids
        notes = aids.notes if aids.teacher & NOTES else None
        if notes != self._notes:
            self._notes, self.show_notes, self.notes_page = notes, True, 0
        return notes is not None and self.show_notes

    def _view_hint(self, scene: Scene) -> tuple[str, ...]:
        """A line when the teacher's view shows none of the table (zoomed or panned away)."""
        if self.window.wall_rects((scene.width_m, scene.height_m)):
            return ()
        return ("the teacher's view shows none of the table just now",)

    def _draw_round(self, color) -> list:
        """The prediction round, if one is under way; returns the lines of text written and where."""
        info = self.net.round
        self.predicting.follow(info)
        if info is None or info.state == "closed":
            return []
        count = f"{info.predicted} of {info.players} predicted"
        # The aids' painter: its labels and these lines avoid each other.
        return paint_round(self.painter, info, self.predicting.guesses, color, count)


def fit_drawing_budget(scene: Scene, env) -> Scene:
    """The scene cut down, if needed, so that one frame stays cheap to draw.

    A server could send thousands of pucks or springs each as big as the
    window, or every puck in its own colour; drawing them would take minutes a
    frame. Honest scenes are far inside these budgets and come back unchanged:
    - pucks in view cover the window at most MAX_PUCK_AREA_SCREENS times over,
      and none is drawn wider than the window's diagonal;
    - at most MAX_PUCK_LOOKS distinct colours (beyond that, colours are rounded);
    - springs span at most MAX_SPRING_SPAN_PX pixels in all (the longest go
      first), and so do cursor strings.
    """
    changes: dict = {}
    if len(scene.radius_m):
        changes.update(_fit_pucks(scene, env))
    if len(scene.spring_pairs):
        changes.update(_fit_springs(scene, env))
    if scene.cursors:
        changes.update(_fit_cursor_strings(scene, env))
    return dataclasses.replace(scene, **changes) if changes else scene


def _fit_pucks(scene: Scene, env) -> dict:
    w, h = env.size_px
    px_per_m = float(env.length_to_px(1.0))
    r_px = scene.radius_m * px_per_m
    centers = env.to_screen(scene.pos_m)
    visible = (
        (centers[:, 0] + r_px >= 0)
        & (centers[:, 0] - r_px <= w)
        & (centers[:, 1] + r_px >= 0)
        & (centers[:, 1] - r_px <= h)
    )
    changes: dict = {}
    colors = scene.color_rgb
    if len(np.unique(colors[visible], axis=0)) > MAX_PUCK_LOOKS:
        changes["color_rgb"] = (colors & 0xE0) | 0x10  # 512 colours at most
    area_px = float(np.minimum(np.pi * r_px[visible] ** 2, w * h).sum())
    budget_px = MAX_PUCK_AREA_SCREENS * w * h
    largest_m = math.hypot(w, h) / px_per_m
    if area_px > budget_px or float(scene.radius_m.max()) > largest_m:
        shrink = math.sqrt(budget_px / area_px) if area_px > budget_px else 1.0
        changes["radius_m"] = np.minimum(scene.radius_m, largest_m) * shrink
    return changes


def _fit_springs(scene: Scene, env) -> dict:
    d = scene.pos_m[scene.spring_pairs[:, 0]] - scene.pos_m[scene.spring_pairs[:, 1]]
    # Drawing a spring costs about its length in pixels, even where it is off screen.
    span_px = (np.abs(d[:, 0]) + np.abs(d[:, 1])) * float(env.length_to_px(1.0))
    if float(span_px.sum()) <= MAX_SPRING_SPAN_PX:
        return {}
    order = np.argsort(span_px, kind="stable")
    keep = np.sort(order[np.cumsum(span_px[order]) <= MAX_SPRING_SPAN_PX])
    return {
        "spring_pairs": scene.spring_pairs[keep],
        "spring_length_m": scene.spring_length_m[keep],
        "spring_width_m": scene.spring_width_m[keep],
        "spring_color_rgb": scene.spring_color_rgb[keep],
    }


def _fit_cursor_strings(scene: Scene, env) -> dict:
    held = [i for i, c in enumerate(scene.cursors) if 0 <= c.held < len(scene.pos_m)]
    if not held:
        return {}
    ends = np.array([scene.cursors[i].cursor_m for i in held]) - scene.pos_m[[scene.cursors[i].held for i in held]]
    span_px = (np.abs(ends[:, 0]) + np.abs(ends[:, 1])) * float(env.length_to_px(1.0))
    if float(span_px.sum()) <= MAX_SPRING_SPAN_PX:
        return {}
    order = np.argsort(span_px, kind="stable")
    dropped = {held[i] for i in order[np.cumsum(span_px[order]) > MAX_SPRING_SPAN_PX]}
    cursors = tuple(dataclasses.replace(c, held=-1) if i in dropped else c for i, c in enumerate(scene.cursors))
    return {"cursors": cursors}


def own_cursor_live(
    cursors: Sequence[CursorView], me: str, color, cursor_m: Sequence[float], button: int, focused: bool
) -> tuple[tuple[CursorView, ...], CursorView | None]:
    """The snapshot's other cursors, and ours (None: we have no seat) moved to where the mouse is now.

    Our cursor in a snapshot is a round trip old; drawing it at the live mouse
    position (and last, over the aids) makes the arrow and its string follow the hand
    without delay. Before the snapshots have it, it is the arrow alone, in our `color`.
    """
    others = tuple(c for c in cursors if c.name != me)
    mine = next((c for c in cursors if c.name == me), None)
    if not focused or not me:  # the mouse is in another window: show what the server has
        return others, mine
    live = (float(cursor_m[0]), float(cursor_m[1]))
    if mine is None:
        return others, CursorView(me, tuple(color), live, button)
    return others, dataclasses.replace(mine, cursor_m=live, button=button)
