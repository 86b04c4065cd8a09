"""Students see the teacher's aids: the AIDS frame (type 10), its strict decoder, the student's window."""

from __future__ import annotations

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, frames_until, post_key, press, server_frames, teacher_and_student
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from airtable.model import aids
from airtable.model.scene import Scene
from airtable.model.shared_aids import annotation_of, record_of
from airtable.model.student_aids import StudentAids
from airtable.net import aids_wire
from airtable.net.aids_wire import AidsDecoder, AidsEncoder, AidsViewer, SharedAids
from airtable.net.codec import SnapshotDecoder, SnapshotEncoder, Viewer
from airtable.net.player import NetPlayer
from airtable.net.protocol import AIDS, LAYOUT, SNAPSHOT, ProtocolError
from airtable.student.aids_view import VELOCITY_COLOR
from airtable.student.window import PlayerApp
from bench.aids import frame_sizes, measure


def _scene(n: int = 3, aids_: SharedAids | None = None, t: float = 0.0) -> Scene:
    pos = np.column_stack([np.linspace(1.0, 3.0, n), np.full(n, 2.0)])
    return Scene(
        width_m=10.0,
        height_m=8.0,
        pos_m=pos,
        radius_m=np.full(n, 0.2),
        color_rgb=np.full((n, 3), 200, np.uint8),
        time_s=t,
        aids=aids_,
    )


class _Student:
    """The decoding side without sockets: the snapshot decoder, then the aids decoder."""

    def __init__(self) -> None:
        self.snaps, self.aids, self.state = SnapshotDecoder(), AidsDecoder(), StudentAids()

    def take(self, data: bytes, now_s: float = 0.0) -> list:
        got = []
        for kind, payload in server_frames(data):
            if kind == LAYOUT:
                self.snaps.feed_layout(payload)
            elif kind == SNAPSHOT:
                self.state.snapshot(self.snaps.feed_tick(payload).scene)
            else:
                assert kind == AIDS
                last = self.snaps.last
                frame = self.aids.feed(payload, last.seq, last.layout.sizes[0], last.time_us / 1e6)
                self.state.take(frame, now_s)
                got.append(frame)
        return got


def test_aids_off_add_no_bytes_at_all():
    with_field, without = SnapshotEncoder(), SnapshotEncoder()
    v1, v2 = Viewer(), Viewer()
    for k in range(5):
        a = with_field.frames_for(v1) if with_field.add(_scene(aids_=SharedAids(), t=k / 30)) else b""
        b = without.frames_for(v2) if without.add(_scene(t=k / 30)) else b""
        assert len(a) == len(b) and AIDS not in frame_sizes(a)


def test_vectors_round_trip_to_a_thousandth_of_the_arrow_scale_and_code_as_deltas():
    enc, viewer, student = SnapshotEncoder(), Viewer(), _Student()
    rng = np.random.default_rng(1)
    v = rng.normal(0, 2, (3, 2))
    sizes = []
    for k in range(6):
        v = v + rng.normal(0, 0.01, (3, 2))
        shared = SharedAids(vectors=1, values=v, amount=2.0, velocity_amount=2.0, com=(1.0, 2.0, 0.5, 0.0))
        enc.add(_scene(aids_=shared, t=k / 30))
        data = enc.frames_for(viewer)
        (frame,) = student.take(data)
        sizes.append(frame_sizes(data)[AIDS])
        assert np.allclose(frame.values, np.round(v / 2.0 * 1000) * 2.0 / 1000, atol=1e-12)
        assert frame.amount == 2.0 and frame.com == (1.0, 2.0, 0.5, 0.0) and frame.vectors == 1
    assert frame.flags & aids_wire.VECTOR_KEY == 0, "later ticks are deltas on what the student holds"
    assert sizes[-1] < sizes[0]


