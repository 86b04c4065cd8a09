"""Drawing pucks: thousands stamped with numpy look exactly as blitted one by one; a few keep their order."""

from __future__ import annotations

import numpy as np
import pygame
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from airtable.app.pucks_view import MIN_PUCK_RADIUS_PX, PuckSprites, core_color, draw_pucks, radii_px

WHITE, ORANGE, TABLE_BLUE = (255, 255, 255), (255, 165, 0), (20, 20, 70)


@pytest.fixture(autouse=True)
def display():
    pygame.display.init()


def blitted_one_by_one(size, centers, r_px, colors) -> np.ndarray:
    """The reference: every puck's sprite blitted alone, in order, at its rounded corner."""
    target, sprites = pygame.Surface(size), PuckSprites()
    target.fill(TABLE_BLUE)
    for (x, y), r, c in zip(centers.tolist(), r_px.tolist(), colors.tolist()):
        target.blit(sprites.get(r, tuple(c)), (round(x) - r, round(y) - r))
    return pygame.surfarray.array3d(target)


def drawn(size, centers, r_px, colors, sprites: PuckSprites) -> np.ndarray:
    target = pygame.Surface(size)
    target.fill(TABLE_BLUE)
    draw_pucks(target, sprites, centers, r_px, colors)
    assert not target.get_locked()
    return pygame.surfarray.array3d(target)


def test_thousands_of_small_pucks_stamped_look_exactly_as_blitted() -> None:
    # 9400 pucks 10 px apart on a 1280 x 720 target, the outer ones cut by its edges; radii 3 and 4, two colours.
    rng = np.random.default_rng(1)
    xs, ys = np.meshgrid(np.arange(-3.0, 1283.0, 10.0), np.arange(-3.0, 723.0, 10.0))
    centers = np.stack([xs.ravel(), ys.ravel()], axis=1) + rng.uniform(-0.45, 0.45, (xs.size, 2))
    n = len(centers)
    r_px = np.where(rng.random(n) < 0.9, 3, 4).astype(np.int64)
    colors = np.where(rng.random((n, 1)) < 0.8, WHITE, ORANGE).astype(np.uint8)
    sprites = PuckSprites()
    stamped = []
    original = sprites.stamp
    sprites.stamp = lambda r, color, target: stamped.append((r, color)) or original(r, color, target)

    image = drawn((1280, 720), centers, r_px, colors, sprites)

    assert (3, WHITE) in stamped  # the big groups took the numpy path
    assert np.array_equal(image, blitted_one_by_one((1280, 720), centers, r_px, colors))


def test_a_few_pucks_look_as_before_overlaps_included() -> None:
    # Five pucks, two overlapping: drawn in their own order, so the later one is on top.
    centers = np.array([[100.0, 100.0], [300.2, 200.7], [310.0, 205.0], [600.0, 50.0], [2.0, 300.0]])
    r_px = np.array([20, 12, 12, 3, 8])
    colors = np.array([ORANGE, WHITE, ORANGE, WHITE, (0, 200, 255)], dtype=np.uint8)
    image = drawn((640, 360), centers, r_px, colors, PuckSprites())
    assert np.array_equal(image, blitted_one_by_one((640, 360), centers, r_px, colors))
    # Pixels at the centres: the dark core of an outlined puck, a tiny one in its colour.
    assert tuple(image[100, 100]) == core_color(ORANGE)
    assert tuple(image[310, 205]) == core_color(ORANGE)  # on top of the white one
    assert tuple(image[600, 50]) == WHITE
    assert tuple(image[2, 300]) == core_color((0, 200, 255))


def test_stamped_pucks_overlap_in_their_own_order_as_blitted_ones_do() -> None:
    # 3000 pucks of radius 6 piled on a 200 x 150 px patch: the later puck is on top, as with blits.
    rng = np.random.default_rng(2)
    centers = rng.uniform((40.0, 30.0), (240.0, 180.0), (3000, 2))
    r_px = np.full(3000, 6)
    colors = np.tile(np.array(WHITE, dtype=np.uint8), (3000, 1))
    sprites = PuckSprites()
    stamped = []
    original = sprites.stamp
    sprites.stamp = lambda r, color, target: stamped.append(r) or original(r, color, target)
    image = drawn((320, 240), centers, r_px, colors, sprites)
    assert stamped == [6]
    assert np.array_equal(image, blitted_one_by_one((320, 240), centers, r_px, colors))


def drawn_big_one_by_one(size, centers, r_px, colors) -> np.ndarray:
    """The reference for big pucks: every one drawn alone, in order."""
    from airtable.app.pucks_view import draw_puck

    target = pygame.Surface(size)
    target.fill(TABLE_BLUE)
    for (x, y), r, c in zip(centers.tolist(), r_px.tolist(), colors.tolist()):
        draw_puck(target, tuple(c), (round(x), round(y)), r)
    return pygame.surfarray.array3d(target)


