"""The teacher runs the room (`Room`): the roster of students, removing one, hands off,
the floor passed around, an anonymous projector, and who can join.

The rules that decide whose cursor acts live on the server (`GameServer.hands_off`,
`GameServer.floor`, `GameServer.may_act`), applied where students' inputs
reach the game loop. This feature keeps the teacher's side: what the keys do,
the roster panel's selection (drawn by roster_view.py), and the words the
projector and the students see. Students learn of hands off and the floor from the status line that
every snapshot carries: its part `HANDS_OFF` puts a banner on their windows
(`student_banner`), and `floor: C3 Ann` says whose turn it is.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import pygame

from airtable.app.feature import Binding, Feature
from airtable.app.overlays import OverlayFlag
from airtable.app.roster_view import ALERT_COLOR, draw_roster
from airtable.model.scene import Scene

if TYPE_CHECKING:
    from airtable.app.host import Host
    from airtable.model.seats import Seat

HANDS_OFF = "HANDS OFF"  # a status part: every student's window shows HANDS_OFF_BANNER
HANDS_OFF_BANNER = "hands off: the teacher is explaining"
FLOOR_PREFIX = "floor: "
REMOVE_CONFIRM_S = 4.0  # the second Delete within this time removes the student
REMOVED_SENTENCE = "the teacher removed you from the table"


def student_banner(scene: Scene, me: str = "") -> str | None:
    """The line across a student's window that the teacher's status line asks for, if any."""
    return HANDS_OFF_BANNER if HANDS_OFF in scene.status_parts else None


def anonymous_label(name: str) -> str:
    """ "C3 Ann" -> "C3": the player's id alone."""
    return name.split(" ", 1)[0]