def test_annotations_are_sent_once_and_forgotten_as_the_teacher_forgets_them():
    enc, viewer, student = AidsEncoder(), AidsViewer(), _Student()
    made = [
        aids.Annotation(
            born_s=10.0,
            contact_m=(1.0, 2.0),
            normal=(1.0, 0.0),
            overlap_m=0.004,
            separation_m=0.004,
            pos_i_before=(1.2, 2.0),
            pos_j_before=(0.8, 2.0),
            pos_i_after=(1.25, 2.0),
            pos_j_after=(0.75, 2.0),
            radius_i_m=0.2,
            radius_j_m=0.2,
            angle_deg=None if k else 90.0,
            target=aids.TargetPush(29.4, 14.5, (1.3, 2.1), (0.8, 0.6), (0.9, 0.4)) if k == 0 else None,
        )
        for k in range(2)
    ]
    sent = []
    for seq, live in ((1, made[:1]), (2, made[:1]), (3, made), (4, made[1:])):
        records = tuple(record_of(a, 10.5) for a in live)
        shared = SharedAids(annotations=tuple(live), annotation_records=records, annotations_on=True)
        enc.publish(enc.prepare(shared, seq))
        frame = student.aids.feed(_payload(enc, viewer), seq, 3)
        student.state.take(frame, now_s=100.0)
        sent.append(len(frame.new_annotations))
    assert sent == [1, 0, 1, 0]
    (kept,) = student.state.live_annotations(100.0)
    assert kept.born_s == pytest.approx(99.5, abs=1e-3), "as old as it was on the teacher's side"
    assert kept.pos_j_after == pytest.approx(made[1].pos_j_after) and kept.angle_deg is None
    assert kept.overlap_m == pytest.approx(0.004) and kept.ratio == pytest.approx(1.0, abs=1e-6)
    assert annotation_of(record_of(made[0], 10.0), 10.0).target.ideal_deg == pytest.approx(14.5)


def _payload(enc: AidsEncoder, viewer: AidsViewer) -> bytes:
    data = enc.frame_for(viewer)
    ((kind, payload),) = server_frames(data)
    assert kind == AIDS
    return payload


def test_chart_samples_append_and_notes_come_once():
    enc, viewer, student = AidsEncoder(), AidsViewer(), _Student()
    notes_bytes = []
    for seq in range(1, 5):
        shared = SharedAids(chart=(seq / 30, 1.0, 0.5, 0.0, 1.5, 0.25), notes="Two pucks collide.")
        enc.publish(enc.prepare(shared, seq))
        payload = _payload(enc, viewer)
        frame = student.aids.feed(payload, seq, 3, seq / 30)
        student.state.take(frame, 0.0)
        notes_bytes.append(frame.notes is not None)
    assert notes_bytes == [True, False, False, False]
    assert student.state.notes == "Two pucks collide."
    series = student.state.chart.series()
    assert list(series["time_s"]) == pytest.approx([1 / 30, 2 / 30, 3 / 30, 4 / 30])
    assert series["total_J"][-1] == pytest.approx(1.5)


def test_a_students_chart_explains_a_springs_swinging_total():
    """A user test: on the spring demo every student's window failed each frame ("'Scene' object has no
    attribute 'spring_damper_Nspm'"): the chart's note asked the snapshot for the table's dampers."""
    enc, viewer, student = AidsEncoder(), AidsViewer(), _Student()
    for seq in range(1, 301):  # 10 s of a total swinging by 1 % about 1.5 J, no drift (at 30 samples a second)
        t = seq / 30
        total = 1.5 * (1.0 + 0.01 * np.sin(2.0 * np.pi * 7.5 * t))  # (the wiggle: twice the spring's frequency)
        enc.publish(enc.prepare(SharedAids(chart=(t, total - 0.5, 0.5, 0.0, total, 0.25)), seq))
        student.state.take(student.aids.feed(_payload(enc, viewer), seq, 3, t), 0.0)
    springs = _scene()
    springs.spring_pairs = np.array([[0, 1]])
    _, _, note = student.state.chart_view(springs)
    assert note is not None and "does not drift" in note
    assert student.state.chart_view(_scene())[2] is None  # no springs: nothing to explain