def test_thousands_of_big_pucks_draw_only_what_shows_and_look_the_same() -> None:
    # 3000 pucks of radius 200-400 px on a 320 x 240 target: stacked on five discs, or each big enough to fill it.
    # Drawn alone each costs its area; only the last filling one and those after it, one per disc, can show.
    rng = np.random.default_rng(3)
    spots = np.array([[0.0, 0.0], [320.0, 240.0], [0.0, 240.0], [160.4, 119.6], [500.0, 120.0]])
    centers = spots[rng.integers(0, 5, 3000)]
    r_px = rng.choice([200, 400], 3000)
    colors = rng.integers(0, 256, (3000, 3), dtype=np.uint8)
    calls = []
    real_circle = pygame.draw.circle
    pygame.draw.circle = lambda *a, **k: calls.append(a) or real_circle(*a, **k)
    try:
        image = drawn((320, 240), centers, r_px, colors, PuckSprites())
    finally:
        pygame.draw.circle = real_circle
    assert np.array_equal(image, drawn_big_one_by_one((320, 240), centers, r_px, colors))
    assert len(calls) <= 2 * 9  # at most the nine discs left (two circles each), where 3000 pucks were drawn


# Stamping against plain blitting on random scenes: small surfaces of odd and even widths, padded pitches
# and other pixel formats, groups of a few pucks (STAMP_MIN_PUCKS lowered) stamped a few at a time
# (STAMP_CHUNK_PIXELS lowered), pucks piled on each other, at the same corner, and cut by the clip.

PALETTE = (WHITE, ORANGE, (0, 200, 255), (250, 10, 10))
FORMATS = ("plain", "plain", "bgr", "padded pitch", "padded pitch", "display", "24 bit", "alpha")  # mostly stamped


def new_target(kind: str, w: int, h: int, pad: int) -> pygame.Surface:
    if kind == "bgr":
        return pygame.Surface((w, h), 0, 32, (0xFF, 0xFF00, 0xFF0000, 0))
    if kind == "padded pitch":  # rows `pad` pixels longer than the surface is wide
        pitch = 4 * (w + pad)
        return pygame.image.frombuffer(bytearray(pitch * h), (w, h), "RGBX", pitch)
    if kind == "display":
        return pygame.display.set_mode((w, h))
    if kind == "24 bit":
        return pygame.Surface((w, h), 0, 24)
    if kind == "alpha":
        return pygame.Surface((w, h), pygame.SRCALPHA, 32)
    return pygame.Surface((w, h))


def blitted_as_specified(target: pygame.Surface, centers, r_px, colors) -> None:
    """What draw_pucks draws, done with plain blits: each group (radius, colour) big enough and of a small
    enough sprite, in the order of (radius, colour), its pucks wholly inside the clip in their order; then
    all other pucks in their order. On a target whose pixels can't be written straight, all blitted in order."""
    from airtable.app import pucks_view

    sprites, clip = PuckSprites(), target.get_clip()
    w, h = target.get_size()
    pucks = [
        (round(x) - r, round(y) - r, r, tuple(c))
        for (x, y), r, c in zip(centers.tolist(), r_px.tolist(), colors.tolist())
        if x + r >= 0 and x - r <= w and y + r >= 0 and y - r <= h
    ]
    counts: dict[tuple, int] = {}
    for _, _, r, c in pucks:
        counts[r, c] = counts.get((r, c), 0) + 1
    direct = target.get_bytesize() == 4 and not target.get_flags() & pygame.SRCALPHA
    stamped = {
        key
        for key, n in counts.items()
        if direct
        and n >= pucks_view.STAMP_MIN_PUCKS
        and (key[0] + 1) ** 2 <= pucks_view.STAMP_MAX_PIXELS
        and np.any(pygame.surfarray.array3d(sprites.get(*key)) != pucks_view.COLORKEY, axis=2).sum()
        <= pucks_view.STAMP_MAX_PIXELS
    }

    def inside(x, y, r):
        return clip.contains(pygame.Rect(x, y, 2 * r + 1, 2 * r + 1))

    for key in sorted(stamped):
        for x, y, r, c in pucks:
            if (r, c) == key and inside(x, y, r):
                target.blit(sprites.get(r, c), (x, y))
    for x, y, r, c in pucks:
        if (r, c) not in stamped or not inside(x, y, r):
            target.blit(sprites.get(r, c), (x, y))


