"""A light puck squeezed between two heavier ones below restitution 1 (collapse.py, events.Step.stick).

The exact run has infinitely many ever smaller hits in a finite time (inelastic collapse) and
ends with the three moving together. Found by a user test's random rows: the engine capped a
pair's hits in a step and left the rest to the overlap correction, which let the light puck
pass through (a 1 kg cue at 100 m/s, a 0.1 kg puck touching a 1 kg one, restitution 0; and a
0.1 g one at restitution 0.95, which ended 30 m ahead at 157 m/s).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from airtable.physics import collapse
from airtable.physics.table import AirTable

R = 0.1


def row(cue_kg: float, light_kg: float, heavy_kg: float, speed: float, cr: float) -> AirTable:
    """On one line mid-table (no wall within reach): the cue at `speed`, 1.8 m behind a light puck that
    touches a still heavy one."""
    table = AirTable(400.0, 20.0)
    table.puck_correction = "perfect-kiss"
    table.cr_puck = cr
    for x, kg, v in ((198.0, cue_kg, speed), (200.0, light_kg, 0.0), (200.0 + 2 * R, heavy_kg, 0.0)):
        table.add_puck((x, 10.0), R, kg / (math.pi * R * R), (v, 0.0))
    return table


def run(table: AirTable, dt: float, seconds: float = 0.6) -> None:
    """Step until the row is well past its hits, checking the order and the energy every step."""
    start = table.kinetic_energy_J()
    for _ in range(round(seconds / dt)):
        table.step(dt)
        x = table.pos_m[:, 0]
        assert x[1] - x[0] > 2 * R - 1e-6 and x[2] - x[1] > 2 * R - 1e-6, x  # in order, never through
        assert table.kinetic_energy_J() <= start * (1 + 1e-12)


@settings(max_examples=40, derandomize=True, deadline=None)
@given(
    ratio=st.floats(2.0, 1e4),
    heavy=st.floats(0.2, 5.0),
    speed=st.floats(5.0, 150.0),
    cr=st.sampled_from([0.0, 0.5, 0.9]) | st.floats(0.0, 0.95),
    dt=st.sampled_from([1 / 240, 1 / 60, 1 / 30]),
)
@example(ratio=10.0, heavy=1.0, speed=100.0, cr=0.0, dt=1 / 60)  # the light puck ended past the heavy one
@example(ratio=1e4, heavy=1.0, speed=20.0, cr=0.95, dt=1 / 30)  # 30 m ahead at 157 m/s
def test_a_squeezed_light_puck_never_passes_through_nor_gains_energy(ratio, heavy, speed, cr, dt) -> None:
    table = row(1.0, heavy / ratio, heavy, speed, cr)
    momentum = table.momentum_Ns().copy()
    run(table, dt)
    np.testing.assert_allclose(table.momentum_Ns(), momentum, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("dt", [1 / 240, 1 / 60, 1 / 30])
@pytest.mark.parametrize("light_kg", [0.1, 1e-4])
def test_at_restitution_0_the_three_move_on_together(light_kg: float, dt: float) -> None:
    # By hand: nothing bounces at restitution 0, so all three end at the total momentum over the total mass.
    table = row(1.0, light_kg, 1.0, 100.0, 0.0)
    run(table, dt)
    np.testing.assert_allclose(table.vel_mps[:, 0], 100.0 / (2.0 + light_kg), rtol=1e-9)
    np.testing.assert_allclose(np.diff(table.pos_m[:, 0]), 2 * R, atol=1e-6)  # side by side


def test_the_cluster_impulses_stop_every_approach_and_only_push() -> None:
    # A light puck (0.001 kg) between a 1 kg one coming at 3 m/s and a 2 kg one on a wall, by hand:
    # all three stop (the wall takes it all): impulses 3 N s on each contact, and none pulls.
    # Contacts (a, b) with normals from b to a: (light, cue), (heavy, light), (heavy, the wall on its right).
    n = np.array([1.0 + 0j, 1.0 + 0j, -1.0 + 0j])
    a, b = np.array([1, 2, 2]), np.array([0, 1, -1])
    inv = 1.0 / np.array([1.0, 0.001, 2.0])
    vn = np.array([0.0 - 3.0, 0.0, 0.0])  # the cue (body 0) moves at 3 m/s towards +x, into the light one
    p = collapse.impulses(n, vn, a, b, inv)
    np.testing.assert_allclose(p, [3.0, 3.0, 3.0], rtol=1e-9)
    # Parting contacts get nothing: the cue moving away.
    assert collapse.impulses(n[:1], np.array([2.0]), a[:1], b[:1], inv).tolist() == [0.0]


def touching_cluster(data, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Discs of radius 0.05-0.5 m in the bottom left corner of a box, each touching two placed earlier or
    one and the floor (the first: both walls), none overlapping another: (centres as complex, radii).
    Touching two closes a triangle: a wedged, rigid cluster, with more contacts than ways to move."""
    radii = np.array(data.draw(st.lists(st.floats(0.05, 0.5), min_size=count, max_size=count)))
    centres = [complex(radii[0], radii[0])]
    for r in radii[1:]:
        k = data.draw(st.integers(0, len(centres) - 1))
        c, reach = centres[k], radii[k] + r
        if len(centres) > 1 and data.draw(st.booleans()):  # on two discs: where the circles of reach meet
            other = data.draw(st.integers(0, len(centres) - 2))
            other += other >= k
            d, far = centres[other] - c, radii[other] + r
            along = (abs(d) ** 2 + reach**2 - far**2) / (2 * abs(d))
            if reach**2 - along**2 <= 0.0:
                continue
            at = c + d / abs(d) * complex(along, math.sqrt(reach**2 - along**2) * data.draw(st.sampled_from([1, -1])))
        elif abs(c.imag - r) < reach:  # on one disc and the floor
            at = c + complex(math.sqrt(reach**2 - (c.imag - r) ** 2) * data.draw(st.sampled_from([1, -1])), r - c.imag)
        else:
            continue
        if (
            at.real >= r - 1e-12
            and at.imag >= r - 1e-12
            and all(abs(at - e) >= radii[q] + r - 1e-9 for q, e in enumerate(centres))
        ):
            centres.append(at)
    return np.array(centres), radii[: len(centres)]


