"""The collision formulas, each written once, in plain Python floats: read these first.

* `collide_1d`: the 1D collision along the normal (momentum kept, relative
  speed reversed times the restitution);
* `contact_time`: when two moving discs first touch (the time of first contact),
  and `wall_time`: when a puck reaches a wall;
these are the code: the hits in time order (events.py) call them for every
hit. `collide_pair` does for one overlapping pair what the pair stage
(pairs.py) does for thousands at once with numpy; the tests check that the two
agree to round-off on random scenes.

Vectors are (x, y) tuples in metres and m/s. Puck 1 and puck 2 overlap when
their centres are closer than r1 + r2. The normal n is the unit vector from
puck 2 to puck 1 along the line of centres; the tangent is perpendicular.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from airtable.physics.pairs import REST_SPEED_MPS

Vec = tuple[float, float]


class Disc(NamedTuple):
    """One puck: position (m), velocity (m/s), radius (m), mass (kg)."""

    pos: Vec
    vel: Vec
    r: float
    m: float


def _add(a: Vec, b: Vec) -> Vec:
    return (a[0] + b[0], a[1] + b[1])


def _sub(a: Vec, b: Vec) -> Vec:
    return (a[0] - b[0], a[1] - b[1])


def _scale(s: float, a: Vec) -> Vec:
    return (s * a[0], s * a[1])


def _dot(a: Vec, b: Vec) -> float:
    return a[0] * b[0] + a[1] * b[1]


def _unit(d: Vec, key: int = 0) -> tuple[Vec, float]:
    """d / |d| and |d|; two pucks exactly on top of each other get the
    direction key * the golden angle (key: the pair's i + j)."""
    dist = math.sqrt(d[0] * d[0] + d[1] * d[1])
    if dist > 0.0:
        return (d[0] / dist, d[1] / dist), dist
    angle = key * math.pi * (3.0 - math.sqrt(5.0))
    return (math.cos(angle), math.sin(angle)), dist


def collide_1d(u1: float, u2: float, m1: float, m2: float, cr: float) -> tuple[float, float]:
    """Speeds after a 1D collision with restitution cr: momentum is kept, and
    the relative speed reverses, times cr: v1 - v2 = -cr (u1 - u2)."""
    p = m1 * u1 + m2 * u2
    v1 = (p - m2 * cr * (u1 - u2)) / (m1 + m2)
    v2 = (p + m1 * cr * (u1 - u2)) / (m1 + m2)
    return v1, v2


def contact_time(d: Vec, w: Vec, reach: float) -> tuple[float, float] | None:
    """(t, u): how long until two discs touch, and how fast they then approach along the line of
    centres (m/s); None if they never touch while approaching.

    d = x1 - x2 (m) and w = v1 - v2 (m/s) now; they touch when |d + w t| = reach,
    the smaller root of w.w t^2 + 2 d.w t + d.d - reach^2 = 0, written as
    c / (sqrt(disc) - d.w) so that no digits cancel. Discs already touching or
    overlapping (by round-off, or resting) that approach touch now: t = 0.
    The one tolerance policy: none; round-off decides, as it would for the oracle.
    """
    dw = _dot(d, w)
    if not dw < 0.0:
        return None  # parting, or still: they never meet
    dd = _dot(d, d)
    c = dd - reach * reach
    if c <= 0.0:
        return 0.0, -dw / math.sqrt(dd)  # touching now (dd > 0: dw < 0 needs d != 0)
    disc = dw * dw - _dot(w, w) * c
    if not disc > 0.0:
        return None  # they pass by (or only graze)
    root = math.sqrt(disc)
    return c / (root - dw), root / reach


def wall_time(x: float, v: float, lo: float, hi: float) -> float | None:
    """How long until a centre at x moving at v (along one axis) reaches lo (moving down) or hi
    (moving up): where a puck of radius r touches the walls at 0 and size (lo = r, hi = size - r).
    0 if it is there or past already; None if it does not move along this axis."""
    if v < 0.0:
        return max((lo - x) / v, 0.0)
    if v > 0.0:
        return max((hi - x) / v, 0.0)
    return None


def collide_along(n: Vec, v1: Vec, v2: Vec, m1: float, m2: float, cr: float) -> tuple[Vec, Vec]:
    """Velocities after the collision along the normal n: the normal parts
    collide in 1D, the tangential parts are kept."""
    u1, u2 = _dot(v1, n), _dot(v2, n)
    w1, w2 = collide_1d(u1, u2, m1, m2, cr)
    return _add(v1, _scale(w1 - u1, n)), _add(v2, _scale(w2 - u2, n))


def _push_apart(x1: Vec, x2: Vec, p1: Disc, p2: Disc, key: int) -> tuple[Vec, Vec]:
    """Part a pair that still overlaps along its line of centres; the lighter puck moves more."""
    n, dist = _unit(_sub(x1, x2), key)
    left = max(p1.r + p2.r - dist, 0.0)
    m_sum = p1.m + p2.m
    return _add(x1, _scale(left * p2.m / m_sum, n)), _sub(x2, _scale(left * p1.m / m_sum, n))


def _time_since_contact(p1: Disc, p2: Disc, dt_s: float) -> float | None:
    """How long ago the pair first touched, if this step's motion explains the overlap, else None.

    With d = x1 - x2 and w = v1 - v2, the centres were r1 + r2 apart t ago:
    |d - w t| = r1 + r2, a quadratic in t; the larger root is the first contact.
    """
    d, w = _sub(p1.pos, p2.pos), _sub(p1.vel, p2.vel)
    reach = p1.r + p2.r
    ww, dw = _dot(w, w), _dot(d, w)
    if not ww > REST_SPEED_MPS**2:
        return None  # not moving: nothing to back up along
    disc = max(dw * dw - ww * (_dot(d, d) - reach * reach), 0.0)
    t = (dw + math.sqrt(disc)) / ww
    return t if 0.0 <= t <= dt_s * (1.0 + 1e-9) + 1e-15 else None


def collide_pair(p1: Disc, p2: Disc, cr: float, mode: str, dt_s: float, key: int = 0) -> tuple[Disc, Disc]:
    """The two pucks after their collision, with the position correction `mode`.

    mode is "off", "two-step" or "perfect-kiss"; dt_s is the step that
    brought them into overlap; key (the pair's i + j) picks the direction
    in which two pucks exactly on top of each other part. A pair that does
    not overlap is returned as is.
    """
    n, dist = _unit(_sub(p1.pos, p2.pos), key)
    overlap = p1.r + p2.r - dist
    if not overlap > 0.0:
        return p1, p2
    m1, m2 = p1.m, p2.m
    x1, x2 = p1.pos, p2.pos
    v1, v2 = p1.vel, p2.vel
    vn = _dot(_sub(v1, v2), n)  # relative normal speed; negative: approaching
    t_kiss = _time_since_contact(p1, p2, dt_s) if mode == "perfect-kiss" else None
    if t_kiss is not None:
        # Perfect kiss: back both pucks up t along their velocities to first
        # contact, collide there along the normal at contact, and move forward
        # t with the new velocities. Approaching is judged at contact.
        c1, c2 = _sub(x1, _scale(t_kiss, v1)), _sub(x2, _scale(t_kiss, v2))
        n, _ = _unit(_sub(c1, c2), key)
        if _dot(_sub(v1, v2), n) < 0.0:
            v1, v2 = collide_along(n, v1, v2, m1, m2, cr)
            x1, x2 = _add(c1, _scale(t_kiss, v1)), _add(c2, _scale(t_kiss, v2))
    elif vn < -REST_SPEED_MPS:
        v1, v2 = collide_along(n, v1, v2, m1, m2, cr)
        if mode != "off":
            # Two-step: back up the penetration time t_p = overlap / |vn| along
            # the normal velocities (the pair parts by the overlap), then go
            # forward t_p with the normal velocities after the collision (it
            # parts by e times the overlap more), so it ends e times the
            # overlap apart: touching at e = 0. An overlap deeper than this
            # step's approach is capped at dt.
            t_p = min(overlap / -vn, dt_s)
            x1 = _add(x1, _scale(t_p * (_dot(v1, n) - _dot(p1.vel, n)), n))
            x2 = _add(x2, _scale(t_p * (_dot(v2, n) - _dot(p2.vel, n)), n))
    if mode != "off":
        x1, x2 = _push_apart(x1, x2, p1, p2, key)  # whatever still overlaps
    return Disc(x1, v1, p1.r, m1), Disc(x2, v2, p2.r, m2)
