"""A contact needs a puck the forces press: of two pucks nothing presses, a touch is a collision.

A user test: dragging one puck through the gas of 10000 made the contact stage take every near pair of
the whole gas as a contact (its margin follows the fastest puck, the dragged one), 40-130 ms a step
where a step takes 3 ms: the table nearly froze (4 fps). Only the dragged puck's pairs can rest.
"""

from __future__ import annotations

import numpy as np
from airtable.demos.demo_0p_gas import gas_scene
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable.model.client import CURSOR_STRINGS
from airtable.physics.forces import Pull


@settings(max_examples=25, deadline=None)
@given(
    n=st.integers(60, 400),
    seed=st.integers(0, 10_000),
    pick=st.floats(0.0, 1.0, exclude_max=True),
    throw=st.tuples(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0)),
    button=st.sampled_from(sorted(CURSOR_STRINGS)),
    dt_s=st.sampled_from([1 / 240, 1 / 60]),
)
def test_only_the_dragged_pucks_pairs_are_contacts_in_a_gas(n, seed, pick, throw, button, dt_s):
    table = gas_scene(n, seed=seed)
    row = int(pick * n)
    k, c = CURSOR_STRINGS[button]
    i, j = np.triu_indices(n, k=1)
    others = (i != row) & (j != row)
    i, j = i[others], j[others]
    for _ in range(20):
        x, y = table.pos_m[row]
        anchor = (float(x + throw[0]), float(y + throw[1]))  # dragged hard, as a mouse swung across the table
        table.step(dt_s, [Pull(row=row, anchor_m=anchor, k_Npm=k, drag_Nspm=c)])
        assert not table.contact_solver.kept(i, j).any()  # no pair without the dragged puck is a contact
    assert np.isfinite(table.pos_m).all()