@settings(max_examples=300, deadline=None, derandomize=True)
@given(count=st.integers(1, 9), data=st.data())
def test_the_cluster_impulses_meet_the_contact_conditions_in_a_wedged_cluster(count: int, data) -> None:
    # The conditions themselves are the oracle: p >= 0, no contact approaches after, and a contact that
    # pushes is closed (p (vn + A p) = 0). A cluster of touching discs in a corner, masses six decades
    # apart, has dependent contacts (a puck wedged under two more: more contacts than ways to move),
    # where an active set's equations may have no exact answer; a random pile met one (test_piles).
    # vn = J v plus a slack >= 0 (a bound that lets a gap close), so an answer exists.
    centres, radii = touching_cluster(data, count)
    i, j = np.triu_indices(len(centres), 1)
    touch = np.abs(centres[i] - centres[j]) <= radii[i] + radii[j] + 1e-9
    left, floor = np.flatnonzero(centres.real <= radii + 1e-9), np.flatnonzero(centres.imag <= radii + 1e-9)
    a = np.concatenate([i[touch], left, floor])
    b = np.concatenate([j[touch], -np.ones(len(left) + len(floor), dtype=int)])
    d = centres[i[touch]] - centres[j[touch]]
    n = np.concatenate([d / np.abs(d), np.ones(len(left)), 1j * np.ones(len(floor))])
    kg = 10.0 ** np.array(data.draw(st.lists(st.floats(-3.0, 3.0), min_size=len(centres), max_size=len(centres))))
    v = np.array(
        data.draw(st.lists(st.complex_numbers(max_magnitude=10.0), min_size=len(centres), max_size=len(centres)))
    )
    slack = np.array(data.draw(st.lists(st.sampled_from([0.0, 0.0, 0.1, 1.0]), min_size=len(a), max_size=len(a))))
    vn = (n.conjugate() * (v[a] - np.where(b < 0, 0.0, v[np.maximum(b, 0)]))).real + slack
    a_mat = collapse.response(n, a, b, 1.0 / kg)
    # Where it starts (the contacts that pushed in the last step, in the engine) changes nothing.
    pushed = np.array(data.draw(st.lists(st.booleans(), min_size=len(a), max_size=len(a))), dtype=bool)
    with pytest.MonkeyPatch.context() as patch:
        if data.draw(st.booleans()):  # none of plain block pivoting's tries: the safe pivoting (_settle) alone
            patch.setattr(collapse, "TRIES", 0)
        p = collapse.solve(a_mat, vn, pushed if data.draw(st.booleans()) else None)
    assert p is not None
    after = vn + a_mat @ p
    round_off = 1e-9 * (np.abs(vn).max() + np.abs(a_mat) @ p)  # (the sum's terms)
    assert p.min() >= 0.0
    assert (after >= -round_off).all()
    assert (np.abs(after) <= round_off)[p > 0.0].all()


def jacobian_response(n: np.ndarray, a: np.ndarray, b: np.ndarray, inv_mass: np.ndarray) -> np.ndarray:
    """By hand: J W J^T, J's row k holding n_k on body a[k]'s x and y and -n_k on body b[k]'s (none for a wall)."""
    jac = np.zeros((len(n), 2 * len(inv_mass)))
    for k, (nk, ak, bk) in enumerate(zip(n, a, b, strict=True)):
        jac[k, 2 * ak : 2 * ak + 2] += (nk.real, nk.imag)
        if bk >= 0:
            jac[k, 2 * bk : 2 * bk + 2] -= (nk.real, nk.imag)
    return jac @ np.diag(np.repeat(inv_mass, 2)) @ jac.T


@settings(max_examples=100, deadline=None, derandomize=True)
@given(bodies=st.integers(1, 12), contacts=st.integers(1, 40), data=st.data())
def test_the_response_matrix_is_the_jacobian_times_the_inverse_masses_times_its_transpose(bodies, contacts, data):
    # Built from the pairs of contacts that share a body (collapse.response); any contacts, any masses.
    a = np.array(data.draw(st.lists(st.integers(0, bodies - 1), min_size=contacts, max_size=contacts)))
    b = np.array([data.draw(st.integers(-1, bodies - 1).filter(lambda x, ak=ak: x != ak)) for ak in a])
    n = np.exp(1j * np.array(data.draw(st.lists(st.floats(-4.0, 4.0), min_size=contacts, max_size=contacts))))
    inv = 10.0 ** np.array(data.draw(st.lists(st.floats(-3.0, 3.0), min_size=bodies, max_size=bodies)))
    expected = jacobian_response(n, a, b, inv)
    got = collapse.response(n, a, b, inv)
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())
