"""proportioning.solve finds the contact impulses: the conditions that define them, checked one by one.

By hand, the impulses p of contacts whose relative normal velocities are w = A p + q are the answer
when no impulse pulls (p >= 0), no contact approaches past its bound (w >= 0), and a contact that pushes
stops exactly at its bound (w = 0 where p > 0). Those three are checked on scenes hypothesis draws:
bodies of masses six decades apart, contacts between random pairs of them and walls along random
normals, and q from real body velocities and gaps (so an answer exists: standing still is one that
closes no gap). Where the exact solve (collapse.solve, block pivoting) settles, both give the same
least value of p.A p / 2 + q.p, the quantity the answer makes least.
"""

from __future__ import annotations

import warnings

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

from airtable.physics import collapse, proportioning
from airtable.physics import contacts as contacts_stage

TOL_MPS = 1e-9


def scene(seed: int, bodies: int, contacts: int, wall_share: float):
    """(n, a, b, inv, q): contacts k between body a[k] and b[k] (== bodies: a wall), unit normals n[k],
    1/mass inv (the wall's 0 last), q[k] the relative normal velocity less the bound -gap / dt."""
    rng = np.random.default_rng(seed)
    a = rng.integers(0, bodies, contacts)
    b = rng.integers(0, bodies, contacts)
    b = np.where((b == a) | (rng.random(contacts) < wall_share), bodies, b)
    n = np.exp(2j * np.pi * rng.random(contacts))
    inv = np.append(10.0 ** rng.uniform(-3.0, 3.0, bodies), 0.0)
    vel = np.append(rng.normal(size=bodies) + 1j * rng.normal(size=bodies), 0.0)
    gap_per_dt = np.maximum(rng.normal(size=contacts), 0.0)
    q = (n.conjugate() * (vel.take(a) - vel.take(b))).real + gap_per_dt
    return n, a, b, inv, q


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    seed=st.integers(0, 2**32 - 1),
    bodies=st.integers(2, 40),
    per_body=st.floats(0.5, 2.0),
    wall_share=st.floats(0.0, 0.5),
)
@example(seed=2547168, bodies=29, per_body=2.0, wall_share=0.375)
@example(seed=1562, bodies=30, per_body=1.59375, wall_share=0.375)
def test_the_impulses_push_never_pull_and_stop_each_pushing_contact_at_its_bound(seed, bodies, per_body, wall_share):
    contacts = max(1, round(per_body * bodies))
    n, a, b, inv, q = scene(seed, bodies, contacts, wall_share)
    response = proportioning.Response(n, a, b, inv)
    scale = float(np.abs(q).max()) + 1.0
    # It may stop where it comes no nearer only where the masses are alike, as the contact stage asks: where they
    # differ it comes nearer as unsteadily and as slowly as they differ (two scenes of masses six decades apart,
    # one stopped so at 500 steps, settled at 3000; the other at 20000 to 40000).
    alike = inv[:-1].max() <= contacts_stage.SAFE_MASS_RATIO * inv[:-1].min()
    p, settled = proportioning.solve(response, q, np.zeros(contacts), TOL_MPS * scale, 50_000, stall=alike)
    dense = collapse.response(n, a, np.where(b == bodies, -1, b), inv[:-1])
    w = dense @ p + q
    assert np.allclose(response(p), dense @ p, rtol=1e-12, atol=1e-12 * float(np.abs(dense).max() * p.max() + 1))
    exact = collapse.solve(dense, q.copy())
    if exact is None:  # (dependent contacts the exact solve does not settle: nor need this one)
        return
    assert settled
    assert p.min() >= 0.0
    assert w.min() >= -2 * TOL_MPS * scale
    assert np.abs(w[p > 0.0]).max(initial=0.0) <= 2 * TOL_MPS * scale
    least = exact @ (dense @ exact) / 2 + q @ exact
    found = p @ (dense @ p) / 2 + q @ p
    assert abs(found - least) <= 1e-9 * (abs(least) + float(q @ q) / float(np.diag(dense).max()))


