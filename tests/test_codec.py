"""Snapshot format 2: round trips of every field, sharing, layouts, restarts, sizes and strict decoding."""

from __future__ import annotations

import dataclasses
import struct

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from airtable import AirTable, Client
from airtable.model.scene import CursorView, Scene
from airtable.net.codec import (
    LAYOUT,
    UNITS_PER_M,
    SnapshotDecoder,
    SnapshotEncoder,
    Viewer,
    shareable_view,
    usable_view,
)
from airtable.net.protocol import MAX_DRAWN_PUCKS, SNAPSHOT, ProtocolError
from bench import snapshots as bench_net


def split_frames(data: bytes) -> list[tuple[int, bytes]]:
    frames = []
    while data:
        length, kind = struct.unpack(">IB", data[:5])
        frames.append((kind, data[5 : 4 + length]))
        data = data[4 + length :]
    return frames


def feed(decoder: SnapshotDecoder, data: bytes):
    decoded = None
    for kind, payload in split_frames(data):
        if kind == LAYOUT:
            decoder.feed_layout(payload)
        else:
            assert kind == SNAPSHOT
            decoded = decoder.feed_tick(payload)
    return decoded


def moving_scene(t: float, n: int = 20, cursors: int = 3, **extra) -> Scene:
    """Pucks on a line moving at 1 m/s in x, cursors circling; time t seconds."""
    x = 0.5 + 0.3 * np.arange(n) + 1.0 * t
    pos = np.column_stack([x, 2.0 + 0.01 * np.arange(n)])
    views = tuple(
        CursorView(f"C{i + 1}", (10 * i, 200, 30), (5 + np.cos(2 * t + i), 4 + np.sin(2 * t + i)), i % 4, i - 1)
        for i in range(cursors)
    )
    values = dict(
        width_m=10.0,
        height_m=8.7556,
        pos_m=pos,
        radius_m=np.full(n, 0.1),
        color_rgb=np.tile(np.array([255, 255, 255], np.uint8), (n, 1)),
        spring_pairs=np.array([[0, 1]]),
        spring_length_m=np.array([0.3]),
        spring_width_m=np.array([0.05]),
        spring_color_rgb=np.array([[255, 215, 0]], np.uint8),
        cursors=views,
        title="Demo 1: test",
        status=f"t = {t:.2f} s",
        time_s=t,
        fps=60.0,
        zoom=1.5,
        origin_m=(0.25, -0.5),
    )
    values.update(extra)
    return Scene(**values)


def assert_same(decoded: Scene, scene: Scene) -> None:
    """Every field of `scene` came through: positions to half a unit, times to a
    microsecond, the frame rate to a hundredth, the rest exactly."""
    half_unit = 0.5 / UNITS_PER_M + 1e-12
    assert (decoded.width_m, decoded.height_m) == (scene.width_m, scene.height_m)
    assert np.abs(decoded.pos_m - scene.pos_m).max(initial=0) <= half_unit
    assert np.array_equal(decoded.radius_m, scene.radius_m)
    assert np.array_equal(decoded.color_rgb, scene.color_rgb)
    assert np.array_equal(decoded.spring_pairs, scene.spring_pairs) and decoded.spring_pairs.dtype == np.intp
    assert np.array_equal(decoded.spring_length_m, scene.spring_length_m)
    assert np.array_equal(decoded.spring_width_m, scene.spring_width_m)
    assert np.array_equal(decoded.spring_color_rgb, scene.spring_color_rgb)
    assert decoded.title == scene.title and decoded.status == scene.status
    assert decoded.gravity_on == scene.gravity_on and decoded.puck_correction == scene.puck_correction
    assert decoded.zoom == scene.zoom and decoded.origin_m == scene.origin_m
    assert decoded.time_s == pytest.approx(scene.time_s, abs=1e-6)
    assert decoded.fps == pytest.approx(scene.fps, abs=0.005 + 1e-12)  # hundredths: 0.125 rounds to 0.12
    assert len(decoded.cursors) == len(scene.cursors)
    for a, b in zip(decoded.cursors, scene.cursors, strict=True):
        assert (a.name, a.color, a.button, a.held) == (b.name, b.color, b.button, b.held)
        assert np.abs(np.subtract(a.cursor_m, b.cursor_m)).max() <= half_unit


def round_trip(scene: Scene) -> Scene:
    """`scene` as a new player decodes it: a LAYOUT and a keyframe."""
    enc = SnapshotEncoder()
    enc.add(scene)
    return feed(SnapshotDecoder(), enc.frames_for(Viewer())).scene


