"""The Python bindings end to end: a scenario and a .bt file, plan, exact check,
plan files, a short flight, and the typed errors of bad input."""

import inspect
import json
import math
from pathlib import Path

import numpy as np
import pytest

import aerial_chain as ac

REPO = Path(__file__).resolve().parents[2]
GEB079 = REPO / "maps" / "geb079.bt"


@pytest.fixture(scope="module")
def window_plan(window):
    return ac.plan(window, units=5)


def test_scenario_loads_with_its_query(window):
    assert window.resolution > 0
    assert window.unknown_is_occupied
    assert window.default_units >= 2
    lo, hi = window.bounds
    assert lo.shape == (3,) and np.all(lo < hi)
    assert np.all((lo <= window.start) & (window.start <= hi))
    voxels = window.occupied_voxels()
    assert voxels.ndim == 2 and voxels.shape[1] == 3 and len(voxels) > 0
    band = window.occupied_voxels(z_range=(1.0, 1.2))
    assert 0 < len(band) < len(voxels)
    assert np.all((band[:, 2] >= 1.0) & (band[:, 2] <= 1.2))


def test_plan_window_n5_verifies_exactly(window, window_plan):
    plan = window_plan
    assert plan.units == 5 and len(plan) >= 2
    zeta = plan.waypoints
    assert zeta.shape == (len(plan), 2 * 5 + 2)
    np.testing.assert_array_equal(plan.heads, zeta[:, :3])
    np.testing.assert_allclose(plan.heads[0], window.start, atol=1e-9)
    assert np.linalg.norm(plan.heads[-1] - window.goal) <= 0.3
    units = plan.unit_positions()
    assert units.shape == (len(plan), 5, 3)
    np.testing.assert_array_equal(units[:, 0, :], plan.heads)
    # Neighbouring units are one link length apart.
    links = np.linalg.norm(np.diff(units, axis=1), axis=2)
    np.testing.assert_allclose(links, plan.chain["link_length"], rtol=1e-6)
    report = ac.verify(window, plan)
    assert report.ok and report.violation is None
    assert report.samples > len(plan)
    assert report.min_clearance > 0
    assert len(report.edges) == len(plan) - 1
    assert set(report.edges) <= {"translation", "shape_change", "stay"}
    assert plan.map["scenario"] == "window"
    assert plan.stats["quality"]["head_path_m"] > 0


def test_plan_files_round_trip(tmp_path, window, window_plan):
    path = tmp_path / "window.json"
    window_plan.write(path)
    again = ac.Plan.read(path)
    np.testing.assert_array_equal(again.waypoints, window_plan.waypoints)
    assert json.loads(again.to_json()) == json.loads(path.read_text())
    assert ac.verify(window, again).ok
    same = ac.Plan.from_json(path.read_text())
    np.testing.assert_array_equal(same.waypoints, window_plan.waypoints)


def test_a_plan_moved_into_a_wall_is_invalid(window, window_plan):
    doc = json.loads(window_plan.to_json())
    # Every head inside the dividing wall (x from 4.0 to 4.2 m), beside the window.
    for w in doc["waypoints"]:
        w["zeta"][:3] = [4.1, 1.0, 1.5]
    bad = ac.Plan.from_json(json.dumps(doc))
    with pytest.raises(ac.VerifyError, match="INVALID"):
        ac.verify(window, bad)
    report = ac.verify(window, bad, strict=False)
    assert not report.ok and report.violation