class Room(Feature):
    """The teacher's side of running the room (`app.room`)."""

    show_roster = OverlayFlag("roster")
    draw_order = 5  # a panel, over everything

    def __init__(self, host: Host, server_problem: str | None = None) -> None:
        super().__init__(host)
        self.server_problem = server_problem  # why students cannot join, when the server did not start
        self.selected = 0  # row of the roster panel
        self.anonymous = False  # names hidden on the projector (colours stay)
        self.remove_armed: tuple[int, float] | None = None  # (player number, clock_s until which Delete removes)
        self.row_boxes: list[tuple[int, pygame.Rect]] = []  # (number, box) drawn last frame
        self.panel_box: pygame.Rect | None = None  # the roster panel as last drawn

    def label(self, name: str) -> str:
        """A player's name as the projector shows it."""
        return anonymous_label(name) if self.anonymous else name

    def projected(self, scene: Scene) -> Scene:
        """The scene as the teacher's window draws it: students' names hidden when anonymous."""
        if not self.anonymous or not scene.cursors:
            return scene
        cursors = tuple(dataclasses.replace(c, name=anonymous_label(c.name)) for c in scene.cursors)
        return dataclasses.replace(scene, cursors=cursors)

    def seats(self) -> list[Seat]:
        server = self.host.server
        return server.roster() if server is not None else []

    # ------------------------------------------------------------ what the windows show

    def alert(self) -> str | None:
        """Why students cannot join, if they cannot: the server did not start, or its thread failed."""
        server = self.host.server
        return server.failure if server is not None else self.server_problem

    def hud_lines(self) -> list:
        """Why students cannot join and who was turned away (in red), the join line and the player count."""
        server = self.host.server
        alerts = [self.alert(), server.door_notice if server is not None else None]
        lines: list = [(alert, ALERT_COLOR) for alert in alerts if alert]  # first: a narrow band keeps the first
        if server is not None:
            n, away = server.player_count, len(server.away())
            gone = f", {away} away" if away else ""  # (their seats are held: they were vanishing from the count)
            count = f"{n} student{'' if n == 1 else 's'}{gone} (F2: roster)"
            # Under an alert, a narrow band folds the first lines into one and keeps the last whole: the
            # join line last then, or late students lose it (a user test: the count stayed, the join line went).
            lines.extend([count, *server.join_lines()] if lines else [*server.join_lines(), count])
        return lines

    def status_parts(self, for_students: bool) -> list[str]:
        """Hands off and the floor, for the status line every window shows."""
        server = self.host.server
        if server is None:
            return []
        parts = [HANDS_OFF] if server.hands_off else []
        if server.floor is not None:
            seat = next((s for s in self.seats() if s.number == server.floor), None)
            if seat is None:  # the student with the floor left
                server.floor = None
                self.host.say("the student with the floor left: everyone's cursor acts again")
            else:
                parts.append(FLOOR_PREFIX + self.label(seat.name))
        return parts

    def draw(self) -> None:
        if self.overlays.panel() != "roster":
            return
        server = self.host.server
        most = server.max_clients if server is not None else 0
        seats, window = self.seats(), self.host.window
        away = [(self.label(name), s) for name, s in server.away()] if server is not None else []
        self.row_boxes, self.panel_box = draw_roster(
            window, seats, selected=self.selected, label=self.label, most=most, anonymous=self.anonymous, away=away
        )

    # ------------------------------------------------------------ keys and clicks

    def _need_server(self) -> bool:
        if self.host.server is None:
            self.host.say("no students: the table runs without its server (--no-server)")
            return False
        return True

    def toggle_roster(self) -> None:
        if self._need_server():
            self.show_roster = not self.show_roster
            self.remove_armed = None

    def toggle_hands_off(self) -> None:
        if self._need_server():
            server = self.host.server
            server.hands_off = not server.hands_off
            self.host.say("hands off: students' cursors let go" if server.hands_off else "students' cursors act again")

    def next_floor(self) -> None:
        """The floor to the next student in seat order; after the last, back to everyone."""
        if not self._need_server():
            return
        server = self.host.server
        numbers = [s.number for s in self.seats()]
        later = [n for n in numbers if server.floor is None or n > server.floor]
        server.floor = later[0] if later else None
        if server.floor is None:
            self.host.say("the floor is back to everyone" if numbers else "no students to give the floor to")

    def toggle_anonymous(self) -> None:
        self.anonymous = not self.anonymous
        self.host.say("names hidden on the projector" if self.anonymous else "names shown on the projector")

    def move_selection(self, step: int) -> None:
        n = len(self.seats())
        self.selected = min(max(0, self.selected + step), max(0, n - 1))
        self.remove_armed = None

    def selected_seat(self) -> Seat | None:
        seats = self.seats()
        if not seats:
            return None
        self.selected = min(self.selected, len(seats) - 1)
        return seats[self.selected]

    def remove_selected(self) -> None:
        """Delete: arm the removal of the selected student; Delete again within a few seconds removes them."""
        seat = self.selected_seat()
        if seat is None:
            return
        name, now = self.label(seat.name), self.host.clock_s
        if self.remove_armed is not None and self.remove_armed[0] == seat.number and now < self.remove_armed[1]:
            self.remove_armed = None
            if self.host.server.remove(seat.number):
                self.host.say(f"removed {name}")
            return
        self.remove_armed = (seat.number, now + REMOVE_CONFIRM_S)
        self.host.say(f"press Delete again to remove {name}")

    def click(self, pos: tuple[int, int]) -> bool:
        """A click on the roster panel selects the row under it; True if the panel took the click."""
        for number, rect in self.row_boxes:
            if rect.collidepoint(pos):
                numbers = [s.number for s in self.seats()]
                if number in numbers:
                    self.selected = numbers.index(number)
                    self.remove_armed = None
                return True
        return self.panel_box is not None and self.panel_box.collidepoint(pos)

    def handle_event(self, event: pygame.event.Event) -> bool:
        """While the roster is open: Up / Down / Delete, and clicks on it (not on the pucks beneath)."""
        if self.overlays.panel() != "roster":
            return False
        if event.type == pygame.KEYDOWN and event.key in ROSTER_KEYS:
            ROSTER_KEYS[event.key](self)
            return True
        if event.type == pygame.MOUSEBUTTONDOWN and event.button in (1, 2, 3) and self.click(event.pos):
            self.host.mouse_px = event.pos
            return True
        return False

    # F2-F5 share F1's row (panels.py documents them): the help must fit one page on a 900 x 788
    # window; the roster panel (F2) and the HUD's "3 students (F2: roster)" name them in full.
    bindings = (
        Binding(
            "F1",
            actions={
                pygame.K_F2: toggle_roster,
                pygame.K_F3: toggle_hands_off,
                pygame.K_F4: next_floor,
                pygame.K_F5: toggle_anonymous,
            },
        ),
    )


# Keys the roster panel takes while it is open (its hints say so).
ROSTER_KEYS = {
    pygame.K_UP: lambda room: room.move_selection(-1),
    pygame.K_DOWN: lambda room: room.move_selection(+1),
    pygame.K_DELETE: Room.remove_selected,
    pygame.K_BACKSPACE: Room.remove_selected,
}