def test_a_student_gets_the_charts_last_seconds_once_and_again_after_it_was_off():
    enc, viewer, student = AidsEncoder(), AidsViewer(), _Student()
    past = np.array([[t, 1.0, 0.5, 0.0, 1.5, 0.25] for t in (0.1, 0.2, 0.3)])
    got = []
    for seq, on in enumerate((True, True, False, True), start=1):
        shared = (
            SharedAids(chart=(seq, 1.0, 0.5, 0.0, 1.5, 0.25), chart_history=past) if on else SharedAids(trails=True)
        )
        enc.publish(enc.prepare(shared, seq))
        frame = student.aids.feed(_payload(enc, viewer), seq, 3, float(seq))
        student.state.take(frame, 0.0)
        got.append(None if frame.chart_history is None else len(frame.chart_history))
    assert got == [3, None, None, 3]
    assert list(student.state.chart.series()["time_s"]) == pytest.approx([0.1, 0.2, 0.3, 4.0])


def _valid_payload() -> bytes:
    enc = AidsEncoder()
    shared = SharedAids(
        trails=True,
        vectors=2,
        values=np.array([[1.0, -2.0], [0.0, 0.5], [3.0, 0.0]]),
        amount=5.0,
        com=(1.0, 1.0, 0.1, 0.0),
        chart=(1.0, 2.0, 3.0, 0.0, 5.0, 1.0),
        chart_history=np.array([[0.5, 2.0, 3.0, 0.0, 5.0, 1.0], [0.75, 2.0, 3.0, 0.0, 5.0, 1.0]]),
        notes="notes",
    )
    enc.publish(enc.prepare(shared, 7))
    return _payload(enc, AidsViewer())


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_fuzzed_aids_frames_raise_protocol_error_or_decode_within_bounds(data):
    payload = bytearray(_valid_payload())
    for _ in range(data.draw(st.integers(0, 6))):
        k = data.draw(st.integers(0, len(payload) - 1))
        payload[k] = data.draw(st.integers(0, 255))
    cut = data.draw(st.integers(0, len(payload)))
    payload = bytes(payload[:cut]) if data.draw(st.booleans()) else bytes(payload)
    try:
        frame = AidsDecoder().feed(payload, 7, 3)
    except ProtocolError as e:
        assert str(e)
        return
    if frame.values is not None:
        assert frame.values.shape == (3, 2) and np.isfinite(frame.values).all()
    assert 0 < frame.amount < 1e30
    assert frame.chart is None or all(np.isfinite(frame.chart))


@given(st.binary(max_size=200), st.integers(0, 2**32 - 1), st.integers(0, 50))
def test_random_bytes_never_crash_the_aids_decoder(payload, seq, pucks):
    try:
        AidsDecoder().feed(payload, seq, pucks)
    except ProtocolError:
        pass


def test_bad_frames_are_refused_in_a_sentence():
    good = _valid_payload()
    with pytest.raises(ProtocolError, match="right after tick"):
        AidsDecoder().feed(good, 8, 3)
    with pytest.raises(ProtocolError, match="arrows for 3 pucks on a table of 4"):
        AidsDecoder().feed(good, 7, 4)
    with pytest.raises(ProtocolError, match="too many"):
        AidsDecoder().feed(good + b"x", 7, 3)


def test_byte_figures_for_demo_4_and_shift_1_with_a_v_c_on():
    off = measure("demo 4 off", "4", "", 30, ticks=30)
    on = measure("demo 4 on", "4", "avc", 30, ticks=30)
    shift1 = measure("Shift+1 on", "1p", "avc", 0, ticks=30)
    rest = measure("rest off", "4", "", 0, ticks=30, rest=True)
    rest_on = measure("rest on", "4", "avc", 0, ticks=30, rest=True)
    assert off.aids_b == 0 and rest.aids_b == 0
    assert on.snapshot_b == off.snapshot_b, "the aids never change the SNAPSHOT"
    assert on.total_b <= 600  # 219 + 221 B when measured
    assert shift1.total_b <= 130  # 47 + 76 B
    assert rest_on.total_b <= 120  # 43 + 74 B: a table at rest stays under its target with the aids on


