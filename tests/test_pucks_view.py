"""Drawing pucks: thousands stamped with numpy look exactly as blitted one by one; a few keep their order."""

from __future__ import annotations

import numpy as np
import pygame
import pytest

from airtable.app.pucks_view import PuckSprites, core_color, draw_pucks

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
