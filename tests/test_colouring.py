"""Rounds of contacts kept from step to step (colouring.py): valid, kept, ordered by bands, few."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable.physics import colouring
from airtable.physics.table import AirTable

SINK = 20  # bodies 0..19, and the sink (walls, sleepers) that any number of contacts may share


@st.composite
def contact_graphs(draw) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Contacts (a, b) between 20 bodies and the sink, no pair twice, and a band per contact."""
    pairs = draw(
        st.lists(
            st.tuples(st.integers(0, SINK - 1), st.integers(0, SINK)).filter(lambda p: p[0] != p[1]),
            min_size=1,
            max_size=60,
            unique_by=lambda p: (min(p), max(p)) if p[1] != SINK else p,
        )
    )
    a = np.array([p[0] for p in pairs])
    b = np.array([p[1] for p in pairs])
    band = np.array(draw(st.lists(st.integers(0, 3), min_size=len(a), max_size=len(a))), dtype=np.int16)
    return a, b, band


def _assert_valid(rounds: np.ndarray, a: np.ndarray, b: np.ndarray) -> None:
    """Every contact has a round, none empty, and no body but the sink twice in a round."""
    assert rounds.min() == 0 and np.all(np.bincount(rounds) > 0)
    for r in range(rounds.max() + 1):
        bodies = np.concatenate([a[rounds == r], b[rounds == r]])
        bodies = bodies[bodies != SINK]
        assert len(bodies) == len(set(bodies.tolist())), f"round {r} has a body twice"


@settings(max_examples=200, deadline=None)
@given(contact_graphs())
def test_fitted_rounds_never_hold_a_body_twice_and_are_few(graph) -> None:
    a, b, _ = graph
    rounds = colouring.fit(np.full(len(a), -1), a, b, SINK)
    _assert_valid(rounds, a, b)
    # Greedy: a contact meets at most (degree of a - 1) + (degree of b - 1) others, so it never
    # needs a round beyond that; and a body with d contacts needs d rounds.
    degree = np.bincount(np.concatenate([a, b[b != SINK]]), minlength=SINK)
    assert rounds.max() + 1 <= max(1, 2 * int(degree.max()) - 1)
    assert rounds.max() + 1 >= int(degree.max())


@settings(max_examples=200, deadline=None)
@given(contact_graphs())
def test_a_contact_goes_after_its_bodies_contacts_of_lower_bands(graph) -> None:
    # Coloured all at once, each contact's round is after every round holding a contact of a
    # lower band on one of its bodies: one sweep in round order passes support up the bands.
    a, b, band = graph
    rounds = colouring.fit(np.full(len(a), -1), a, b, SINK, band)
    _assert_valid(rounds, a, b)
    for k in range(len(a)):
        share = ((a == a[k]) | (b == a[k]) | ((a == b[k]) | (b == b[k])) & (b[k] != SINK)) & (band < band[k])
        assert np.all(rounds[share] < rounds[k])


@settings(max_examples=200, deadline=None)
@given(contact_graphs(), st.data())
def test_kept_contacts_keep_their_rounds_and_new_ones_fit_in(graph, data) -> None:
    a, b, band = graph
    rounds = colouring.fit(np.full(len(a), -1), a, b, SINK, band)
    new = np.array(data.draw(st.lists(st.booleans(), min_size=len(a), max_size=len(a))))
    again = colouring.fit(np.where(new, -1, rounds), a, b, SINK, band)
    _assert_valid(again, a, b)
    kept = np.flatnonzero(~new)
    # The kept ones stay in their rounds (renumbered only if a round was left empty: order kept).
    for i in kept:
        for j in kept:
            assert (again[i] < again[j]) == (rounds[i] < rounds[j])