def test_a_column_of_pucks_landing_on_the_floor_stops_dead():
    """By hand: 30 pucks of 1 kg one on another, all falling at 3 m/s onto the floor, restitution 0: each
    contact's bound is 0, and the answer stops every puck. The floor's impulse is the column's momentum,
    90 N s, and the k-th contact from the floor carries the 30 - k pucks above it: 3 (30 - k) N s."""
    pucks = 30
    a = np.arange(pucks)  # contact k: puck k above, the puck below (k - 1) or the floor
    b = np.append(pucks, np.arange(pucks - 1))
    n = np.full(pucks, 1j)  # up, from the lower body to the upper
    inv = np.append(np.ones(pucks), 0.0)
    q = np.append(-3.0, np.zeros(pucks - 1))  # only the floor's contact approaches: the pucks fall together
    response = proportioning.Response(n, a, b, inv)
    p, settled = proportioning.solve(response, q, np.zeros(pucks), 1e-12, 1000)
    assert settled
    np.testing.assert_allclose(p, 3.0 * (pucks - np.arange(pucks)), rtol=1e-10)


def test_a_puck_squeezed_between_two_walls_that_both_push_it_out_has_no_answer_and_says_so():
    """By hand: a puck overlapping both walls of a channel, each contact asking it to move away from its wall
    at 0.5 m/s, cannot do both: the impulses grow without bound along (1, 1), which changes nothing. The
    solve must say it did not settle, quietly (no numpy warnings reach the user's console)."""
    n = np.array([1.0 + 0j, -1.0 + 0j])  # from each wall (body 1) to the puck (body 0)
    response = proportioning.Response(n, np.array([0, 0]), np.array([1, 1]), np.array([1.0, 0.0]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _, settled = proportioning.solve(response, np.array([-0.5, -0.5]), np.zeros(2), 1e-9, 10_000)
    assert not settled


class _Counted(proportioning.Response):
    """A Response that counts how often A p is asked for (each step asks once or twice)."""

    calls = 0

    def __call__(self, p: np.ndarray) -> np.ndarray:
        self.calls += 1
        return super().__call__(p)


def _stacked_grid(across: int, rows: int, seed: int) -> tuple[_Counted, np.ndarray]:
    """A grid of pucks, each touching its neighbours, on the floor and between the side walls (body across * rows: the
    walls), masses 0.5 to 2 kg: more contacts than the pucks have ways to move. q: each contact's normal speed less
    its bound, at random from -1 to 0.2 m/s."""
    rng = np.random.default_rng(seed)
    wall = across * rows
    contacts = []  # (a, b, normal from b to a)
    for i in range(across):
        for j in range(rows):
            k = i * rows + j
            touching = ((k + rows, k, 1.0, i + 1 < across), (k + 1, k, 1j, j + 1 < rows))
            walls = ((k, wall, 1.0, i == 0), (k, wall, -1.0, i == across - 1), (k, wall, 1j, j == 0))
            contacts += [(p, q, normal) for p, q, normal, here in touching + walls if here]
    a, b, n = (np.array(column) for column in zip(*contacts, strict=True))
    inv = np.append(1.0 / rng.uniform(0.5, 2.0, wall), 0.0)
    return _Counted(n.astype(complex), a, b, inv), rng.uniform(-1.0, 0.2, len(a))


def test_a_solve_that_comes_no_nearer_its_answer_stops_without_using_up_its_steps():
    """Demo 4's grid of 9 x 6 pucks on the floor between the walls, its contacts asking at random: the impulses
    wander, never within the tolerance, and the solve gives up after STALL_STEPS steps and a look (struck, the
    demo's stacks so wandered for all of their 2000 steps, 120 ms a step), not after the 2000 it was allowed."""
    response, q = _stacked_grid(9, 6, seed=0)
    _, settled = proportioning.solve(response, q, np.zeros(len(q)), 1e-6, 2000)
    assert not settled
    assert response.calls <= 2 * (proportioning.STALL_STEPS + 1) + 1