def test_a_short_flight_arrives(window):
    # Two waypoints 0.5 m apart: a short flight along the start's heading.
    start = window.start
    yaw = window.start_yaw
    goal = start + 0.5 * np.array([math.cos(yaw), math.sin(yaw), 0.0])
    plan = ac.plan(window, units=4, goal=goal, goal_tol=0.05)
    flight = ac.simulate(window, plan, settle_time=5.0, record_every=25)
    assert flight.success, flight.report
    t = flight.t
    assert t.ndim == 1 and len(t) == len(flight) and np.all(np.diff(t) > 0)
    pos = flight.unit_positions
    assert pos.shape == (len(t), 4, 3)
    states = flight.unit_states
    assert states.shape == (len(t), 4, 13)
    np.testing.assert_array_equal(states[..., :3], pos)
    q = states[..., 3:7]
    np.testing.assert_allclose(np.linalg.norm(q, axis=2), 1.0, atol=1e-4)
    # The head settles at the goal: it hardly moves at the end.
    assert np.linalg.norm(states[-1, 0, 7:10]) < 0.05
    assert flight.head_reference.shape == (len(t), 3)
    assert np.linalg.norm(pos[-1, 0] - plan.heads[-1]) <= 0.1
    assert flight.report["min_clearance"] > 0


def test_a_bt_file_plans_and_verifies():
    geb = ac.Map.from_file(GEB079, unknown_free=True)
    assert not geb.unknown_is_occupied and geb.start is None
    plan = ac.plan(geb, units=5, start=(-3, 0, 1), start_yaw=0.0, goal=(25, 0, 1))
    assert plan.map["sha256"]
    assert ac.verify(geb, plan, start=(-3, 0, 1), goal=(25, 0, 1)).ok
    # The same plan under the stricter assumption (unknown space occupied) is INVALID.
    strict = ac.Map.from_file(GEB079)
    with pytest.raises(ac.VerifyError, match="INVALID"):
        ac.verify(strict, plan)


def test_bad_input_raises_typed_errors(tmp_path, window):
    assert issubclass(ac.MapError, ac.ArcError) and issubclass(ac.ArcError, ValueError)
    with pytest.raises(ac.MapError, match="no_such_map.bt"):
        ac.Map.from_file(tmp_path / "no_such_map.bt")
    junk = tmp_path / "junk.bt"
    junk.write_bytes(b"not an octree")
    with pytest.raises(ac.MapError, match="junk.bt"):
        ac.Map.from_file(junk)
    with pytest.raises(ac.MapError, match="nowhere"):
        ac.Map.scenario("nowhere")
    for n in (1, 17, -3, 300):
        with pytest.raises(ac.PlanError, match=f"units = {n}"):
            ac.plan(window, units=n)
    with pytest.raises(ac.PlanError, match="start_shape"):
        ac.plan(window, units=5, start_shape=[0.0, 0.0])
    with pytest.raises(ac.PlanError, match="time_limit"):
        ac.plan(window, units=5, time_limit=-1.0)
    geb = ac.Map.from_file(GEB079, unknown_free=True)
    with pytest.raises(ac.PlanError, match="start is required"):
        ac.plan(geb, units=5)
    with pytest.raises(ac.PlanError, match="units is required"):
        ac.plan(geb, start=(0, 0, 1), goal=(1, 0, 1))
    with pytest.raises(ac.PlanError, match="missing.json"):
        ac.Plan.read(tmp_path / "missing.json")
    with pytest.raises(ac.PlanError, match="zeta"):
        ac.Plan.from_json(
            json.dumps(
                {
                    "format": "arc-plan/1",
                    "chain": json.loads(ac.plan(window, units=5).to_json())["chain"],
                    "map": {"resolution": 0.1, "unknown_is_occupied": True},
                    "waypoints": [{"zeta": [0.0, 0.0]}],
                }
            )
        )


def test_bad_simulation_settings_raise_sim_error(window, window_plan):
    with pytest.raises(ac.SimError, match="rate"):
        ac.simulate(window, window_plan, rate=10.0)
    with pytest.raises(ac.SimError, match="record_every"):
        ac.simulate(window, window_plan, record_every=0)
    with pytest.raises(ac.SimError, match="angular limits"):
        ac.simulate(window, window_plan, yaw_rate=0.0)


def test_the_head_yaw_rate_is_arc_sims_unless_given():
    # None: `arc sim`'s 45 deg/s; a given rate reaches the limits (yaw_rate=0.0 is
    # refused above).
    assert inspect.signature(ac.simulate).parameters["yaw_rate"].default is None