def keyframe_payloads(scene: Scene) -> tuple[bytes, bytes]:
    """The LAYOUT and SNAPSHOT payloads a new player gets for `scene`."""
    enc = SnapshotEncoder()
    enc.add(scene)
    (k1, layout), (k2, tick) = split_frames(enc.frames_for(Viewer()))
    assert (k1, k2) == (LAYOUT, SNAPSHOT)
    return layout, tick


def assert_sentence(error: ProtocolError) -> None:
    message = str(error)
    assert "\n" not in message and len(message.split()) >= 5, message


def test_every_tick_and_every_third_tick_decode_to_the_scene():
    enc = SnapshotEncoder()
    fast, slow = Viewer(), Viewer()
    dec_fast, dec_slow = SnapshotDecoder(), SnapshotDecoder()
    for i in range(30):
        scene = moving_scene(i / 30)
        enc.add(scene)
        assert_same(feed(dec_fast, enc.frames_for(fast)).scene, scene)
        if i % 3 == 0:
            assert_same(feed(dec_slow, enc.frames_for(slow)).scene, scene)
    # Each tick was encoded once for the fast viewer and once more on the slow
    # one's ticks, except the first keyframe, which they share.
    assert enc.encodings == 30 + 9


def test_students_on_the_same_base_share_one_encoding():
    enc = SnapshotEncoder()
    viewers = [Viewer() for _ in range(10)]
    for i in range(5):
        enc.add(moving_scene(i / 30))
        frames = {enc.frames_for(v) for v in viewers}
        assert len(frames) == 1
    assert enc.encodings == 5
    assert enc.frames_for(viewers[0]) == b""  # nothing new


def test_constant_velocity_costs_almost_nothing_after_two_ticks():
    enc = SnapshotEncoder()
    viewer = Viewer()
    sizes = []
    for i in range(10):
        enc.add(moving_scene(i / 30, n=500, cursors=0))
        sizes.append(len(enc.frames_for(viewer)))
    # 500 pucks at 1 m/s: a keyframe, a delta, then residuals of at most one unit.
    assert max(sizes[2:]) < 200


def test_the_layout_goes_out_only_when_it_changes():
    enc = SnapshotEncoder()
    viewer, dec = Viewer(), SnapshotDecoder()
    kinds = []
    red = np.tile(np.array([255, 0, 0], np.uint8), (20, 1))
    for i, extra in enumerate([{}, {}, {"color_rgb": red}, {"color_rgb": red}]):
        scene = moving_scene(i / 30, **extra)
        enc.add(scene)
        data = enc.frames_for(viewer)
        kinds.append([k for k, _ in split_frames(data)])
        assert_same(feed(dec, data).scene, scene)
    assert kinds == [[LAYOUT, SNAPSHOT], [SNAPSHOT], [LAYOUT, SNAPSHOT], [SNAPSHOT]]
    assert enc.newest.layout.version == 1


def test_a_restart_or_new_puck_count_starts_a_new_epoch_with_a_keyframe():
    enc = SnapshotEncoder()
    viewer, dec = Viewer(), SnapshotDecoder()
    epochs = []
    for t, n in [(0.0, 20), (0.1, 20), (0.2, 20), (0.0, 20), (0.1, 20), (0.2, 25)]:
        scene = moving_scene(t, n=n)
        enc.add(scene)
        got = feed(dec, enc.frames_for(viewer))
        assert_same(got.scene, scene)
        epochs.append(got.epoch)
    assert epochs == [0, 0, 0, 1, 1, 2]


def table_scene() -> Scene:
    """A real table: three pucks, a spring, gravity on, a player holding a puck with button 3."""
    table = AirTable()
    a = table.add_puck((2, 2), 0.3, color="orange")
    b = table.add_puck((4, 2), 0.2, color="cyan")
    table.add_puck((6, 6), 0.5)
    table.add_spring(a, b, 1.5, color="gold")
    table.gravity_on = True
    table.puck_correction = "perfect-kiss"
    c = Client(name="C2 Zoë", color=(255, 52, 179))
    c.set_input(table, (4.05, 2.0), 3)
    table.step(1 / 240)
    return Scene.from_table(
        table,
        [Client(), c],
        title="Demo 6: Spring triangle",
        status="gravity on   t = 0.00 s",
        fps=59.94,
        zoom=1.5,
        origin_m=(-1.0, 0.25),
    )


