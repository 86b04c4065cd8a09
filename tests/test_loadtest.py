"""The load tool: players in worker processes, bytes and Mbit/s, and its own bottleneck."""

from __future__ import annotations

import pytest
from conftest import WAIT_S, wait_until

from airtable.net.server import GameServer
from tools.loadtest import LoadResult, TableLoop, default_processes, grid_table, run_load


@pytest.fixture
def table_server():
    server = GameServer(host="127.0.0.1", port=0)
    server.start()
    loop = TableLoop(server, grid_table(), fps=60).start()
    yield server
    loop.stop()
    server.stop()


def test_players_spread_over_two_processes_are_all_measured(table_server):
    result = run_load("127.0.0.1", table_server.port, clients=4, seconds=0.5, processes=2, baseline_s=0.2)
    assert result.connected == 4 and result.processes == 2
    # Every player has its rate; on a starved machine one may see nothing in half a second.
    assert len(result.snapshot_rates) == 4 and min(result.snapshot_rates) >= 0 and sum(result.snapshot_rates) > 0
    assert result.snapshots == pytest.approx(sum(result.snapshot_rates) * 0.5)
    assert result.mean_snapshot_bytes > 50 and result.mbit_per_s > 0
    assert len(result.tool_cpu) == 2 and all(0 <= c < 2 for c in result.tool_cpu)
    assert result.latencies_s and all(0 <= t < WAIT_S for t in result.latencies_s)
    assert result.baseline_fps > 0 and result.loaded_fps
    report = result.report()
    for part in ("snapshots/s", "B per snapshot", "Mbit/s", "p50", "p99", "the tool:", "verdict"):
        assert part in report, part
    wait_until(lambda: table_server.connection_count == 0, what="the load players to leave")


def _result(**changes) -> LoadResult:
    values = dict(
        address="127.0.0.1:8888",
        clients=30,
        connected=30,
        seconds=10.0,
        snapshot_rates=[30.0] * 30,
        baseline_fps=60.0,
        loaded_fps=[60.0],
        latencies_s=[0.01] * 100,
        errors=[],
        processes=1,
        snapshot_bytes=30 * 300 * 600,
        snapshots=30 * 300,
        tool_cpu=[0.3],
        tool_lag_s=[0.002],
    )
    values.update(changes)
    return LoadResult(**values)


def test_a_calm_run_holds_the_class_and_counts_the_bandwidth():
    result = _result()
    assert result.verdict() == "OK, this server holds 30 players"
    assert result.mean_snapshot_bytes == 600
    assert result.mbit_per_s == pytest.approx(30 * 30 * 600 * 8 / 1e6)  # 4.32


def test_a_busy_tool_says_it_was_the_bottleneck():
    busy = _result(tool_cpu=[0.95, 0.4], snapshot_rates=[10.0] + [30.0] * 29)
    assert "the load tool itself was the bottleneck (a worker used 95 % of a core)" in busy.verdict()
    assert "bottleneck" not in _result(tool_lag_s=[0.03]).verdict()  # a frame or two late is normal
    late = _result(tool_lag_s=[0.2])
    assert "loop ran 200 ms late" in late.verdict()


def test_about_fifty_players_per_process():
    assert default_processes(1) == 1
    assert default_processes(100) >= 1
    with pytest.raises(ValueError, match="--processes"):
        run_load("127.0.0.1", 1, clients=2, seconds=1.0, processes=3)


def test_an_echo_is_timed_from_its_own_send_not_from_an_earlier_lap_of_the_cursor():
    """A user test: every run measured a cursor echo p99 of 6.3 s, the lap of the tool's cursor path: a
    place sent but never shown (the table shows only the newest input) matched its next lap's echo."""
    from airtable.model.scene import CursorView
    from airtable.net import protocol as proto
    from airtable.net.player import empty_scene
    from tools.rawplayer import RawPlayer, _key

    p = RawPlayer("127.0.0.1", 1, "Bo", welcome=proto.Welcome("C1", (255, 255, 255), 10.0, 8.0))
    path = [(1.0, 1.0), (2.0, 1.0), (3.0, 1.0)]
    for lap in range(2):
        for k, place in enumerate(path):
            p.sent.setdefault(_key(place), 10.0 * lap + k)  # as send_input remembers them, at 1 s apart
        for k in ((0, 2), (1, 2))[lap]:  # the first lap's middle place never shown, the next lap's is
            scene = empty_scene(10.0, 8.0)
            scene.cursors = (CursorView(p.welcome.label, (255, 255, 255), path[k]),)
            p._look(scene, 10.0 * lap + k + 0.02)
    assert p.latencies_s == pytest.approx([0.02] * 4)
