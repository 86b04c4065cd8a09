"""Students see the teacher's lesson panels: the momenta diagram, the values panel and the rewind
timeline travel in the AIDS frame (format 2), are checked on decode, and draw on the student's window
with the teacher's numbers."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, WAIT_S, press, server_frames, teacher_and_student, wait_until
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from airtable.app.app import App
from airtable.app.demo_loader import BUILTIN_DIR, DemoShelf
from airtable.app.environment import DEFAULT_SIZE_PX, Environment
from airtable.app.lessons_paint import TOTAL_COLOR
from airtable.app.panel_view import ACCENT
from airtable.app.window import GameWindow, LessonsPainter, TimelinePainter
from airtable.model.momenta import MAX_DIAGRAM_PUCKS, MomentaView, values_for
from airtable.model.student_aids import StudentAids
from airtable.net import aids_wire
from airtable.net.aids_wire import AidsDecoder, AidsEncoder, AidsViewer, SharedAids, SharedLessons
from airtable.net.player import NetPlayer
from airtable.net.protocol import AIDS, ProtocolError
from airtable.student.aids_view import draw_student_lessons
from airtable.student.window import PlayerApp

# Puck 0 (1 m/s) hits puck 1 (at rest) head on after 0.1 s; puck 2 drifts far away. With SIX more
# pucks at rest in a row at the bottom, the table has nine: more than FEW_PUCKS.
DEMO = (
    "KEY = '5'\nTITLE = 'Head-on'\nNOTES = ''\n\n"
    "def build(table, variation=0):\n"
    "    table.add_puck((3.0, 4.0), 0.25, vel_mps=(1.0, 0.0))\n"
    "    table.add_puck((3.6, 4.0), 0.25, density_kgpm2=0.6)\n"
    "    table.add_puck((8.0, 2.0), 0.25, vel_mps=(0.0, 0.5))\n"
    "    for k in range(6 if variation else 0):\n"
    "        table.add_puck((1.0 + k, 1.0), 0.25)\n"
)
VARIATIONS = "VARIATIONS = ['three pucks', 'nine pucks']\n"


def _view(k: int = 3) -> MomentaView:
    before = np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 0.25]])[:k]
    after = np.array([[-0.5, 0.0], [1.5, 0.0], [0.0, 0.25]])[:k]
    return MomentaView(
        0.125, np.arange(k), before, after, before.sum(axis=0), after.sum(axis=0), np.zeros((k, 3), np.uint8)
    )


def _shared(view=None, **lessons) -> SharedAids:
    defaults = dict(
        momenta_on=True,
        momenta_corner=2,
        momenta=view,
        values_on=True,
        values_corner=1,
        values_every=True,
        value_rows=(0, 1, 2),
        value_mass_kg=np.array([0.5, 1.0, 0.25]),
        value_vel_mps=np.array([[1.0, 0.0], [0.0, -2.0], [0.5, 0.5]]),
        timeline=(0.5, 3.0, 2.0, 151, 90),
    )
    defaults.update(lessons)
    return SharedAids(lessons=SharedLessons(**defaults))


def _payload(enc: AidsEncoder, viewer: AidsViewer) -> bytes:
    ((kind, payload),) = server_frames(enc.frame_for(viewer))
    assert kind == AIDS
    return payload


def test_the_panels_round_trip_and_a_collisions_rows_travel_once():
    enc, viewer, dec = AidsEncoder(), AidsViewer(), AidsDecoder()
    view = _view()
    sizes = []
    for seq in (1, 2, 3):
        enc.publish(enc.prepare(_shared(view), seq))
        payload = _payload(enc, viewer)
        frame = dec.feed(payload, seq, 3)
        sizes.append(len(payload))
        m = frame.momenta
        assert m.t_s == 0.125 and m.rows.tolist() == [0, 1, 2]
        assert m.before_Ns.tolist() == view.before_Ns.tolist() and m.after_Ns.tolist() == view.after_Ns.tolist()
        assert m.total_before_Ns == (1.0, 0.25) and m.total_after_Ns == (1.0, 0.25)
        assert (frame.momenta_corner, frame.values_corner, frame.values_every) == (2, 1, True)
        assert frame.value_mass_kg.tolist() == [0.5, 1.0, 0.25] and frame.value_vel_mps[1].tolist() == [0.0, -2.0]
        assert frame.timeline == (0.5, 3.0, 2.0, 151, 90)
    # By hand: 10 header + 1 lesson flags + 5 momenta head + 26 rows head + 3 x (4 + 16) rows
    # + 4 values head + 3 x (4 + 12) + 32 timeline = 186; without the rows (held): 186 - 86 = 100.
    assert sizes == [186, 100, 100]
    enc.publish(enc.prepare(_shared(_view()), 4))  # another collision: its rows, once
    assert len(_payload(enc, viewer)) == 186


def test_with_every_panel_off_the_frame_is_format_1_byte_for_byte():
    enc, viewer = AidsEncoder(), AidsViewer()
    assert enc.prepare(SharedAids(lessons=SharedLessons()), 1) is None  # nothing on: no frame at all
    enc.publish(enc.prepare(SharedAids(trails=True, lessons=SharedLessons()), 1))
    payload = _payload(enc, viewer)
    assert len(payload) == 10 and payload[4] == aids_wire.AIDS_VERSION == 1
    enc.publish(enc.prepare(SharedAids(lessons=SharedLessons(timeline=(0.0, 1.0, 1.0, 2, 1))), 2))
    payload = _payload(enc, viewer)
    assert payload[4] == aids_wire.LESSONS_VERSION and payload[10] == aids_wire.TIMELINE
    assert len(payload) == 11 + 32


def _valid() -> bytes:
    enc = AidsEncoder()
    enc.publish(enc.prepare(_shared(_view()), 7))
    return _payload(enc, AidsViewer())


def _patched(offset: int, fmt: str, *values) -> bytes:
    data = bytearray(_valid())
    struct.pack_into(fmt, data, offset, *values)
    return bytes(data)


# Offsets in _valid(): 10 lesson flags; 11 momenta head (corner 11, serial 12); 16 rows head (t 16,
# totals 24-39, count 40); 42 rows (u32 x 3); 54 momenta (f4 x 12); 102 values head (corner, every,
# count 104); 106 rows; 118 numbers (mass, vx, vy per row); 154 timeline (oldest, newest 162, view 170,
# frames 178, index 182).
BAD = {
    "an unknown lesson flag": ((10, "<B", 16 | 1), "lesson panels flagged"),
    "rows without the diagram": ((10, "<B", 2 | 4 | 8), "lesson panels flagged"),
    "a corner past the fourth": ((11, "<B", 5), "momenta diagram in corner 5"),
    "rows of no collision": ((12, "<I", 0), "momenta rows for no collision"),
    "more rows than pucks": ((40, "<H", 4), "momenta diagram of 4 pucks on a table of 3"),
    "a row off the table": ((50, "<I", 3), "not distinct pucks"),
    "rows out of order": ((42, "<II", 1, 0), "not distinct pucks"),
    "a NaN momentum": ((58, "<f", float("nan")), "momenta that are not finite"),
    "an infinite total": ((28, "<f", float("inf")), "momenta total that is not a finite"),
    "values of some pucks when every puck": ((104, "<H", 2), "values of 2 pucks on a table of 3"),
    "a puck of no mass": ((118, "<f", 0.0), "no mass"),
    "a view past the newest": ((170, "<d", 9.0), "a timeline at 9.0 s"),
    "a history of one frame": ((178, "<I", 1), "frame 90 of 1"),
    "a view past the frames": ((182, "<I", 151), "frame 151 of 151"),
}


@pytest.mark.parametrize("case", BAD, ids=list(BAD))
def test_a_malformed_lessons_section_is_refused_in_a_sentence(case):
    (offset, fmt, *values), hint = BAD[case]
    with pytest.raises(ProtocolError, match=hint):
        AidsDecoder().feed(_patched(offset, fmt, *values), 7, 3)


def test_sizes_and_held_momenta_are_never_trusted():
    good = _valid()
    with pytest.raises(ProtocolError, match="cut short"):
        AidsDecoder().feed(good[:-1], 7, 3)
    with pytest.raises(ProtocolError, match="too many"):
        AidsDecoder().feed(good + b"\0", 7, 3)
    no_rows = bytearray(good[:16] + good[102:])  # the rows left out: only the serial
    no_rows[10] = aids_wire.MOMENTA | aids_wire.VALUES | aids_wire.TIMELINE
    with pytest.raises(ProtocolError, match="never sent"):
        AidsDecoder().feed(bytes(no_rows), 7, 3)
    held = AidsDecoder()
    held.feed(good, 7, 3)
    assert held.feed(bytes(no_rows), 7, 3).momenta.rows.tolist() == [0, 1, 2]  # the rows it holds


def test_many_collided_pucks_draw_the_forty_whose_momentum_changed_most():
    from airtable.model.momenta import MomentaAround

    n = 100
    before = np.zeros((n, 2))
    after = np.zeros((n, 2))
    after[:, 0] = np.arange(n) * 0.01  # row k changed by k / 100 N s
    collided = np.ones(n, bool)
    m = MomentaAround(1.0, before, after, collided, np.zeros((n, 3), np.uint8))
    assert m.shown().tolist() == list(range(n - MAX_DIAGRAM_PUCKS, n))
    assert m.view is m.view and m.view.total_after_Ns[0] == pytest.approx(sum(range(n)) * 0.01)
    assert MAX_DIAGRAM_PUCKS <= aids_wire.MAX_MOMENTA_ROWS


# ---------------------------------------------------------------- the teacher's table, a student's window


@pytest.fixture
def classroom(tmp_path: Path):
    (tmp_path / "head_on.py").write_text(DEMO + VARIATIONS)
    with teacher_and_student(DemoShelf([BUILTIN_DIR, tmp_path]), "5") as pair:
        yield pair


def _student(teacher: App, net: NetPlayer, until) -> PlayerApp:
    """The student's window, the teacher's loop stepped once per student frame, until `until(student)`
    has held for a frame the student drew (the condition may come true just after one)."""
    student = PlayerApp(net, headless=True)
    held_at = []

    def step():
        teacher.frame(FRAME_S)
        if not until(student):
            held_at.clear()
            return False
        held_at.append(student.frames)
        return student.frames > held_at[0]

    assert student.run(seconds=WAIT_S, until=step) == 0
    assert until(student), "the condition came true before the time ran out"
    return student


def _pixels(student: PlayerApp, color, rect=None) -> int:
    surface = student.window.surface if rect is None else student.window.surface.subsurface(rect)
    image = pygame.surfarray.array3d(surface)
    return int(np.count_nonzero(np.all(image == np.array(color, np.uint8), axis=2)))


def test_a_student_sees_the_teachers_momenta_diagram(classroom):
    teacher, net = classroom
    press(teacher, pygame.K_d)

    def got_collision(student):
        m = net.aids.frame.momenta if net.aids.frame is not None else None
        return m is not None and teacher.lessons.momenta.latest is not None

    student = _student(teacher, net, got_collision)
    corner, seen = net.aids.momenta_view(teacher.table.color_rgb)
    shown = teacher.lessons.momenta.latest.view
    assert corner == teacher.lessons.painter.corners["momenta"]
    assert seen.t_s == shown.t_s and seen.rows.tolist() == shown.rows.tolist() == [0, 1, 2]
    assert seen.before_Ns == pytest.approx(shown.before_Ns, rel=1e-6, abs=1e-9)
    assert seen.after_Ns == pytest.approx(shown.after_Ns, rel=1e-6, abs=1e-9)
    assert seen.total_after_Ns == pytest.approx(shown.total_after_Ns, rel=1e-6)
    assert seen.colors.tolist() == shown.colors.tolist()
    # By hand: m0 = 0.3 pi 0.25^2 = 0.0589 kg at 1 m/s onto 2 m0 at rest, elastic: -1/3 and 2/3 m/s after,
    # so momenta -m0 / 3 and 4 m0 / 3; puck 2 (m0) drifts at 0.5 m/s.
    m0 = 0.3 * np.pi * 0.25**2
    assert seen.before_Ns[0] == pytest.approx([m0, 0.0], rel=1e-6)
    assert seen.after_Ns[:2, 0] == pytest.approx([-m0 / 3, 4 * m0 / 3], rel=1e-6)
    assert seen.total_before_Ns == pytest.approx([m0, 0.5 * m0], rel=1e-6)
    assert _pixels(student, TOTAL_COLOR) > 100  # the totals' arrows and text, on the student's window


def test_a_student_sees_the_values_of_every_puck_when_there_are_few(classroom):
    teacher, net = classroom
    press(teacher, pygame.K_t)
    press(teacher, pygame.K_SPACE)  # paused: the numbers hold still while they are compared
    student = _student(teacher, net, lambda s: net.aids.values_rows(None) is not None)
    corner, rows = net.aids.values_rows(None)
    mine = values_for(teacher.table, None)
    assert corner == teacher.lessons.painter.corners["values"]
    assert [r.cells() for r in rows] == [r.cells() for r in mine]  # the same text, cell for cell
    for got, want in zip(rows, mine):
        assert got.mass_kg == pytest.approx(want.mass_kg, rel=1e-6)
        assert got.momentum_Ns == pytest.approx(want.momentum_Ns, rel=1e-6)
        assert got.kinetic_J == pytest.approx(want.kinetic_J, rel=1e-6)
    assert rows[0].speed_mps == pytest.approx(1.0, rel=1e-6) and rows[2].speed_mps == pytest.approx(0.5)
    assert _pixels(student, ACCENT) > 20  # the total's row


def test_with_many_pucks_a_student_sees_the_values_of_the_puck_under_their_cursor(classroom):
    teacher, net = classroom
    teacher.start_demo("5", variation=1)  # nine pucks
    press(teacher, pygame.K_t)
    press(teacher, pygame.K_SPACE)
    target = teacher.table.pos_m[5].copy()  # one of the pucks at rest in the bottom row

    def pointed():
        net.send_input(target)  # the student's cursor on puck 5, as its window sends it
        teacher.frame(FRAME_S)
        got = net.aids.values_rows(5)
        return got is not None and got[1]

    wait_until(pointed, what="the values of the puck under the student's cursor")
    (row,) = net.aids.values_rows(5)[1]
    (want,) = values_for(teacher.table, 5)
    assert row.cells() == want.cells() and (row.name, row.row) == ("6", 5)  # row 5 is puck 6
    assert row.mass_kg == pytest.approx(0.3 * np.pi * 0.25**2, rel=1e-6) and row.speed_mps == 0.0
    assert net.aids.values_rows(4)[1] == []  # a puck nobody points at: the hint
    # The student's window draws the row of the puck under its own cursor.
    window = GameWindow(Environment(DEFAULT_SIZE_PX, width_m=teacher.table.width_m), headless=True)
    drawn = []
    paint = LessonsPainter(window)
    paint.values_panel = lambda rows, colors, hint, corner: drawn.append((rows, colors, corner))
    draw_student_lessons(paint, TimelinePainter(window), net.latest(), net.aids, target)
    ((rows, colors, corner),) = drawn
    assert [r.cells() for r in rows] == [want.cells()] and corner == teacher.lessons.painter.corners["values"]
    assert tuple(colors[0]) == tuple(teacher.table.color_rgb[5])


def test_a_student_sees_the_timeline_while_the_teacher_is_back_in_the_history(classroom):
    teacher, net = classroom
    for _ in range(40):
        teacher.frame(FRAME_S)
    press(teacher, pygame.K_SPACE)
    press(teacher, pygame.K_COMMA, mod=pygame.KMOD_SHIFT)  # a second back (or to the oldest moment)
    press(teacher, pygame.K_PERIOD)
    want = teacher.rewind.history.timeline()
    student = _student(teacher, net, lambda s: net.aids.timeline() == want)
    assert want.view_s < want.newest_s and 0.0 < want.fraction < 1.0
    bar = student.timeline_painter.bar_rect()
    area = pygame.Rect(bar.left, bar.top - 2 * bar.height, bar.width, 5 * bar.height)
    assert _pixels(student, ACCENT, area) > 0  # the mark on the student's bar
    assert student.timeline_painter.bar_rect().width > 0
    press(teacher, pygame.K_SPACE)  # running on from there: no bar, so no AIDS bytes at all
    assert teacher.shared_aids() is None


def test_the_teacher_draws_from_the_same_view_the_students_get(classroom):
    teacher, _ = classroom
    press(teacher, pygame.K_d)
    for _ in range(30):
        teacher.frame(FRAME_S)
    drawn = []
    painter = teacher.lessons.painter
    original = painter.momenta_diagram
    painter.momenta_diagram = lambda m, corner: drawn.append(m) or original(m, corner)
    teacher.lessons.draw()
    assert drawn == [teacher.lessons.momenta.latest.view]
    assert StudentAids().momenta_view(np.zeros((0, 3))) is None  # no frame: nothing drawn


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_fuzzed_lessons_sections_raise_protocol_error_or_decode_within_bounds(data):
    payload = bytearray(_valid())
    for _ in range(data.draw(st.integers(1, 4))):
        k = data.draw(st.integers(10, len(payload) - 1))
        payload[k] = data.draw(st.integers(0, 255))
    try:
        frame = AidsDecoder().feed(bytes(payload), 7, 3)
    except ProtocolError as e:
        assert str(e)
        return
    for rows in (frame.momenta.rows if frame.momenta is not None else (), frame.value_rows):
        assert all(0 <= r < 3 for r in rows)
    if frame.momenta is not None:
        assert np.isfinite(frame.momenta.after_Ns).all() and len(frame.momenta.rows) <= 3
    if frame.value_mass_kg is not None:
        assert (frame.value_mass_kg > 0).all()
    if frame.timeline is not None:
        oldest, newest, view, frames, index = frame.timeline
        assert oldest <= view <= newest and index < frames