def test_a_table_scene_round_trips_every_field():
    scene = table_scene()
    back = round_trip(scene)
    assert_same(back, scene)
    assert back.cursors[1].name == "C2 Zoë" and back.cursors[1].held == 1 and back.cursors[1].button == 3
    assert back.gravity_on and back.puck_correction == "perfect-kiss" and back.fps == 59.94
    assert back.pos_m.flags.writeable


def test_an_empty_table_round_trips():
    scene = Scene(10.0, 8.7556, np.zeros((0, 2)), np.zeros(0), np.zeros((0, 3), np.uint8))
    back = round_trip(scene)
    assert_same(back, scene)
    assert back.pos_m.shape == (0, 2) and back.cursors == ()


def test_unprintable_text_is_cleaned_when_encoding():
    scene = dataclasses.replace(moving_scene(0.0), status="line one\nline\x00two", title="a\tb")
    back = round_trip(scene)
    assert back.status == "line one line two" and back.title == "a b"


# What str.isprintable() accepts: no control/format characters and no spaces but " ".
printable_text = st.text(st.characters(blacklist_categories=("C", "Z"), whitelist_characters=" "), max_size=30)


@st.composite
def scenes(draw) -> Scene:
    """Valid scenes, up to the edges of what a player accepts (sizes, aspect, zoom, origin, radii)."""
    n = draw(st.integers(0, 20))
    s = draw(st.integers(0, 10)) if n else 0
    c = draw(st.integers(0, 5))
    width_m = draw(st.floats(0.1, 1000))
    height_m = draw(st.floats(max(0.1, width_m / 99), min(1000, width_m * 99)))
    size = max(width_m, height_m)
    x = st.floats(-size, width_m + size)
    y = st.floats(-size, height_m + size)
    cursors = tuple(
        CursorView(
            name=draw(printable_text),
            color=draw(st.tuples(*[st.integers(0, 255)] * 3)),
            cursor_m=(draw(x), draw(y)),
            button=draw(st.integers(0, 3)),
            held=draw(st.integers(-1, n - 1)),
        )
        for _ in range(c)
    )
    pos = np.column_stack([draw(hnp.arrays(float, (n,), elements=x)), draw(hnp.arrays(float, (n,), elements=y))])
    return Scene(
        width_m=width_m,
        height_m=height_m,
        pos_m=pos.reshape(n, 2),
        radius_m=draw(hnp.arrays(float, (n,), elements=st.floats(1e-3, min(10, size)))),
        color_rgb=draw(hnp.arrays(np.uint8, (n, 3))),
        spring_pairs=draw(hnp.arrays(np.intp, (s, 2), elements=st.integers(0, max(n - 1, 0)))),
        spring_length_m=draw(hnp.arrays(float, (s,), elements=st.floats(0, min(100, size)))),
        spring_width_m=draw(hnp.arrays(float, (s,), elements=st.floats(0, min(1, size)))),
        spring_color_rgb=draw(hnp.arrays(np.uint8, (s, 3))),
        cursors=cursors,
        title=draw(printable_text),
        status=draw(printable_text),
        gravity_on=draw(st.booleans()),
        puck_correction=draw(st.sampled_from(["off", "two-step", "perfect-kiss"])),
        time_s=draw(st.floats(0, 1e6)),
        fps=draw(st.floats(0, 655)),  # centi-fps travel in 16 bits
        zoom=draw(st.floats(0.05, 200)),
        origin_m=(draw(x), draw(y)),
    )


@given(scenes())
@settings(max_examples=50, deadline=None)
def test_valid_scenes_at_the_edges_round_trip(scene):
    assert_same(round_trip(scene), scene)


def test_a_student_far_behind_gets_a_keyframe():
    enc = SnapshotEncoder()
    viewer, dec = Viewer(), SnapshotDecoder()
    enc.add(moving_scene(0.0))
    feed(dec, enc.frames_for(viewer))
    for i in range(300):
        enc.add(moving_scene(i / 30))
    scene = moving_scene(10.0)
    enc.add(scene)
    assert_same(feed(dec, enc.frames_for(viewer)).scene, scene)


def test_jumps_across_the_whole_cursor_range_still_decode():
    enc = SnapshotEncoder()
    viewer, dec = Viewer(), SnapshotDecoder()
    for t, x in [(0.0, -45.0), (0.01, 55.0), (0.05, -45.0)]:  # cursors may be 5 tables off
        pos = np.array([[x, 1.0], [1.0, 1.0]])
        scene = moving_scene(t, n=2, cursors=0, pos_m=pos)
        enc.add(scene)
        assert_same(feed(dec, enc.frames_for(viewer)).scene, scene)


