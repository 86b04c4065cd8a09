"""Under gravity, pucks sliding along the floor collide with each other and the side walls as without it.

A user test: with gravity on, two pucks sliding along the floor into each other at 0.15 m/s stuck
together at restitution 1, a puck at 2 cm/s stopped dead at the side wall, and a puck at 5 cm/s
stopped at a sleeping one, their momentum gone. Gravity presses them on the floor, not on each other
or on a side wall: those hits are collisions at their restitution, however slow.

By hand, for a head-on hit along the floor of a puck of mass ma at speed v on a still one of mass mb
at restitution e (the course's 1D collision along the normal): afterwards
    va = (ma - e mb) v / (ma + mb),    vb = (1 + e) ma v / (ma + mb),
and a puck hitting a side wall at v leaves it at e v.
"""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable.physics.table import AirTable

FLOOR_R = 0.25
GAP_M = 0.1


def _floor_pair(v: float, density_b: float, e: float, dt: float, sleeping: bool, mode: str):
    """Puck a sliding along the floor at v into a still puck b GAP_M ahead; run until a quarter second
    after b has moved (b falls asleep while a comes, if `sleeping`)."""
    table = AirTable()
    table.gravity_on, table.sleeping, table.puck_correction = True, sleeping, mode
    table.cr_puck = e
    a = table.add_puck((3.0, FLOOR_R), FLOOR_R, vel_mps=(v, 0.0))
    b = table.add_puck((3.0 + 2 * FLOOR_R + GAP_M, FLOOR_R), FLOOR_R, density_kgpm2=0.3 * density_b)
    after = round(0.25 / dt)
    for _ in range(round((GAP_M / v + 1.0) / dt)):
        table.step(dt)
        after -= b.vel_mps[0] != 0.0
        if after == 0:
            break
    assert after == 0, "b was hit"
    return table, a, b


@settings(max_examples=25, deadline=None, derandomize=True)
@given(
    v=st.floats(0.01, 0.5),
    density_b=st.floats(0.1, 10.0),
    e=st.sampled_from([0.0, 0.5, 0.9, 1.0]),
    dt=st.sampled_from([1 / 240, 1 / 60]),
    sleeping=st.booleans(),
    mode=st.sampled_from(["perfect-kiss", "two-step"]),
)
def test_a_hit_along_the_floor_keeps_momentum_and_its_restitution(v, density_b, e, dt, sleeping, mode) -> None:
    table, a, b = _floor_pair(v, density_b, e, dt, sleeping, mode)
    ma, mb = table.mass_kg[0], table.mass_kg[1]
    assert a.vel_mps[0] == pytest.approx((ma - e * mb) * v / (ma + mb), abs=1e-9)
    assert b.vel_mps[0] == pytest.approx((1 + e) * ma * v / (ma + mb), abs=1e-9)
    for puck in (a, b):  # and still on the floor
        assert puck.pos_m[1] == pytest.approx(FLOOR_R, abs=1e-6) and abs(puck.vel_mps[1]) < 1e-6


@pytest.mark.parametrize("e", [1.0, 0.7])
@pytest.mark.parametrize("v", [0.02, 0.1])
def test_a_puck_sliding_into_a_side_wall_bounces_at_its_restitution(v: float, e: float) -> None:
    table = AirTable()
    table.gravity_on, table.cr_wall = True, e
    puck = table.add_puck((table.width_m - FLOOR_R - 0.2, FLOOR_R), FLOOR_R, vel_mps=(v, 0.0))
    for _ in range(round(2 * 0.2 / v * 240)):  # there and back
        table.step(1 / 240)
    assert puck.vel_mps[0] == pytest.approx(-e * v, abs=1e-9)
    assert table.wall_collision_count == 1
    assert puck.pos_m[1] == pytest.approx(FLOOR_R, abs=1e-6)


def _drop_on_the_floor_puck(vx: float, dt: float) -> tuple[float, float, float]:
    """An equal puck dropped 2 m onto one on the floor, both sliding at vx: (the top one's highest after
    the hit, the energy at the start, at the end)."""
    table = AirTable()
    table.gravity_on, table.cr_puck, table.cr_wall = True, 1.0, 1.0
    table.add_puck((2.0, 0.4), 0.4, vel_mps=(vx, 0.0))
    top = table.add_puck((2.0, 3.2), 0.4, vel_mps=(vx, 0.0))
    start = table.kinetic_energy_J() + table.gravity_energy_J()
    highest = 0.0
    for step in range(round(2.5 / dt)):  # down (0.64 s to the hit) and back up (0.64 s)
        table.step(dt)
        if step * dt > 1.0:
            highest = max(highest, float(top.pos_m[1]))
    return highest, start, table.kinetic_energy_J() + table.gravity_energy_J()


@pytest.mark.parametrize("dt", [1 / 240, 1 / 60])
def test_a_puck_dropped_on_one_sliding_along_the_floor_bounces_as_on_one_at_rest(dt: float) -> None:
    """A helper's user test: a puck dropped 2 m onto an equal one on the floor bounced back up when the
    lower one sat still, and stuck to it, half the energy gone, when both slid sideways (at 2 cm/s or
    1 m/s): the lower one, held on the floor, was driven into it and never bounced. By hand (restitution
    1, equal masses): the top one stops, the lower one hits the floor and comes back up into it, and the
    top one leaves at the speed it came, in any frame sliding along the floor. (At dt 1/60 it rises 1.4 %
    short of its start, in every frame alike: the pair's hit is not resolved on its parabola.)"""
    at_rest = _drop_on_the_floor_puck(0.0, dt)
    for vx in (0.02, 1.0):
        highest, start, end = _drop_on_the_floor_puck(vx, dt)
        assert highest == pytest.approx(at_rest[0], abs=1e-6)
        assert end - start == pytest.approx(at_rest[2] - at_rest[1], abs=1e-6)
    assert at_rest[0] == pytest.approx(3.2, abs=0.02 if dt < 1 / 100 else 0.05)
    assert at_rest[2] == pytest.approx(at_rest[1], rel=0.01 if dt < 1 / 100 else 0.03)


@pytest.mark.parametrize("v", [0.001, 0.005, 0.011])
def test_a_lone_puck_sliding_slowly_along_the_floor_keeps_sliding(v: float) -> None:
    """A helper's user test: under gravity a lone puck sliding along the floor slower than 1.2 cm/s stopped
    dead after half a second (it fell asleep: it stayed within SLEEP_DRIFT_M, 5 mm, of where it was slow).
    On a frictionless table it slides on; a puck resting among others still falls asleep."""
    table = AirTable()
    table.gravity_on = True
    puck = table.add_puck((3.0, FLOOR_R), FLOOR_R, vel_mps=(v, 0.0))
    for _ in range(2 * 240):
        table.step(1 / 240)
    assert puck.vel_mps[0] == v and not table.asleep.any()
    assert puck.pos_m[0] == pytest.approx(3.0 + 2 * v, abs=1e-9)