@settings(max_examples=200, deadline=None)
@given(contact_graphs(), st.data())
def test_contacts_whose_pucks_changed_band_are_put_back_in_order(graph, data) -> None:
    a, b, band = graph
    rounds = colouring.fit(np.full(len(a), -1), a, b, SINK, band)
    moved = np.array(data.draw(st.lists(st.integers(0, 3), min_size=len(a), max_size=len(a))), dtype=np.int16)
    checked = colouring.keep_order(rounds, a, b, SINK, moved)
    late = np.flatnonzero(checked < 0)
    for k in range(len(a)):  # out of order: some contact of a lower band on one of its bodies is not before it
        share = ((a == a[k]) | (b == a[k]) | ((a == b[k]) | (b == b[k])) & (b[k] != SINK)) & (moved < moved[k])
        assert (k in late) == bool(np.any(rounds[share] >= rounds[k]))
    assert np.all(checked[checked >= 0] == rounds[checked >= 0])
    checked = colouring.fit(checked, a, b, SINK, moved)
    for _ in range(len(a) + 1):  # fitted in again until in order (each pass puts at least one in place)
        again = colouring.keep_order(checked, a, b, SINK, moved)
        if again is checked:
            break
        checked = colouring.fit(again, a, b, SINK, moved)
    _assert_valid(checked, a, b)
    assert colouring.keep_order(checked, a, b, SINK, moved) is checked


@settings(max_examples=200, deadline=None)
@given(contact_graphs(), st.data())
def test_the_order_looked_at_where_it_can_break_is_the_order_looked_at_everywhere(graph, data) -> None:
    # The contact stage looks at the band order only at the bodies of the contacts that are new
    # or changed band since the rounds were last all in order (contacts.py): a body whose
    # contacts all kept their rounds and bands keeps them in order. Both looks must agree.
    a, b, band = graph
    rounds = colouring.fit(np.full(len(a), -1), a, b, SINK, band)
    for _ in range(len(a) + 1):
        again = colouring.keep_order(rounds, a, b, SINK, band)
        if again is rounds:
            break
        rounds = colouring.fit(again, a, b, SINK, band)
    assert colouring.keep_order(rounds, a, b, SINK, band) is rounds  # in order, as the stage needs to look less

    def draw(values) -> np.ndarray:
        return np.array(data.draw(st.lists(values, min_size=len(a), max_size=len(a))))

    few = st.integers(0, 9).map(lambda k: k == 0)  # a tenth of them: most bodies keep their contacts
    moved, new, level = draw(few), draw(few), draw(st.integers(0, 3))
    now_band = np.where(moved, level, band).astype(np.int16)
    now = colouring.fit(np.where(new, -1, rounds), a, b, SINK, now_band)
    changed = np.flatnonzero(moved | new)
    dirty = np.zeros(SINK + 1, dtype=bool)
    dirty[a[changed]] = dirty[b[changed]] = True
    dirty[SINK] = False
    everywhere = colouring.keep_order(now, a, b, SINK, now_band)
    np.testing.assert_array_equal(colouring.keep_order(now, a, b, SINK, now_band, dirty), everywhere)
    if not changed.size:
        assert everywhere is now  # nothing changed: still in order


def _fit_in_passes(rounds: np.ndarray, a: np.ndarray, b: np.ndarray, band: np.ndarray) -> np.ndarray:
    """The colouring as its docstring defines it, in passes, written out plainly: in each pass, every
    new contact whose priority is the lowest among the new contacts left at each of its bodies (the
    sink aside) takes the first round free at both bodies, after their rounds of lower bands."""
    rounds = rounds.copy()
    left = [int(k) for k in np.flatnonzero(rounds < 0)]
    prio = {k: int(colouring.priorities(np.array([k]), band)[0]) for k in left}
    for _ in range(len(left)):  # (each pass takes at least the lowest priority left)
        if not left:
            break

        def bodies(k: int) -> list[int]:
            return [int(x) for x in (a[k], b[k]) if x != SINK]

        first = [k for k in left if all(prio[k] <= min(prio[o] for o in left if x in bodies(o)) for x in bodies(k))]
        for k in first:
            at = [o for o in range(len(a)) if rounds[o] >= 0 and set(bodies(o)) & set(bodies(k))]
            after = max([rounds[o] + 1 for o in at if band[o] < band[k]], default=0)
            busy = {int(rounds[o]) for o in at}
            rounds[k] = next(r for r in range(after, after + len(a) + 1) if r not in busy)
        left = [k for k in left if k not in first]
    used = np.flatnonzero(np.bincount(rounds))
    return np.searchsorted(used, rounds)  # the empty rounds dropped


