"""Fairness on a tight link: 30 students on demo 4 over a loopback held to 10 Mbit/s.

Runs only where Linux network namespaces and tc work (root); skipped with the
reason elsewhere. Takes about four seconds.
"""

from __future__ import annotations

import statistics

import pytest

from tools import fairness

WHY_NOT = fairness.available()


@pytest.mark.skipif(WHY_NOT is not None, reason=f"no network namespace here: {WHY_NOT}")
def test_thirty_students_on_ten_mbit_share_the_link_evenly():
    """Every student gets snapshots, and nobody far fewer than the others. How many a second the
    link carries depends on the machine's speed (25 of 30 on an idle one): `make bench` measures it;
    a test asserts no clock (the table's loop runs slower on a busy machine)."""
    result = fairness.measure_rates(10, clients=30, seconds=2)  # 60 snapshots each at 30 a second
    rates = result.rates
    assert len(rates) == 30, result.line()
    assert min(rates) > 0, result.line()
    assert min(rates) >= 0.5 * statistics.median(rates), result.line()


@pytest.mark.skipif(WHY_NOT is not None, reason=f"no network namespace here: {WHY_NOT}")
def test_the_namespace_is_gone_afterwards():
    with fairness.Namespace(5) as ns:
        shown = ns.run("tc", "qdisc", "show", "dev", "lo").stdout
        assert "tbf" in shown and "5Mbit" in shown
        name = ns.name
    assert name not in fairness._ip("netns", "list").stdout
