"""Fast pucks: swept over their step, so they never pass through a puck or a wall.

A step moves a puck by v dt. When that is a good part of a radius, the
overlap test at the end of the step can miss a hit altogether (the puck is
already past) or find it after the closest approach (it looks as if the pair
were parting). This stage runs before the others and finds, for each fast
puck, the first moment in the step when it touches another puck or a wall,
solving |d + w t| = r1 + r2 for t (d, w: relative position and velocity).
Events are resolved one at a time in time order: both pucks are put where
they touch, collide with the course's 1D collision along the line of
centres, and go on with their new velocities for the rest of the step. So a
hit resolved here is exact, whatever the step, and the pucks' paths are
reversible: negating every velocity retraces them.

A pair that still overlaps and approaches at the end of the step is left to
the pair stage and its correction mode (the course's model, and what demo 2p
teaches); this stage takes only the hits the pair stage would miss or get
backwards.

Each puck carries an "origin" o with position o + v t at time t of the step
(t = 0 at its start), so a velocity change at time t only resets o.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from airtable.physics import vectors

# A puck moving more than this share of its radius in a step is swept (a slower
# one cannot pass through a puck, and in a gas at 1 m/s almost none is this fast).
FAST_FRACTION = 0.5
# A bound on the events of one step (the pi demo at n = 4 needs hundreds).
MAX_EVENTS = 20_000
# Hits slower than this (m/s, relative, along the normal) are left to the pair
# and contact stages. Without it, pucks that collide inelastically in a cluster
# hit each other again and again at ever smaller speeds (inelastic collapse):
# 200000 events in one step, 25 s, in a 300-puck gas at restitution 0.
MIN_APPROACH_MPS = 1e-3


@dataclass
class Swept:
    """What the sweep of one step did: puck-pair hits (rows i, j, normals, times) and wall hits."""

    i: list
    j: list
    normal: list
    t: list
    x: list  # (position of i, position of j) where they touched
    v_before: list  # (velocity of i, of j) before the hit
    v_after: list
    walls: int = 0


def fast_rows(vel: np.ndarray, radius: np.ndarray, dt: float) -> np.ndarray:
    """Rows that move more than FAST_FRACTION of their radius this step."""
    if dt <= 0.0 or len(vel) == 0:
        return np.empty(0, dtype=np.intp)
    v2 = vectors.squared_lengths(vel)
    if v2.max() * dt * dt <= (FAST_FRACTION * float(radius.min())) ** 2:
        return np.empty(0, dtype=np.intp)  # the usual case: nobody is that fast
    lim = FAST_FRACTION * radius / dt
    return np.flatnonzero(v2 > lim * lim)


def _near(o, vel, radius, rows, dt) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (row, other) whose paths over the step come within reach: each of `rows` against every puck.

    Two pucks can touch during the step only if the middles of their paths are
    closer than their reach plus half of each path.
    """
    mid = o + 0.5 * dt * vel
    half = 0.5 * dt * vectors.lengths(vel)
    d = mid[rows][:, None, :] - mid[None, :, :]
    lim = radius[rows][:, None] + radius[None, :] + half[rows][:, None] + half[None, :]
    near = (d * d).sum(-1) < lim * lim
    near[np.arange(len(rows)), rows] = False
    m, k = np.nonzero(near)
    return rows.take(m), k


def _first_pair_hit(o, vel, radius, ci, cj, t_now, dt):
    """(t, a, b) of the earliest hit among the candidate pairs (ci, cj) after t_now, or None."""
    if len(ci) == 0:
        return None
    d = vectors.take(o, ci) - vectors.take(o, cj)  # origins: positions at t = 0
    w = vectors.take(vel, ci) - vectors.take(vel, cj)
    reach = radius.take(ci) + radius.take(cj)
    ww, dw, dd = vectors.squared_lengths(w), vectors.dot_rows(d, w), vectors.squared_lengths(d)
    # |d + w t|^2 = reach^2: ww t^2 + 2 dw t + dd - reach^2 = 0, the earlier root.
    disc = dw * dw - ww * (dd - reach * reach)
    ok = (disc > 0.0) & (ww > 0.0)
    t = np.where(ok, (-dw - np.sqrt(np.where(ok, disc, 0.0))) / np.where(ok, ww, 1.0), 0.0)
    # Approaching at the hit (faster than MIN_APPROACH_MPS: (d + w t).w / reach is
    # the normal speed), and not already touching at t_now (the pair stage's).
    gap_now = dd + 2.0 * dw * t_now + ww * t_now * t_now - reach * reach
    approaching = dw + ww * t < -MIN_APPROACH_MPS * reach
    valid = ok & (t >= t_now - 1e-12 * dt) & (t <= dt) & approaching & (gap_now > -1e-12 * reach * reach)
    if not valid.any():
        return None
    t = np.where(valid, t, np.inf)
    k = int(np.argmin(t))
    return float(t[k]), int(ci[k]), int(cj[k])