# ---------------------------------------------------------------- the real player


@pytest.fixture
def classroom(demos):
    with teacher_and_student(demos, "1p") as pair:
        yield pair


def _run_student(teacher, net, until, keys=()):
    """The student's window, with the teacher's loop stepped once per student frame; `keys` are
    pressed (for the student: posted after the teacher's frame) on the student's 5th frame."""
    student = PlayerApp(net, headless=True)

    def step():
        teacher.frame(FRAME_S)
        if student.frames == 5:
            for key in keys:
                post_key(key)
                post_key(key, down=False)
        return student.frames > 8 and until(student)

    assert student.run(seconds=20, until=step) == 0
    assert until(student), "the condition came true before the time ran out"
    return student


def test_after_a_rewind_the_students_chart_keeps_what_came_before_it_as_the_teachers_does(classroom):
    """A user test: the student's chart was empty after the teacher rewound and ran on (time went back, so it
    started afresh) while the teacher's kept the samples before that moment."""
    teacher, net = classroom
    teacher.aids.show_chart = True
    series = lambda: net.aids.chart.series(100.0)["time_s"]  # noqa: E731
    frames_until(teacher, lambda: len(series()) > 20 and series()[-1] > 1.0, "a second of chart at the student")
    press(teacher, pygame.K_SPACE)
    for _ in range(8):
        press(teacher, pygame.K_COMMA)
    t = teacher.table.time_s
    assert t > 0.5
    frames_until(teacher, lambda: net.latest().time_s <= t + 1e-9, "the student to see the moment looked back at")
    charted = len(series())
    assert charted > 20 and series()[-1] > t + 0.3  # looking back: the chart as it was (a user test: it went blank)
    press(teacher, pygame.K_SPACE)  # runs on from t: the later samples go
    frames_until(teacher, lambda: len(series()) and series()[-1] > t + 0.1, "samples after the rewind")
    times = series()
    assert times[0] < t - 0.5 and np.all(np.diff(times) > 0), (t, times)
    teachers = teacher.aids.chart.series(100.0)["time_s"]
    assert set(np.round(times[times <= t], 5)) <= set(np.round(teachers, 5))  # (float32 on the wire)


def test_the_students_own_cursor_and_name_are_drawn_over_the_chart(classroom):
    """A user test: the student's own name lay under the teacher's chart when the mouse was over it."""
    teacher, net = classroom
    teacher.aids.show_chart = True
    student = _run_student(teacher, net, lambda s: len(net.aids.chart.series()["time_s"]) > 5)
    chart = student.painter.chart_plot
    point = student.env.to_world(np.array(chart.center, dtype=float))
    student._draw(net.latest(), point, True)
    label = student.window.cursor_boxes[-1]
    assert chart.colliderect(label), (chart, label)
    surface, color = student.window.surface, tuple(net.welcome.color)
    drawn = [surface.get_at((x, y))[:3] for x in range(label.left, label.right) for y in range(label.top, label.bottom)]
    assert drawn.count(color) > 10, "our name in our colour, over the chart"


