"""The online planner one replan at a time (`OnlinePlanner`), as a robot's own loop
drives it: what it commits on a known map, that it commits nothing into space no
cloud has shown, what a cloud changes, and the typed errors of bad input."""

import numpy as np
import pytest

import aerial_chain as ac


def test_on_a_known_map_the_first_replan_commits_a_valid_motion_to_the_goal(window):
    planner = ac.OnlinePlanner(window, units=4, known=window)
    record = planner.replan(0.0, "start")
    assert record["trigger"] == "start"
    assert record["outcome"]["kind"] == "committed", record
    assert planner.reached and planner.pieces >= 1
    assert planner.due(planner.committed_until) is None
    t, zeta = planner.committed(dt=0.05)
    assert t[0] == 0.0 and t[-1] == pytest.approx(planner.committed_until)
    assert np.all(np.diff(t) > 0)
    assert zeta.shape == (len(t), 2 * 4 + 2)
    np.testing.assert_allclose(zeta[0, :3], window.start, atol=1e-6)
    assert np.linalg.norm(zeta[-1, :3] - window.goal) <= 0.3
    # What was committed is one plan, valid by the exact test on the world.
    plan = planner.plan()
    assert plan.units == 4
    assert ac.verify(window, plan).ok
    assert planner.replans == [record]


def test_from_nothing_it_commits_no_motion_until_clouds_show_the_way(window, tmp_path):
    planner = ac.OnlinePlanner(window, units=4)
    before = planner.voxels_seen
    assert before > 0  # the start's own space
    record = planner.replan(0.0, "start")
    assert record["outcome"]["kind"] in {"looked", "no_room"}, record
    # Whatever it committed (a turn to look) moves no body: the head stays put.
    t, zeta = planner.committed()
    np.testing.assert_allclose(zeta[:, :3], np.tile(window.start, (len(t), 1)), atol=1e-9)
    assert planner.route is not None and planner.route.shape[1] == 3
    # A fan of rays without a return clears space ahead of the head.
    head = np.asarray(window.start)
    angles = np.radians(np.arange(-40.0, 41.0, 2.0))
    misses = head + 10.0 * np.stack([np.cos(angles), np.sin(angles), 0 * angles], axis=1)
    changed = planner.observe(head, misses, 5.0)
    assert changed > 0 and planner.voxels_seen > before
    assert planner.observe(head, misses, 5.0) >= 0
    assert planner.observe_flown([head]) == 0  # its own ball was known free
    due = planner.due(planner.committed_until)
    assert due == "commit_short"
    planner.write_seen(tmp_path / "seen.bt")
    seen = ac.Map.from_file(tmp_path / "seen.bt")
    assert seen.resolution == window.resolution
    assert "OnlinePlanner(" in repr(planner)


@pytest.mark.parametrize(
    "call, named",
    [
        (lambda p: p.replan(0.0, "soon"), "trigger"),
        (lambda p: p.replan(-1.0, "start"), "now = -1"),
        (lambda p: p.due(0.0, period=0.0), "period = 0"),
        (lambda p: p.observe([0, 0, 0], [[1.0, 2.0]], 5.0), "points"),
        (lambda p: p.observe([0, 0, 0], [[1.0, np.nan, 2.0]], 5.0), "row 0"),
        (lambda p: p.observe([0, np.inf, 0], [[1.0, 1.0, 1.0]], 5.0), "origin"),
        (lambda p: p.observe([1, 1, 1], [[2.0, 1.0, 1.0]], -5.0), "range"),
        (lambda p: p.committed(dt=0.0), "dt = 0"),
        (lambda p: (p.replan(0.0, "start"), p.committed(dt=1e-9)), "samples"),
        (lambda p: p.follow_at_ticks(-1.0), "period = -1"),
        (lambda p: p.stuck(float("nan")), "now = NaN"),
    ],
)
def test_bad_input_is_refused_naming_it(window, call, named):
    planner = ac.OnlinePlanner(window, units=3)
    with pytest.raises(ac.ExploreError, match=named):
        call(planner)


def test_bad_settings_are_refused_naming_them(window):
    with pytest.raises(ac.ExploreError, match="start_free"):
        ac.OnlinePlanner(window, units=3, start_free="all")
    with pytest.raises(ac.ExploreError, match="deadline = 0"):
        ac.OnlinePlanner(window, units=3, deadline=0.0)
    with pytest.raises(ac.PlanError, match="units"):
        ac.OnlinePlanner(ac.Map.scenario("window"), units=1)


def test_a_loop_of_ones_own_flies_the_window_from_nothing(window):
    """examples/explore_loop.py: a perfect follower, sensors scanned from the truth with
    `Map.scan`, the planner fed clouds only; the chain comes to rest at the goal, and
    what was committed is valid on the world."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).parents[1] / "examples" / "explore_loop.py"
    spec = importlib.util.spec_from_file_location("explore_loop", path)
    loop = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(loop)
    planner, at = loop.fly(window, 4, time_limit=120.0)
    assert at is not None, planner
    assert planner.reached and planner.pieces >= 2
    assert ac.verify(window, planner.plan()).ok
    np.testing.assert_allclose(planner.at(at)[:3], planner.plan().heads[-1], atol=1e-5)
    assert np.linalg.norm(planner.at(at)[:3] - window.goal) <= 0.3


def test_a_scan_sees_the_wall_ahead_and_misses_beyond_the_range(window):
    head = window.start
    origin, points, max_range = window.scan(head, yaw=0.0)
    np.testing.assert_allclose(origin, head)
    assert max_range == 5.0 and points.shape == (59 * 39, 3)
    reach = np.linalg.norm(points - origin, axis=1)
    hits = reach < max_range
    # Looking along +x from x = 2 the dividing wall stands at x = 4, 2 m ahead.
    assert hits.any() and (reach[~hits] == pytest.approx(2 * max_range, rel=1e-6))
    ahead = points[hits & (np.abs(points[:, 1] - head[1]) < 0.05) & (np.abs(points[:, 2] - head[2]) < 0.05)]
    assert len(ahead) and np.all(np.abs(ahead[:, 0] - 4.0) < 0.01)
    with pytest.raises(ac.ExploreError, match="fov_h_deg"):
        window.scan(head, sensor={"fov_h_deg": 500})
    with pytest.raises(ac.ExploreError, match="attitude"):
        window.scan(head, attitude=[2.0, 0.0, 0.0, 0.0])