@settings(max_examples=200, deadline=None)
@given(contact_graphs(), st.data())
def test_contacts_fitted_one_by_one_take_the_rounds_the_passes_give(graph, data) -> None:
    a, b, band = graph
    rounds = colouring.fit(np.full(len(a), -1), a, b, SINK, band)
    new = np.array(data.draw(st.lists(st.booleans(), min_size=len(a), max_size=len(a))))
    for start in (np.full(len(a), -1), np.where(new, -1, rounds)):
        np.testing.assert_array_equal(colouring.fit(start, a, b, SINK, band), _fit_in_passes(start, a, b, band))


def test_a_heap_of_pucks_all_touching_is_coloured_as_few_rounds_as_a_body_needs_and_at_most_twice() -> None:
    # 40 pucks dropped on one spot: each touches the 39 others. A body with 39 contacts needs 39
    # rounds; greedy needs at most 2 * 39 - 1.
    a, b = (x.astype(np.intp) for x in np.triu_indices(40, k=1))
    rounds = colouring.fit(np.full(len(a), -1), a, b, 40)
    for r in range(rounds.max() + 1):
        bodies = np.concatenate([a[rounds == r], b[rounds == r]])
        assert len(bodies) == len(set(bodies.tolist()))
    assert 39 <= rounds.max() + 1 <= 77


def test_a_woken_body_splits_a_round_it_appeared_twice_in() -> None:
    # Contacts 0 and 1 share body 5, which slept (the sink stood for it): in one round then. Awake,
    # it is a body again: keep() sends the later contact back to be fitted in.
    a, b = np.array([1, 2, 3]), np.array([5, 5, 4])
    rounds = np.array([0, 0, 1])
    assert colouring.keep(rounds, a, np.array([SINK, SINK, 4]), SINK) is rounds  # asleep: nothing to do
    kept = colouring.keep(rounds, a, b, SINK)
    assert kept.tolist() == [0, -1, 1]
    _assert_valid(colouring.fit(kept, a, b, SINK), a, b)


def _bodies(keys: np.ndarray, n: int) -> np.ndarray:
    """(K, 2) the pucks of contact keys (contacts.py: a * (n + 4) + b; b >= n: a wall, -1 here)."""
    a, b = np.divmod(keys, n + 4)
    return np.column_stack((a, np.where(b < n, b, -1)))


def test_a_settling_pile_keeps_its_contacts_rounds_from_step_to_step() -> None:
    table = AirTable(width_m=3.0, height_m=3.0)
    table.gravity_on, table.sleeping, table.cr_puck, table.cr_wall = True, False, 0.5, 0.5
    rng = np.random.default_rng(1)
    for k in range(120):
        table.add_puck(pos_m=(0.15 + 0.25 * (k % 11) + rng.uniform(0, 0.02), 0.15 + 0.22 * (k // 11)), radius_m=0.1)
    for _ in range(360):  # 1.5 s: fallen, and settling
        table.step(1 / 240)
    solver = table.contact_solver
    kept_changes = 0
    for _ in range(60):
        keys, rounds, free, bands = solver._keys, solver._band_rounds, solver._free_rounds, solver._layouts.levels
        table.step(1 / 240)
        both, i, j = np.intersect1d(keys, solver._keys, return_indices=True)
        assert len(both) > 150
        # Every contact that lasted kept its round (up to the renumbering of emptied rounds: order kept);
        # in the band rounds, but where a contact moved to another band: those bodies' rounds are fitted again.
        moved = _bodies(both[bands.take(i) != solver._layouts.levels.take(j)], table.n_pucks)
        moved = moved[moved >= 0]
        calm = ~np.isin(_bodies(both, table.n_pucks), moved).any(axis=1)
        for old, now, where in (
            (rounds.take(i), solver._band_rounds.take(j), calm),
            (free.take(i), solver._free_rounds.take(j), np.ones(len(both), dtype=bool)),
        ):
            old, now = old[where], now[where]
            assert np.all(np.diff(now[np.argsort(old, kind="stable")]) >= 0)
            kept_changes += int(np.any(np.diff(old[np.argsort(now, kind="stable")]) < 0))
        assert solver._free_rounds.max() + 1 <= 11  # a pile: at most 6 neighbours and the walls
    assert kept_changes == 0