def test_a_student_sees_the_teachers_vectors_annotations_and_chart(classroom):
    teacher, net = classroom
    teacher.aids.show_annotations, teacher.aids.vectors, teacher.aids.show_chart = True, 1, True
    student = _run_student(teacher, net, lambda s: net.aids.annotations and len(net.aids.chart.series()["time_s"]) > 5)
    frame = net.aids.frame
    assert frame.vectors == 1 and frame.values.shape == (len(teacher.table.pos_m), 2)
    moving = np.hypot(*frame.values.T) > 0
    assert moving.any()
    assert frame.amount == teacher.painter.vector_scale("velocity").update(np.zeros((0, 2)))[0]
    # The arrows' colour and the chart panel are on the student's window.
    pixels = pygame.surfarray.array3d(student.window.surface).reshape(-1, 3)
    assert (pixels == VELOCITY_COLOR).all(axis=1).any()
    box = student.painter.chart_rect()
    assert box.width > 100 and (pygame.surfarray.array3d(student.window.surface.subsurface(box)) > 0).any()
    a = net.aids.live_annotations(__import__("time").monotonic())
    assert a and a[0].overlap_m > 0 and a[0].radius_i_m == pytest.approx(teacher.table.radius_m[0])


def test_a_student_toggles_aids_on_their_own_window_only(classroom):
    teacher, net = classroom
    teacher.aids.vectors, teacher.aids.show_chart = 1, True
    trails = teacher.aids.trails  # Shift+1 starts with trails on
    student = _run_student(teacher, net, lambda s: not net.aids.shows("v"), keys=(pygame.K_v, pygame.K_e))
    shown = teacher.aids
    assert shown.vectors == 1 and shown.show_chart and shown.trails == trails, "the teacher's aids stay"
    assert net.aids.teacher & aids_wire.VELOCITY, "and the teacher still sends them"
    assert net.aids.shows("c") and net.aids.shows("e") != trails and not net.aids.shows("v")
    assert not {"v", "e"} & student.keys, "the toggles are not sent in INPUT"


def test_f1_opens_the_students_help_panel(classroom):
    teacher, net = classroom
    plain = _run_student(teacher, net, lambda s: True)
    assert not plain.show_help
    net2 = NetPlayer("127.0.0.1", net.port, name="Bo", max_backoff_s=0.3)
    net2.connect()
    try:
        student = _run_student(teacher, net2, lambda s: s.show_help and s.frames > 8, keys=(pygame.K_F1,))
        rect = student.window.panel_rect()
        assert student.show_help and rect.width > 100
    finally:
        net2.close()


def test_with_the_teachers_aids_off_a_student_draws_arrows_from_the_snapshots(classroom):
    teacher, net = classroom
    teacher.aids.trails = False  # every aid off: no AIDS frames at all
    student = _run_student(
        teacher, net, lambda s: net.aids.velocities(2) is not None and net.aids.shows("v"), keys=(pygame.K_v,)
    )
    assert net.aids.frame is None and net.aids.teacher == 0
    v = net.aids.velocities(2)
    assert np.hypot(*v[0]) == pytest.approx(np.hypot(*teacher.table.vel_mps[0]), rel=0.05)
    pixels = pygame.surfarray.array3d(student.window.surface).reshape(-1, 3)
    assert (pixels == VELOCITY_COLOR).all(axis=1).any()


def test_a_student_sees_the_teachers_lecture_notes_panel(classroom):
    teacher, net = classroom
    teacher.aids.trails, teacher.panels.show_notes = False, True
    seen = []

    def notes_then_none(student):
        if not seen and net.aids.teacher & aids_wire.NOTES and net.aids.notes is not None:
            seen.append(net.aids.notes)
            teacher.panels.show_notes = False  # the teacher closes them
        return seen and net.aids.frame is None

    _run_student(teacher, net, notes_then_none)
    assert seen == [teacher.demo.notes] and len(seen[0]) > 20
    assert net.aids.teacher == 0, "notes closed and every other aid off: no AIDS frames"


