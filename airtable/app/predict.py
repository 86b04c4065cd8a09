"""Predict, then reveal: a round of peer instruction on the shared table.

The `Predict` feature owns the round; one key (F6, `predict_key`) steps it along:

    none -> open      the table freezes; students (and the local mouse) drag
                      arrows from pucks: the velocity each puck will have once
                      the coming collision is over; the projector shows only a count
    open -> revealed  every guess is drawn thin in its student's colour and the
                      table plays; once the collision is over (no collision for
                      SETTLE_S after at least one, or TIMEOUT_S) it freezes, the
                      true velocities are drawn bold and a summary per puck printed
    revealed -> none  the round closes; the table runs, or stays paused, as it did
                      when the round opened

The guesses live in the server's PredictionBook (airtable/net/predictions.py)
and in the round's `local`; nothing in them reaches the physics. `summarize`
is the maths of the summary: angles between guess and truth, and speed ratios.
The drawing is predict_view.py's, the same on the students' windows.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
import pygame

from airtable.app.feature import Binding, Feature
from airtable.app.predict_view import paint_round
from airtable.model.momenta import puck_number
from airtable.model.rounds import ARROW_S, MAX_ROUND_PUCKS, Arrow, RoundInfo, clamp_speed

if TYPE_CHECKING:
    from airtable.app.host import Host
    from airtable.app.room import Room

SETTLE_S = 0.3  # table time with no collision after which the collision is over
TIMEOUT_S = 8.0  # table time after which the reveal freezes anyway
WITHIN_DEG = 5.0  # "within 5 deg"
WITHIN_SPEED = 0.2  # "speeds within 20 %"
RESTING_MPS = 0.05  # a true speed below this: the puck stops, and direction means nothing
STILL_MPS = 1e-4  # every puck slower than this a step after the reveal: nothing is coming (a drop from rest is not)
LOCAL_LABEL = "teacher"
LOCAL_COLOR = (120, 255, 120)


def angle_deg(a: Sequence[float], b: Sequence[float]) -> float:
    """The angle between two vectors, 0 to 180 degrees (180 if either is zero)."""
    na, nb = math.hypot(*a), math.hypot(*b)
    if na == 0.0 or nb == 0.0:
        return 180.0
    cos = (a[0] * b[0] + a[1] * b[1]) / (na * nb)
    return math.degrees(math.acos(min(1.0, max(-1.0, cos))))


def puck_summary(puck: int, truth: Sequence[float], guesses: Sequence[Sequence[float]]) -> str:
    """One line: how far the guesses for `puck` spread from its true velocity."""
    n = len(guesses)
    label = f"puck {puck_number(puck)}"
    speed = math.hypot(*truth)
    if n == 0:
        return f"{label}: no predictions"
    if speed < RESTING_MPS:
        still = sum(1 for g in guesses if math.hypot(*g) < RESTING_MPS)
        return f"{label}: comes to rest; {still} of {n} predicted under {RESTING_MPS:g} m/s"
    off = [angle_deg(g, truth) for g in guesses]
    near = sum(1 for d in off if d <= WITHIN_DEG)
    speeds = sum(1 for g in guesses if abs(math.hypot(*g) - speed) <= WITHIN_SPEED * speed)
    return (
        f"{label}: median {float(np.median(off)):.0f} deg off; {near} of {n} within {WITHIN_DEG:g} deg; "
        f"speeds within {WITHIN_SPEED * 100:.0f} %: {speeds} of {n}"
    )


def summarize(truth: Sequence[Sequence[float]], arrows: Sequence[Arrow]) -> list[str]:
    """A line per puck that someone predicted, in puck order."""
    by_puck: dict[int, list[tuple[float, float]]] = {}
    for a in arrows:
        if a.puck < len(truth):
            by_puck.setdefault(a.puck, []).append(a.vel_mps)
    return [puck_summary(p, truth[p], by_puck[p]) for p in sorted(by_puck)]


class PredictRound:
    """The round's state on the teacher's side (`Predict.round`)."""

    def __init__(self) -> None:
        self.round_id = 0
        self.state = "closed"  # "open", "revealed", "closed" (no round)
        self.pucks = 0
        self.from_m: tuple[tuple[float, float], ...] = ()  # where the pucks stood when the round opened
        self.show_names = False  # labels on the revealed arrows (Shift+F6)
        self.names_sent = False  # whether the last ROUND carried names
        self.local: dict[int, tuple[float, float]] = {}  # the local mouse's guesses
        self.dragging: int | None = None  # the puck whose arrow the local mouse drags
        self.arrows: tuple[Arrow, ...] = ()
        self.truth: tuple[tuple[float, float], ...] = ()
        self.summary: tuple[str, ...] = ()
        self.players = 0
        self.predicted = 0
        self._hits = 0
        self._last_hit_s = 0.0
        self._started_s = 0.0
        self._quiet_until_s = 0.0
        self._seen_collision = False

    @property
    def active(self) -> bool:
        return self.state != "closed"

    @property
    def settled(self) -> bool:
        """Revealed and the collision is over: the truth is known."""
        return self.state == "revealed" and bool(self.truth)

    def open(self, pos_m: np.ndarray) -> None:
        self.round_id += 1
        self.state, self.pucks = "open", min(len(pos_m), MAX_ROUND_PUCKS)
        self.from_m = tuple((float(x), float(y)) for x, y in pos_m[: self.pucks])
        self.local, self.dragging = {}, None
        self.arrows, self.truth, self.summary = (), (), ()

    def reveal(self, arrows: Sequence[Arrow], table) -> None:
        local = [Arrow(p, v, LOCAL_COLOR, LOCAL_LABEL) for p, v in sorted(self.local.items())]
        self.arrows = tuple(arrows) + tuple(local)
        self.state, self.dragging = "revealed", None
        self._hits, self._started_s = table.collision_count, table.time_s
        self._last_hit_s, self._seen_collision = table.time_s, False
        throw = table.timed.next_s()  # a demo's throw to come (see collision_over); inf: none
        self._quiet_until_s = throw if math.isfinite(throw) else table.time_s

    def close(self) -> None:
        self.state, self.dragging = "closed", None

    def collision_over(self, table) -> bool:
        """Called while the revealed table plays: True once it should freeze."""
        if table.collision_count != self._hits:
            self._hits, self._last_hit_s, self._seen_collision = table.collision_count, table.time_s, True
        quiet = table.time_s - self._last_hit_s >= SETTLE_S
        # A table still a step after the reveal, and after the demo's next timed event (its throw), has no
        # collision to come (user tests: "playing until the collision is over" for 8 s over pucks at rest;
        # opened before demo 9's throw, the reveal froze before it, at t = 0.18 s).
        started = table.time_s > max(self._started_s, self._quiet_until_s)
        still = started and not np.any(np.abs(table.vel_mps) >= STILL_MPS)
        return (self._seen_collision and quiet) or still or table.time_s - self._started_s >= TIMEOUT_S

    def settle(self, table) -> None:
        """Freeze on the truth: every predictable puck's velocity now, and the summary."""
        n = min(self.pucks, len(table.vel_mps))
        self.truth = tuple((float(v[0]), float(v[1])) for v in table.vel_mps[:n])
        self.summary = tuple(summarize(self.truth, self.arrows))

    def info(self, predicted: int, players: int, names: bool = False) -> RoundInfo:
        """What the ROUND message says now (arrows only after the reveal; their labels only with `names`)."""
        shown = self.state == "revealed"
        return RoundInfo(
            self.round_id,
            self.state,
            self.pucks,
            predicted,
            players,
            tuple(a if names else replace(a, label="") for a in self.arrows) if shown else (),
            self.truth if shown else (),
            self.summary if shown else (),
            self.from_m,
        )

    def guess_from_drag(self, puck_pos_m: Sequence[float], mouse_m: Sequence[float]) -> tuple[float, float]:
        """The velocity an arrow dragged from the puck to the mouse stands for."""
        return clamp_speed(((mouse_m[0] - puck_pos_m[0]) / ARROW_S, (mouse_m[1] - puck_pos_m[1]) / ARROW_S))


