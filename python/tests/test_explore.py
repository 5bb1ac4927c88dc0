"""Flying into the unknown from Python: `explore` as `arc explore` flies it, its
flight, plan, replans and seen map, and the typed errors of bad input."""

import json

import numpy as np
import pytest

import aerial_chain as ac


@pytest.fixture(scope="module")
def run(window):
    return ac.explore(window, units=4)


def test_the_chain_reaches_the_goal_from_an_empty_map(window, run):
    assert run.reached, run.end
    assert run.end["kind"] == "reached" and run.end["t"] > 0
    flight = run.flight
    assert flight.report["contact"] is False
    assert flight.unit_positions.shape[1:] == (4, 3)
    np.testing.assert_allclose(flight.unit_positions[0, 0], window.start, atol=1e-6)
    assert np.linalg.norm(flight.unit_positions[-1, 0] - window.goal) <= 0.3
    # What was flown is one plan, valid by the exact test on the world.
    plan = run.plan
    assert plan.units == 4
    np.testing.assert_allclose(plan.heads[0], window.start, atol=1e-6)
    assert np.linalg.norm(plan.heads[-1] - window.goal) <= 0.3
    assert ac.verify(window, plan).ok


def test_the_record_lists_every_replan(run):
    replans = run.replans
    assert len(replans) == run.summary["replans"] > 0
    assert replans[0]["trigger"] == "start"
    kinds = {r["outcome"]["kind"] for r in replans}
    assert "committed" in kinds and kinds <= {
        "committed",
        "looked",
        "rerouted",
        "nothing_new",
        "no_room",
        "reached",
    }, kinds
    times = [r["t"] for r in replans]
    assert times == sorted(times)
    assert all(r["wall_s"] >= 0 for r in replans)
    assert run.voxels_seen > 1000
    assert "reached the goal" in repr(run)


def test_the_flight_and_the_seen_map_are_written_as_arc_writes_them(window, run, tmp_path):
    run.write(tmp_path / "f.json")
    flight = json.loads((tmp_path / "f.json").read_text())
    assert flight["format"] == "arc-sim/1"
    assert flight["explore"]["end"]["kind"] == "reached"
    assert len(flight["explore"]["replans"]) == len(run.replans)
    run.write_seen(tmp_path / "seen.bt")
    seen = ac.Map.from_file(tmp_path / "seen.bt")
    assert seen.resolution == window.resolution
    # Every piece was committed in space seen free, so the plan holds on the seen map
    # with unknown space occupied.
    assert ac.verify(seen, run.plan).ok
    # The map as it grew holds the seen map's occupied voxels, in the order seen, and
    # the flight file carries it (`arc view` draws it).
    centres, t = run.seen_growth
    occupied = seen.occupied_voxels()
    assert centres.shape == occupied.shape and t.shape == (len(centres),)
    key = lambda a: {tuple(np.round(p / seen.resolution - 0.5).astype(int)) for p in a}
    assert key(centres) == key(occupied)
    assert np.all(np.diff(t) >= 0) and 0 <= t[0] and t[-1] <= run.end["t"]
    grew = flight["explore"]["seen_occupied"]
    assert len(grew["voxels"]) == len(grew["t"]) == len(t)


def test_a_sensor_that_sees_almost_nothing_gets_the_chain_stuck_near_its_start(window):
    short = ac.explore(
        window, units=4, sensor={"max_range": 0.25}, time_limit=15.0, record_every=50
    )
    assert not short.reached
    assert short.end["kind"] == "stuck" and short.end["t"] < 15.0
    assert "nothing new" in short.end["why"]
    heads = short.flight.unit_positions[:, 0]
    assert np.max(np.linalg.norm(heads - heads[0], axis=1)) < 1.0
    assert short.flight.report["contact"] is False


def test_a_run_out_of_time_says_what_it_tried(window):
    hasty = ac.explore(window, units=4, time_limit=3.0, record_every=50)
    assert not hasty.reached
    assert hasty.end["kind"] == "time_limit" and hasty.end["t"] == 3.0
    assert "replans" in hasty.end["tried"]


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"sensor": {"fov_h_deg": 400.0}}, "fov_h_deg"),
        ({"sensor": {"range": 3.0}}, "range"),
        ({"start_free": "nope"}, "start_free"),
        ({"deadline": 0.0}, "deadline = 0"),
        ({"clearance": -0.1}, "clearance = -0.1"),
        ({"sensor_rate": 0.0}, "rate"),
        ({"time_limit": -1.0}, "time"),
        ({"record_every": 0}, "record_every = 0"),
    ],
)
def test_bad_settings_raise_explore_error_naming_them(window, kwargs, words):
    with pytest.raises(ac.ExploreError, match=words):
        ac.explore(window, units=4, **kwargs)


def test_a_bad_query_raises_plan_error(window):
    with pytest.raises(ac.PlanError, match="units = 1"):
        ac.explore(window, units=1)
    with pytest.raises(ac.ArcError):
        ac.explore(window, units=4, start=[-50.0, 0.0, 0.0])
