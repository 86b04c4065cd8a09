"""Stages 1 and 2: forces, then semi-implicit Euler, v += (F/m + g) dt and x += v dt.

The forces are the pulls (cursor strings), the springs and gravity
(forces.py). What a puck's springs ask beyond what an explicit step can hold
is solved implicitly (implicit.py), with the walls braced; springs too stiff
for the step are stepped in substeps instead (substeps.py), so their slow
modes keep ringing.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from airtable.physics import forces, implicit, substeps

if TYPE_CHECKING:
    from airtable.physics.context import StepContext
    from airtable.physics.storage import Storage

# Said once (in `notices`) when springs are first solved implicitly (beyond what substeps.py takes). (A user test's
# chain of 8 at 25000 times the explicit limit, 5.8 steps a period, lost about 3 % a period, not the fifth once said.)
IMPLICIT_NOTICE = (
    f"Some springs vibrate faster than even {substeps.MAX_SUBSTEPS} substeps of a step can follow: the step"
    " solves them implicitly, so they hold and sag as their k says, but their vibrations die away, the fastest"
    " within a step or two, and even the slowest lose some of their swing each period, from a few per cent to"
    " nine tenths, the more the stiffer the springs. A shorter step, softer springs or heavier pucks keep them"
    " ringing."
)
# Passes that add walls to the implicit solve (see _brace_walls).
BRACE_PASSES = 4
# A guard against runaway values: nothing on a table moves this fast (the pi demo's light puck, at 100^4 times the
# heavy one's mass, 10 km/s). Every hit is resolved in turn, some 0.1 ms each among many pucks: a puck at 1 Mm/s
# in a crowd of 40 hit 27000 times a step, 6 s; at 1 Gm/s a step took minutes (a user test's).
MAX_SPEED_MPS = 1e5
# Said once when a puck is slowed to MAX_SPEED_MPS.
SPEED_NOTICE = (
    f"A puck went faster than {MAX_SPEED_MPS / 1000:g} km/s: it was slowed to that, so that each step's hits"
    " can still be followed one by one."
)


def forces_and_integrate(table: Storage, ctx: StepContext) -> None:
    """Forces and integration in as many substeps as the springs need (substeps.py); sets ctx.kick,
    the velocity the whole step's forces gave each puck. Forces written from outside act in every substep."""
    n = 1
    if table.n_springs:
        n = substeps.count(table.mass_kg, *table.spring_ends, table.spring_k_Npm, ctx.dt)
    if n == 1:
        ctx.kick = integrate(table, ctx, add_forces(table, ctx.pulls, ctx.dt), ctx.dt)
        return
    h, outside = ctx.dt / n, table.force_N.copy()
    for s in range(n):
        if s:
            table.force_N[:] = outside
        add = integrate(table, ctx, add_forces(table, ctx.pulls, h), h)
        ctx.kick = add if ctx.kick is None else ctx.kick if add is None else ctx.kick + add


def add_forces(table: Storage, pulls, dt: float) -> forces.Implicit | None:
    """Add the pulls' and springs' forces to force_N; return what the step takes implicitly (None: nothing)."""
    if not pulls and table.n_springs == 0:
        return None  # a gas: nothing to add, and no (N, 2) arrays to make and check
    force = table.force_N
    parts = forces.Implicit.empty(table.n_pucks)
    if pulls:
        forces.add_pull_forces(force, parts, pulls, table.pos_m, table.vel_mps, table.mass_kg, dt)
    if table.n_springs:
        a, b, f1 = spring_forces(table, dt, parts)
        forces.add_spring_forces(force, a, b, f1)
    return parts


def integrate(table: Storage, ctx: StepContext, parts: forces.Implicit | None, dt: float) -> np.ndarray | None:
    """Semi-implicit Euler: v += (F/m + g) dt (the implicit parts solved for), then x += v dt.

    Returns the velocity the forces and gravity added to each puck ((N, 2),
    or (2,) if the same for all), or None if nothing pushed: the contact
    stage's rest speeds come from it (resting.rest_speeds).
    """
    pos, vel, force, mass = table.pos_m, table.vel_mps, table.force_N, table.mass_kg
    kick = None
    if parts is not None and parts.any:
        rhs = dt * (force + parts.lag)
        if table.gravity_on:
            rhs[:, 1] -= table.gravity_mps2 * dt * mass
        dv = implicit_velocity_change(table, parts, rhs, dt)
        vel += dv
        kick = dv
    elif force.any():  # usually nothing pushes: skip the (N, 2) update (any() beats count_nonzero on floats)
        dv = force * (dt / mass)[:, None]
        if table.gravity_on:
            dv[:, 1] -= table.gravity_mps2 * dt
        vel += dv
        kick = dv
    elif table.gravity_on:
        vel[:, 1] -= table.gravity_mps2 * dt
        kick = np.array([0.0, -table.gravity_mps2 * dt])
    if ctx.sleepers is not None:
        vel[ctx.sleepers] = 0.0  # sleepers stay where they are
    if _cap_speeds(vel):
        table.notices.say("fast", SPEED_NOTICE)
    pos += vel * dt
    return kick