# ---------------------------------------------------------------- the teacher's side

FROZEN_NOTICE = "the table stays frozen while students predict: F6 reveals"
ESC_AGAIN_S = 3.0  # while students guess, a second Esc within this ends the round (s)


class Predict(Feature):
    """Predict, then reveal, on the teacher's window (`app.predict`): the keys, the students' count, the freeze."""

    draw_order = 3  # over the aids

    def __init__(self, host: Host, room: Room) -> None:
        super().__init__(host)
        self.room = room  # an anonymous projector hides the names on the arrows
        self.round = PredictRound()
        self._end_asked_until = -math.inf  # (clock_s) until when a second Esc ends an open round
        self._paused_before = False  # whether the table was paused when the round opened

    def _book(self):
        server = self.host.server
        return getattr(server, "predictions", None) if server is not None else None

    def _counts(self) -> tuple[int, int]:
        """(who predicted, of how many): the students, plus the local mouse once it predicted."""
        book = self._book()
        students = self.host.student_count()
        predicted = book.count() if book is not None else 0
        if self.round.local:
            return predicted + 1, students + 1
        return predicted, students

    def count_text(self) -> str:
        predicted, players = self._counts()
        return f"{predicted} of {players} predicted"

    def status_parts(self, for_students: bool) -> list[str]:
        """The round in the status line; the teacher's keys only on the teacher's window."""
        r = self.round
        if r.state == "open":
            return [f"PREDICT: {self.count_text()}" + ("" if for_students else " (F6 reveals)")]
        if r.settled:
            return ["REVEALED" + ("" if for_students else " (F6 closes the round)")]
        return ["REVEALED: playing until the collision is over"] if r.active else []

    def publish(self) -> None:
        """Tell the students where the round is (a ROUND message to each)."""
        book = self._book()
        if book is None:
            return
        r = self.round
        r.predicted, r.players = self._counts()
        r.names_sent = self.names_shown()
        info = r.info(r.predicted, r.players, r.names_sent)
        if info.state == "open" and book.accepts() != (info.round_id, info.pucks):
            book.open(info.round_id, info.pucks)
        elif info.state != "open":
            book.set_state(info.state)
        self.host.server.send_round(info)

    def predict_key(self) -> None:
        """The round key: open a round, reveal it, close it."""
        r, host = self.round, self.host
        if r.state == "closed":
            if not len(host.table.pos_m):
                host.say("no pucks on the table to predict")
                return
            r.open(host.table.pos_m)
            self._paused_before, host.paused = host.paused, True
            # The class predicts from the pucks: the notes, over the table, close (a user test: with them open
            # neither the teacher's window nor the students' showed the pucks or the PREDICT lines).
            notes = " (the notes closed: L shows them)" if host.overlays.close("notes") else ""
            host.say(f"prediction round open: F6 again reveals{notes}")
        elif r.state == "open":
            book = self._book()
            r.reveal(book.arrows() if book is not None else (), host.table)
            host.paused = False  # after_physics keeps everyone's strings off until the collision is over
            # (a user test: "prediction round open" stayed over a bar saying REVEALED)
            host.say("revealed (F6 again closes the round)")  # (it plays, then stands still: no verb that lapses)
        else:
            self._end("prediction round closed")  # (it tells the students)
            return
        self.publish()

    def _end(self, said: str) -> None:
        """Close the round (_close) and say so, and whether the table runs, as the status line's PAUSED does."""
        self._close()
        after = "paused, as before the round (Space runs on)" if self._paused_before else "the table runs on"
        self.host.say(f"{said}: {after}")

    def _close(self) -> None:
        """Close the round, tell the students, and leave the table as it was when the round opened (a user
        test: a running table stayed paused after F6, F6, F6)."""
        self.round.close()
        self.publish()
        self.host.paused = self._paused_before

    def on_escape(self) -> bool:
        """Esc during a round ends it, as closing an overlay would, leaving the table running or paused as
        before the round. While the students guess, only a second Esc within ESC_AGAIN_S does (one Esc
        threw every guess away)."""
        if not self.round.active:
            return False
        if self.round.state == "open" and self.host.clock_s > self._end_asked_until:
            self._end_asked_until = self.host.clock_s + ESC_AGAIN_S
            self.host.say("Esc again ends the prediction round, and the students' guesses go (F6 reveals)")
            return True
        self._end("prediction round closed (Esc)")
        return True

    def pause_key(self) -> bool:
        """Space during a round; True if the round took it (else Space pauses and resumes as always).

        Open: refused with a notice, since the table is what the students predict.
        Revealed and frozen on the truth: the lesson goes on, so the round closes and
        the table runs. While the reveal plays, Space pauses and resumes it as usual."""
        r = self.round
        if r.state == "open":
            self.host.say(FROZEN_NOTICE)
            return True
        if r.settled:
            r.close()
            self.publish()
            self.host.paused = False
            self.host.say("prediction round closed: the table runs on")
            return True
        return False

    def holds(self) -> bool:
        """True while the round needs the table as it is: open, or revealed and still playing."""
        r = self.round
        return r.state == "open" or (r.state == "revealed" and not r.settled)

    def holds_the_table(self) -> bool:
        """True, and says why, while the round holds the table (`holds`): the rewind keys leave it alone."""
        if not self.holds():
            return False
        if self.round.state == "open":
            self.host.say(FROZEN_NOTICE)
        else:
            self.host.say("the reveal plays until the collision is over; then , and . step through it")
        return True

    def names_shown(self) -> bool:
        """Names on the revealed arrows: only when the teacher shows them (Shift+F6),
        and never while the projector is anonymous (F5, room.py)."""
        return self.round.show_names and not self.room.anonymous

    def toggle_names(self) -> None:
        """Shift+F6: names on the revealed arrows, here and on the students' windows."""
        r = self.round
        r.show_names = not r.show_names
        self.host.say(f"prediction names {'shown' if r.show_names else 'hidden'}")

    def on_demo_start(self, table) -> None:
        """A new demo: a round under way ends with it, and the table runs or not as before the round."""
        if self.round.active:
            self._close()

    def before_physics(self) -> None:
        """While the reveal plays nobody's string holds a puck, so the truth is what the guesses were about."""
        if self.round.state == "revealed" and not self.round.truth:
            for client in self.host.clients:
                client.release()

    def after_physics(self) -> None:
        """Freeze the reveal once the collision is over; keep the students' count fresh."""
        r, host = self.round, self.host
        if r.state == "revealed" and not r.truth and not host.paused and r.collision_over(host.table):
            host.paused = True
            r.settle(host.table)
            self.publish()
        elif r.state == "open" and self._counts() != (r.predicted, r.players):
            self.publish()
        elif r.state == "revealed" and self.names_shown() != r.names_sent:  # F5 (anonymous) or Shift+F6
            self.publish()

    def handle_event(self, event: pygame.event.Event) -> bool:
        """While a round is open the local mouse drags prediction arrows, not pucks; True if it took `event`."""
        r, host = self.round, self.host
        if r.state != "open" or event.type not in (pygame.MOUSEBUTTONDOWN, pygame.MOUSEMOTION, pygame.MOUSEBUTTONUP):
            return False
        host.mouse_px = event.pos
        where = host.env.to_world(np.asarray(event.pos, dtype=float))
        if event.type == pygame.MOUSEBUTTONDOWN and event.button == 1:
            puck = host.table.puck_at(where)
            if puck is not None and puck.index < r.pucks:
                r.dragging = puck.index
        elif r.dragging is not None and event.type != pygame.MOUSEBUTTONDOWN:
            r.local[r.dragging] = r.guess_from_drag(host.table.pos_m[r.dragging], where)
            if event.type == pygame.MOUSEBUTTONUP:
                r.dragging = None
                self.after_physics()
        return True

    def draw(self) -> None:
        self.paint()

    def paint(self) -> list[tuple[str, pygame.Rect]]:
        """The round on the projector: a count while open, everything once revealed; returns the lines
        of text written and where. The volunteer at the teacher's laptop sees their own arrows; the
        students' stay hidden until the reveal."""
        r = self.round
        if not r.active:
            return []
        info = r.info(r.predicted, r.players, self.names_shown())
        return paint_round(self.host.painter, info, r.local, LOCAL_COLOR, self.count_text())

    bindings = (
        Binding(
            "F6", "predict, then reveal", {pygame.K_F6: predict_key, (pygame.KMOD_SHIFT, pygame.K_F6): toggle_names}
        ),
    )