def _first_wall_hit(o, vel, radius, size_m, movers, t_now, dt):
    """(t, mover, axis) of the earliest wall hit of a mover after t_now, or None."""
    p, v, r = o[movers], vel[movers], radius[movers][:, None]
    wall = np.where(v < 0.0, r, size_m - r)  # the wall each mover heads for, per axis
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(v != 0.0, (wall - p) / v, np.inf)
    inside_now = (p + v * t_now >= r - 1e-12) & (p + v * t_now <= size_m - r + 1e-12)
    t = np.where(inside_now & (t >= t_now) & (t <= dt), t, np.inf)
    if not np.isfinite(t).any():
        return None
    k = int(np.argmin(t))
    m, axis = divmod(k, 2)
    return float(t.flat[k]), int(movers[m]), axis


def _ends_overlapping_and_approaching(o, vel, radius, a, b, dt) -> bool:
    """Whether the pair (a, b) overlaps and approaches at the end of the step: the pair stage's case."""
    d = o[a] - o[b] + (vel[a] - vel[b]) * dt
    reach = radius[a] + radius[b]
    return float(d @ d) < reach * reach and float(d @ (vel[a] - vel[b])) < 0.0


def sweep(pos, vel, radius, mass, size_m, cr_puck, cr_wall, dt, pucks=True, movers=None, leave=False) -> Swept:
    """Resolve the fast pucks' hits of this step in time order, in place (see the module docstring).

    pos are the positions at the end of the step (x = x0 + v dt already done).
    leave: a hit that would end the step overlapping and approaching is left
    to the pair stage (its correction mode is what a demo shows).
    """
    out = Swept([], [], [], [], [], [], [])
    movers = fast_rows(vel, radius, dt) if movers is None else movers
    if len(movers) == 0:
        return out
    o = pos - vel * dt  # each puck's position at t = 0 of the step
    t_now = 0.0
    touched: set[int] = set()
    none = np.empty(0, dtype=np.intp)
    ci, cj = _near(o, vel, radius, movers, dt) if pucks else (none, none)
    for _ in range(MAX_EVENTS):
        hit = _first_pair_hit(o, vel, radius, ci, cj, t_now, dt)
        wall = _first_wall_hit(o, vel, radius, size_m, movers, t_now, dt)
        if wall is not None and (hit is None or wall[0] < hit[0]):
            t_now, a, axis = wall
            x = o[a] + vel[a] * t_now
            vel[a, axis] *= -cr_wall
            o[a] = x - vel[a] * t_now
            out.walls += 1
            touched.add(a)
            if pucks:  # a new path for a: its candidates again
                keep = (ci != a) & (cj != a)
                ni, nj = _near(o, vel, radius, np.array([a]), dt)
                ci, cj = np.concatenate([ci[keep], ni]), np.concatenate([cj[keep], nj])
        elif hit is not None:
            t_now, a, b = hit
            if leave and _ends_overlapping_and_approaching(o, vel, radius, a, b, dt):
                break  # the pair stage's, and with it whatever comes later in the step
            _collide(o, vel, mass, a, b, t_now, cr_puck, out)
            touched.update((a, b))
            movers = np.union1d(movers, [a, b])
            # New paths for a and b: their candidates again.
            keep = (ci != a) & (ci != b) & (cj != a) & (cj != b)
            ni, nj = _near(o, vel, radius, np.array([a, b]), dt)
            ci, cj = np.concatenate([ci[keep], ni]), np.concatenate([cj[keep], nj])
        else:
            break
    rows = np.fromiter(touched, dtype=np.intp, count=len(touched))
    pos[rows] = o[rows] + vel[rows] * dt  # the others are where they were
    return out


def _collide(o, vel, mass, a, b, t, cr, out: Swept) -> None:
    """Collide a and b where they touch at time t, along the line of centres; reset their origins."""
    xa, xb = o[a] + vel[a] * t, o[b] + vel[b] * t
    n = xa - xb
    n /= np.sqrt(n @ n)
    out.x.append((xa, xb))
    out.v_before.append((vel[a].copy(), vel[b].copy()))
    u = (vel[a] - vel[b]) @ n
    jn = -(1.0 + cr) * u / (mass[a] + mass[b])  # change of relative normal speed, shared by mass
    vel[a] += jn * mass[b] * n
    vel[b] -= jn * mass[a] * n
    o[a], o[b] = xa - vel[a] * t, xb - vel[b] * t
    out.i.append(a)
    out.j.append(b)
    out.normal.append(n.copy())
    out.t.append(t)
    out.v_after.append((vel[a].copy(), vel[b].copy()))