@pytest.mark.parametrize(
    ("make", "target"),
    [(bench_net.at_rest, 120), (bench_net.students_on_demo4, 600), (lambda: bench_net.gas(1000), 3000)],
)
def test_mean_snapshot_frames_meet_the_targets(make, target):
    measured = bench_net.measure(make(), ticks=20)
    assert measured.mean_b <= target


# ---------------------------------------------------------------- strict decoding


def primed() -> tuple[SnapshotEncoder, Viewer, SnapshotDecoder, list[tuple[int, bytes]]]:
    """An encoder and decoder that have exchanged a keyframe, and the next frames."""
    enc, viewer, dec = SnapshotEncoder(), Viewer(), SnapshotDecoder()
    enc.add(moving_scene(0.0))
    feed(dec, enc.frames_for(viewer))
    enc.add(moving_scene(1 / 30))
    feed(dec, enc.frames_for(viewer))
    enc.add(moving_scene(2 / 30, color_rgb=np.tile(np.array([1, 2, 3], np.uint8), (20, 1))))
    return enc, viewer, dec, split_frames(enc.frames_for(viewer))


def test_a_delta_without_its_base_is_refused_with_a_sentence():
    enc, viewer, _, frames = primed()
    fresh = SnapshotDecoder()
    fresh.feed_layout(frames[0][1])
    with pytest.raises(ProtocolError, match="does not hold"):
        fresh.feed_tick(frames[1][1])


def test_a_tick_for_a_layout_never_sent_is_refused():
    _, _, dec, frames = primed()
    with pytest.raises(ProtocolError, match="never sent"):
        dec.feed_tick(frames[1][1])


def test_another_format_version_says_install_the_same_version():
    _, _, dec, frames = primed()
    payload = bytearray(frames[1][1])
    payload[4] = 1
    dec.feed_layout(frames[0][1])
    with pytest.raises(ProtocolError, match="install the same airtable version"):
        dec.feed_tick(bytes(payload))


def test_a_held_puck_out_of_range_is_left_out_and_the_rest_shown():
    enc, viewer, dec = SnapshotEncoder(), Viewer(), SnapshotDecoder()
    scene = moving_scene(0.0, n=2, cursors=1)
    enc.add(dataclasses.replace(scene, cursors=(dataclasses.replace(scene.cursors[0], held=5),)))
    shown = feed(dec, enc.frames_for(viewer)).scene
    assert shown.cursors[0].held == -1 and "held puck" in dec.problem
    np.testing.assert_allclose(shown.pos_m, scene.pos_m, atol=1 / 4000)


def test_a_view_that_is_not_finite_keeps_the_last_usable_one():
    layout, tick = keyframe_payloads(moving_scene(0.0))
    payload = bytearray(tick)
    payload[31 : 31 + 8] = struct.pack("<d", float("nan"))  # a keyframe's view follows its header
    dec = SnapshotDecoder()
    dec.feed_layout(layout)
    shown = dec.feed_tick(bytes(payload)).scene
    assert (shown.zoom, *shown.origin_m) == (1.0, 0.0, 0.0) and "zoom nan" in dec.problem


@given(
    zoom=st.floats(allow_nan=True, allow_infinity=True),
    ox=st.floats(allow_nan=True, allow_infinity=True),
    oy=st.floats(allow_nan=True, allow_infinity=True),
)
def test_any_view_the_teacher_has_travels_as_one_the_client_uses(zoom, ox, oy):
    view = shareable_view(zoom, ox, oy)
    assert usable_view(view)
    if usable_view((zoom, ox, oy)):
        assert view == (zoom, ox, oy)


@pytest.mark.parametrize(
    ("offset", "count", "hint"),
    [
        (8, MAX_DRAWN_PUCKS + 1, f"{MAX_DRAWN_PUCKS + 1} pucks"),
        (8, 0xFFFFFFFF, "4294967295 pucks"),
        (12, 0xFFFFFFFF, "4294967295 springs"),
        (16, 0xFFFFFFFF, "4294967295 cursors"),
    ],
)
def test_a_layout_claiming_too_many_things_is_refused_before_inflating(offset, count, hint):
    _, _, _, frames = primed()
    payload = bytearray(frames[0][1])
    payload[offset : offset + 4] = count.to_bytes(4, "little")
    with pytest.raises(ProtocolError, match="more than this client draws") as err:
        SnapshotDecoder().feed_layout(bytes(payload))
    assert hint in str(err.value)