@st.composite
def scenes(draw):
    """A target and pucks on it, each at a random place, or near the one before (piles), or at the very
    place of one a few before (the same corner again, after others)."""
    w, h = draw(st.integers(16, 80)), draw(st.integers(16, 60))
    kind, pad = draw(st.sampled_from(FORMATS)), draw(st.integers(1, 3))
    radius = st.integers(2, 6) | st.integers(7, 9)  # 9: too big a sprite to stamp
    kinds = draw(st.lists(st.tuples(radius, st.sampled_from(PALETTE)), min_size=1, max_size=4))
    half = st.sampled_from([0.0, 0.25, 0.5, 0.75, 0.4999])  # rounding both ways, and half to even
    place = st.tuples(st.integers(-6, w + 6), half, st.integers(-6, h + 6), half)
    step = st.tuples(st.integers(0, len(kinds) - 1), st.sampled_from(["place", "near", "again"]), place)
    centers: list[tuple[float, float]] = []
    which = []
    for k, how, (x, fx, y, fy) in draw(st.lists(step, min_size=8, max_size=80)):
        if how == "place" or not centers:
            centers.append((x + fx, y + fy))
        elif how == "near":  # x, y as a small step from the one before
            centers.append((centers[-1][0] + x % 5 - 2 + fx, centers[-1][1] + y % 5 - 2 + fy))
        else:
            centers.append(centers[-1 - x % min(len(centers), 4)])
        which.append(kinds[k])
    inset = draw(st.tuples(*[st.integers(0, 5)] * 4))  # the clip: left, top, right and bottom margins
    clip = (inset[0], inset[1], max(1, w - inset[0] - inset[2]), max(1, h - inset[1] - inset[3]))
    return {
        "target": (kind, w, h, pad),
        "clip": clip,
        "centers": np.array(centers, dtype=float).reshape(-1, 2),
        "r_px": np.array([r for r, _ in which], dtype=np.int64),
        "colors": np.array([c for _, c in which], dtype=np.uint8).reshape(-1, 3),
        "min_pucks": draw(st.integers(1, 4)),
        "chunk_pixels": draw(st.sampled_from([1, 50, 200, 1000, 65536])),
    }


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scenes())
def test_stamped_pucks_look_exactly_as_blitted_on_any_scene_and_target(scene) -> None:
    from airtable.app import pucks_view

    images = []
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(pucks_view, "STAMP_MIN_PUCKS", scene["min_pucks"])
        patch.setattr(pucks_view, "STAMP_CHUNK_PIXELS", scene["chunk_pixels"])
        for draw in (
            lambda t: draw_pucks(t, PuckSprites(), scene["centers"], scene["r_px"], scene["colors"]),
            lambda t: blitted_as_specified(t, scene["centers"], scene["r_px"], scene["colors"]),
        ):
            target = new_target(*scene["target"])
            target.fill(TABLE_BLUE)
            if scene["clip"] is not None:
                target.set_clip(pygame.Rect(scene["clip"]))
            draw(target)
            assert not target.get_locked()
            images.append(pygame.surfarray.array3d(target))
    assert np.array_equal(images[0], images[1])


@settings(max_examples=200, deadline=None)
@given(st.lists(st.integers(0, 12) | st.integers(0, 1 << 40), min_size=1, max_size=300))
def test_groups_are_those_of_unique_with_few_keys_or_many(keys) -> None:
    from airtable.app.pucks_view import _groups

    keys = np.array(keys, dtype=np.int64)
    expected = np.unique(keys, return_inverse=True, return_counts=True)
    for got, want in zip(_groups(keys), expected):
        assert np.array_equal(got, want.ravel())


def test_a_crowd_of_tiny_pucks_is_drawn_at_its_own_size_and_a_puck_of_its_own_colour_enlarged() -> None:
    """A user test: a gas of 10000 white pucks (radius 0.5 px, 30 % of the table) drew 96 % of a 320x240
    window white: each was drawn with radius 2. Now a colour whose pucks so enlarged would cover a tenth of
    the window is drawn as it is (a pixel each where a puck covers under 1.5 pixels); a few pucks keep the
    least radius, and so does the one orange puck the lesson follows."""
    window = (320, 240)
    white, orange = (255, 255, 255), (255, 165, 0)
    n = 10000
    colors = np.array([orange] + [white] * (n - 1), dtype=np.uint8)
    for r, drawn in ((0.5, 0), (0.68, 0), (0.7, 1), (1.3, 1), (2.27, 2), (7.6, 8)):
        radii = radii_px(np.full(n, r), colors, window)
        assert radii[0] == max(drawn, MIN_PUCK_RADIUS_PX) and set(radii[1:].tolist()) == {drawn}
    few = 50  # 50 pucks of radius 2 cover 628 of the window's 76800 pixels: all enlarged
    assert radii_px(np.full(few, 0.5), colors[:few], window).tolist() == [MIN_PUCK_RADIUS_PX] * few
    assert radii_px(np.array([1e9]), colors[:1], window).tolist() == [1 << 20]  # any zoom: a sane integer
    # Drawn: the window's pixels lit where pucks cover a third of it, not all of it.
    rng = np.random.default_rng(1)
    target = pygame.Surface(window)
    centers = rng.uniform((0, 0), window, size=(n, 2))
    draw_pucks(target, PuckSprites(), centers, radii_px(np.full(n, 0.5), colors, window), colors)
    lit = (pygame.surfarray.array3d(target).sum(axis=2) > 0).mean()
    assert 0.1 < lit < 0.15  # 10000 single pixels on 76800, some on the same one