def test_a_student_turns_puck_numbers_on_for_their_own_window(classroom):
    """A reveal's summary says "puck 4": k shows the numbers on the student's window (the teacher's
    k is the projector's alone)."""
    teacher, net = classroom
    teacher.paused = True  # the same picture twice, but for the numbers
    plain = _run_student(teacher, net, lambda s: True)
    before = pygame.surfarray.array3d(plain.window.surface).copy()
    student = _run_student(teacher, net, lambda s: net.aids.shows("k"), keys=(pygame.K_k,))
    assert net.aids.shows("k") and not teacher.lessons.show_numbers
    assert "k" not in student.keys, "the toggle is not sent in INPUT"
    after = pygame.surfarray.array3d(student.window.surface)
    # Each puck's number is drawn on it: pixels change at every puck's centre.
    centres = student.window.env.to_screen(teacher.table.pos_m).astype(int)
    for x, y in centres:
        assert (after[x - 6 : x + 7, y - 6 : y + 7] != before[x - 6 : x + 7, y - 6 : y + 7]).any(), (x, y)


@pytest.mark.parametrize("bits", [0x7F800001, 0x7FC00000, 0x7F800000, 0x7F7FFFFF])  # signalling NaN, NaN, inf, 3.4e38
def test_numbers_off_the_wire_that_are_no_physics_are_refused_without_a_warning(bits):
    """A signalling NaN among an aids frame's float32s made numpy warn on the teacher's or student's console
    ("invalid value encountered in cast") before the frame was refused: refused in a sentence, silently."""
    import struct
    import warnings

    from airtable.net import aids_wire
    from airtable.net.wire import Reader

    data = struct.pack("<6f", 1.0, 2.0, 3.0, 4.0, 5.0, 6.0)[:-4] + struct.pack("<I", bits)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ProtocolError, match="chart history samples that are not finite numbers"):
            aids_wire._numbers(Reader(data, "aids"), (1, 6), "chart history samples")


def test_a_student_pages_through_the_help_and_the_notes_in_a_small_window(classroom):
    """A user test: in a small student window the help and the teacher's notes ended "a larger window shows
    the rest", F1 again closed the help, and nothing hid the notes but the teacher. Now F1 and L turn the
    pages, L after the last page (or Esc) hides the notes on this window alone, and L shows them again."""
    teacher, net = classroom
    teacher.aids.trails, teacher.panels.show_notes = False, True
    student = PlayerApp(net, headless=True)
    L, ESC, F1 = pygame.K_l, pygame.K_ESCAPE, pygame.K_F1
    keys: list[int] = []
    seen = []  # after each key, once drawn: (key, help shown, its page, notes shown, their page)
    last = []  # the key last pressed and the frame it was pressed in

    def step():
        teacher.frame(FRAME_S)
        if student.frames == 3:
            pygame.event.post(pygame.event.Event(pygame.VIDEORESIZE, size=(320, 240), w=320, h=240))
        if last and student.frames > last[1] + 1:  # a frame has drawn what the key did
            key = last[0]
            last.clear()
            seen.append((key, student.show_help, student.help_page, student._notes_shown(), student.notes_page))
            if key == F1 and not student.show_help:
                return True  # the help closed after its last page
        if not keys and not seen and student.frames > 10 and student.notes_pages > 1:
            keys.extend([L] * student.notes_pages + [L, ESC] + [F1] * 20)
        if keys and not last:
            key = keys.pop(0)
            post_key(key)
            post_key(key, down=False)
            last.extend([key, student.frames])
        return False

    assert student.run(seconds=30, until=step) == 0
    help_pages, notes_pages = student.help_pages, student.notes_pages
    assert student.window.surface.get_size() == (320, 240) and help_pages > 1 and notes_pages > 1
    assert teacher.panels.show_notes, "the student's keys are the student's window's alone"
    expected = [(L, False, 0, True, k) for k in range(1, notes_pages)] + [(L, False, 0, False, 0)]
    expected += [(L, False, 0, True, 0), (ESC, False, 0, False, 0)]
    expected += [(F1, True, k, False, 0) for k in range(help_pages)] + [(F1, False, 0, False, 0)]
    assert seen == expected
    assert student.leave_asked_until < 0, "Esc hid the notes: it did not ask to leave"