@pytest.mark.parametrize(
    ("frame", "offset", "value", "hint"),
    [
        (LAYOUT, 0, b"XXXX", "does not start with ATLY"),
        (LAYOUT, 4, b"\x01", "version 1"),
        (LAYOUT, 20, struct.pack("<d", float("nan")), "table size"),
        (LAYOUT, 20, struct.pack("<d", -1.0), "table size"),
        (SNAPSHOT, 0, b"XXXX", "does not start with ATSN"),
        (SNAPSHOT, 16, struct.pack("<q", 1 << 62), "time out of range"),
    ],
)
def test_header_checks(frame, offset, value, hint):
    layout, tick = keyframe_payloads(moving_scene(0.0))
    payload = bytearray(layout if frame == LAYOUT else tick)
    payload[offset : offset + len(value)] = value
    dec = SnapshotDecoder()
    with pytest.raises(ProtocolError, match=hint):
        if frame == LAYOUT:
            dec.feed_layout(bytes(payload))
        else:
            dec.feed_layout(layout)
            dec.feed_tick(bytes(payload))


def test_every_truncation_and_any_extra_byte_is_a_protocol_error():
    """Of a LAYOUT, a keyframe and a delta: every byte of each is needed, and no more."""
    layout, keyframe = keyframe_payloads(table_scene())
    after_layout = SnapshotDecoder()
    after_layout.feed_layout(layout)
    _, _, primed_dec, frames = primed()
    primed_dec.feed_layout(frames[0][1])
    delta = frames[1][1]
    cases = [(layout, SnapshotDecoder().feed_layout), (keyframe, after_layout.feed_tick), (delta, primed_dec.feed_tick)]
    for payload, decode in cases:
        for broken in [*(payload[:cut] for cut in range(len(payload))), payload + b"\0"]:
            with pytest.raises(ProtocolError) as err:
                decode(broken)
            assert_sentence(err.value)
    # A refused frame leaves the decoder as it was: the whole delta still decodes.
    red = np.tile(np.array([1, 2, 3], np.uint8), (20, 1))
    assert_same(primed_dec.feed_tick(delta).scene, moving_scene(2 / 30, color_rgb=red))


def _decode_all(dec: SnapshotDecoder, frames: list[tuple[int, bytes]]):
    decoded = None
    for kind, payload in frames:
        if kind == LAYOUT:
            dec.feed_layout(payload)
        else:
            decoded = dec.feed_tick(payload)
    return decoded


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(kind=st.sampled_from([LAYOUT, SNAPSHOT]), data=st.binary(max_size=400))
def test_random_bytes_raise_only_protocol_errors(kind, data):
    _, _, dec, _ = primed()
    try:
        _decode_all(dec, [(kind, data)])
    except ProtocolError as e:
        assert str(e)


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    which=st.integers(0, 1),
    edits=st.lists(st.tuples(st.integers(0, 10_000), st.integers(0, 255)), min_size=1, max_size=4),
    cut=st.one_of(st.none(), st.integers(0, 10_000)),
    tail=st.binary(max_size=8),
)
def test_mutated_frames_raise_only_protocol_errors(which, edits, cut, tail):
    _, _, dec, frames = primed()
    kind, payload = frames[which]
    payload = bytearray(payload)
    for at, value in edits:
        payload[at % len(payload)] = value
    if cut is not None:
        payload = payload[: cut % (len(payload) + 1)]
    mutated = list(frames)
    mutated[which] = (kind, bytes(payload) + tail)
    try:
        decoded = _decode_all(dec, mutated)
    except ProtocolError as e:
        assert str(e)
    else:  # whatever decodes is safe to draw: finite, in range, printable
        scene = decoded.scene
        assert np.isfinite(scene.pos_m).all() and (scene.radius_m > 0).all()
        assert all(-1 <= c.held < len(scene.pos_m) and 0 <= c.button <= 3 for c in scene.cursors)
        assert scene.title.isprintable() and scene.status.isprintable()


def test_a_forgotten_tick_is_not_sent_to_a_player_who_joins_later():
    enc = SnapshotEncoder()
    enc.add(moving_scene(0.0))
    enc.forget()  # everybody left
    late = Viewer()
    assert enc.frames_for(late) == b""
    scene = moving_scene(5.0)
    enc.add(scene)
    assert_same(feed(SnapshotDecoder(), enc.frames_for(late)).scene, scene)