# ---------------------------------------------------------------- a student's side


class StudentGuesses:
    """A student's own arrows in the round the server announced (the player window keeps one)."""

    def __init__(self) -> None:
        self.round_id = 0
        self.guesses: dict[int, tuple[float, float]] = {}
        self.dragging: int | None = None

    def follow(self, info: RoundInfo | None) -> None:
        """A new round starts with no arrows."""
        if info is not None and info.round_id != self.round_id:
            self.round_id, self.guesses, self.dragging = info.round_id, {}, None
        if info is None or info.state != "open":
            self.dragging = None

    def press(self, info: RoundInfo | None, point_m: Sequence[float], radius_m: Sequence[float]) -> bool:
        """Button 1 at `point_m`: start an arrow if it is on a predictable puck (True: taken)."""
        self.follow(info)
        if info is None or info.state != "open":
            return False
        for puck in range(min(len(info.from_m), len(radius_m)) - 1, -1, -1):  # the top one first
            x, y = info.from_m[puck]
            if math.hypot(point_m[0] - x, point_m[1] - y) <= radius_m[puck]:
                self.dragging = puck
                return True
        return False

    def drag(self, info: RoundInfo | None, point_m: Sequence[float]) -> tuple[int, tuple[float, float]] | None:
        """The mouse moved (or let go) while dragging: (puck, velocity) now guessed, else None."""
        self.follow(info)
        if self.dragging is None or info is None:
            return None
        x, y = info.from_m[self.dragging]
        vel = clamp_speed(((point_m[0] - x) / ARROW_S, (point_m[1] - y) / ARROW_S))
        self.guesses[self.dragging] = vel
        return self.dragging, vel