def _cap_speeds(vel: np.ndarray) -> bool:
    """A guard against runaway values: slow down what is faster than MAX_SPEED_MPS; whether any was."""
    if len(vel) == 0 or not math.sqrt(2.0) * float(np.abs(vel).max()) > MAX_SPEED_MPS:  # sqrt 2 x the largest part
        return False
    speed = np.hypot(vel[:, 0], vel[:, 1])  # not lengths(): v^2 may overflow here
    vel *= np.minimum(1.0, MAX_SPEED_MPS / np.maximum(speed, 1e-300))[:, None]
    return bool((speed > MAX_SPEED_MPS).any())


def implicit_velocity_change(table: Storage, parts: forces.Implicit, rhs: np.ndarray, dt: float) -> np.ndarray:
    """dv from the implicit solve (implicit.py), with walls braced and the springs' turning taken in."""
    mass = table.mass_kg
    dv = implicit.velocity_change(mass, parts, rhs)
    released = np.zeros(dv.shape, dtype=bool)
    walls = (table.size_m, table.cr_wall)
    for _ in range(BRACE_PASSES):  # bracing one puck can push another of its body into a wall
        braced = implicit.brace_walls(table.pos_m, table.vel_mps, dv, table.radius_m, walls, parts, released, dt)
        if not braced:
            break
        dv = implicit.velocity_change(mass, parts, rhs)
        # A wall only pushes: let go where it had to pull the puck to keep it bouncing.
        pulled = implicit.wall_impulses(mass, parts, rhs, dv) * parts.fixed_side < 0.0
        if pulled.any():
            parts.fixed &= ~pulled
            released |= pulled
            dv = implicit.velocity_change(mass, parts, rhs)
    if implicit.correct_for_turning(table.pos_m, table.vel_mps + dv, mass, parts, rhs, dt):
        dv = implicit.velocity_change(mass, parts, rhs)
    return dv


def spring_forces(
    table: Storage, dt: float, parts: forces.Implicit | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(rows of p1, rows of p2, force on p1) for every spring; p2 gets minus that.

    With `parts`, a step is being taken: each spring's share beyond its
    pucks' explicit budget is recorded there, with its lag forces added in.
    """
    a, b = table.spring_ends
    mass, length = table.mass_kg, table.spring_length_m
    mu = forces.reduced_masses(mass, a, b)
    k, c = forces.effective_spring(table.spring_k_Npm, table.spring_damper_Nspm, mu, dt)
    n, f1 = forces.spring_forces(table.pos_m, table.vel_mps, a, b, length, k, c)
    if parts is not None:
        table.spring_dt_s = dt
        frac_k, frac_c = forces.explicit_fractions(mass, a, b, k, c, dt)
        if frac_k.min() < 1.0 or frac_c.min() < 1.0:  # else all explicit, as soft springs usually are
            k_i, c_i = (1.0 - frac_k) * k, (1.0 - frac_c) * c
            ia, ib, lag = forces.implicit_springs(parts, table.vel_mps, (a, b, n), k_i, c_i, dt)
            forces.add_spring_forces(parts.lag, ia, ib, lag)
            if frac_k.min() < 1.0:
                table.notices.say("implicit", IMPLICIT_NOTICE)
        if (k < table.spring_k_Npm).any():
            _notice_softened(table, k)
    return a, b, f1


def _notice_softened(table: Storage, k: np.ndarray) -> None:
    for s in np.flatnonzero(k < table.spring_k_Npm):
        table.notices.say(
            ("softened", int(s)),
            f"Spring {s} asks for k = {table.spring_k_Npm[s]:.3g} N/m, more than a step can compute;"
            f" it acts with k = {k[s]:.3g} N/m (its k_effective_Npm).",
        )
