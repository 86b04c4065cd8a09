"""A puck's next hits, predicted pair by pair in Python numbers or all at once in numpy: the same bits.

events.py predicts the hits of a puck whose path just changed with each of its partners. Up to
FEW_PARTNERS partners go one by one in Python numbers, more at once in numpy, through the same lines
(either.py); these tests hold the two to the same queue, bit for bit.
"""

from __future__ import annotations

import math
import struct

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable.physics import events
from airtable.physics.rest_speeds import RestSpeeds


def _step(seed: int, n: int, mode: str, dt: float, resting: bool) -> events._Step:
    """n pucks crowded in a 1 m box, some of them on new paths from a time within the step."""
    rng = np.random.default_rng(seed)
    radius = rng.uniform(0.02, 0.12, n)
    mass = rng.uniform(0.1, 3.0, n)
    pos = rng.uniform(0.1, 0.9, (n, 2))
    vel = rng.uniform(-4.0, 4.0, (n, 2)) * rng.choice([0.0, 0.1, 1.0, 10.0], (n, 1))
    press = rng.uniform(0.0, 0.5, n) * np.exp(1j * rng.uniform(0.0, 2 * np.pi, n)) * rng.choice([0.0, 1.0], n)
    rest = RestSpeeds(press, 0.0, 1.0, 1.0) if resting else None
    held_pairs = {(i, j) for i in range(n) for j in range(i + 1, n) if rng.random() < 0.2} if resting else set()

    def held(i: np.ndarray, j: np.ndarray) -> np.ndarray:
        assert (i < j).all()
        return np.array([(a, b) in held_pairs for a, b in zip(i.tolist(), j.tolist(), strict=True)], dtype=bool)

    rules = events.Rules(1.0, 1.0, pairs=mode, walls=True, rest=rest, held=held if resting else None)
    step = events._Step(pos, vel, radius, mass, np.array([1.0, 1.0]), dt, rules)
    step.t_now = float(rng.uniform(0.0, dt))
    for k in rng.choice(n, size=n // 2, replace=False).tolist():  # a hit gave these new paths
        step.set_path(k, step.at(k, step.t_now) + complex(*rng.normal(0.0, 0.01, 2)), complex(*rng.uniform(-5, 5, 2)))
    return step


def _queued(step: events._Step, k: int, one_by_one: bool) -> list[tuple[bytes, int, int]]:
    """The hits of puck k with every other puck that predict_pairs queues: (t's bits, a, b)."""
    queued: list[tuple[bytes, int, int]] = []
    step.push = lambda t, a, b: queued.append((struct.pack("<d", t), a, b))
    others = [o for o in range(len(step.radius)) if o != k]
    if one_by_one:
        for other in others:
            step.predict_pairs(k, other)
    else:
        step.predict_pairs(np.full(len(others), k), np.array(others, dtype=np.intp))
    return queued


@settings(max_examples=150, deadline=None, derandomize=True)
@given(
    st.integers(0, 2**32 - 1),
    st.integers(2, 25),
    st.sampled_from(["perfect-kiss", "two-step", "off"]),
    st.sampled_from([1 / 1000, 1 / 240, 1 / 60, 1 / 30]),
    st.booleans(),
)
def test_one_by_one_and_all_at_once_queue_the_same_hits(seed: int, n: int, mode: str, dt: float, resting: bool):
    step = _step(seed, n, mode, dt, resting)
    for k in range(min(n, 4)):
        one, many = _queued(step, k, True), _queued(step, k, False)
        assert one == many
        for t_bits, _, _ in one:  # within the step, not before now
            t = struct.unpack("<d", t_bits)[0]
            assert step.t_now <= t <= step.dt and not math.isnan(t)


def test_a_crowd_of_pucks_puts_hits_in_the_queue_both_ways() -> None:
    """The test above is not empty: its scenes queue hits, in every mode."""
    for mode in ("perfect-kiss", "two-step", "off"):
        queued = sum(len(_queued(_step(seed, 25, mode, 1 / 30, False), 0, True)) for seed in range(20))
        assert queued >= 10, mode
