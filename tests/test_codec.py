"""Snapshot format 2: round trips, sharing, layouts, restarts, sizes and strict decoding."""

from __future__ import annotations

import dataclasses
import struct

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from airtable.app.scene import CursorView, Scene
from airtable.net import bench_net
from airtable.net.codec import (
    LAYOUT,
    UNITS_PER_M,
    SnapshotDecoder,
    SnapshotEncoder,
    Viewer,
)
from airtable.net.protocol import MAX_DRAWN_PUCKS, SNAPSHOT, ProtocolError


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
    half_unit = 0.5 / UNITS_PER_M + 1e-12
    assert np.abs(decoded.pos_m - scene.pos_m).max() <= half_unit
    assert np.array_equal(decoded.radius_m, scene.radius_m)
    assert np.array_equal(decoded.color_rgb, scene.color_rgb)
    assert np.array_equal(decoded.spring_pairs, scene.spring_pairs)
    assert decoded.title == scene.title and decoded.status == scene.status
    assert decoded.zoom == scene.zoom and decoded.origin_m == scene.origin_m
    assert decoded.time_s == pytest.approx(scene.time_s, abs=1e-6)
    assert len(decoded.cursors) == len(scene.cursors)
    for a, b in zip(decoded.cursors, scene.cursors, strict=True):
        assert (a.name, a.color, a.button, a.held) == (b.name, b.color, b.button, b.held)
        assert np.abs(np.subtract(a.cursor_m, b.cursor_m)).max() <= half_unit


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


def test_a_held_puck_out_of_range_is_refused():
    enc, viewer, dec = SnapshotEncoder(), Viewer(), SnapshotDecoder()
    scene = moving_scene(0.0, n=2, cursors=1)
    enc.add(dataclasses.replace(scene, cursors=(dataclasses.replace(scene.cursors[0], held=5),)))
    with pytest.raises(ProtocolError, match="held puck"):
        feed(dec, enc.frames_for(viewer))


def test_a_layout_claiming_too_many_pucks_is_refused_before_inflating():
    _, _, _, frames = primed()
    payload = bytearray(frames[0][1])
    payload[8:12] = (MAX_DRAWN_PUCKS + 1).to_bytes(4, "little")
    with pytest.raises(ProtocolError, match="more than this client draws"):
        SnapshotDecoder().feed_layout(bytes(payload))


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
    else:
        assert np.isfinite(decoded.scene.pos_m).all()
        assert all(-1 <= c.held < len(decoded.scene.pos_m) for c in decoded.scene.cursors)


def test_a_forgotten_tick_is_not_sent_to_a_player_who_joins_later():
    enc = SnapshotEncoder()
    enc.add(moving_scene(0.0))
    enc.forget()  # everybody left
    late = Viewer()
    assert enc.frames_for(late) == b""
    scene = moving_scene(5.0)
    enc.add(scene)
    assert_same(feed(SnapshotDecoder(), enc.frames_for(late)).scene, scene)
