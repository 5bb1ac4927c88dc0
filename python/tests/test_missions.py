"""Mission plans from Python: a plan that `arc plan --mission` wrote (its waypoints mark
the goals it reaches and their holds) is read, verified, flown with its holds and
exported like any other plan (docs/model.md, "Missions")."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np

import aerial_chain as ac

REPO = Path(__file__).resolve().parents[2]


def test_a_mission_plan_reads_verifies_flies_and_exports(tmp_path):
    binary = os.environ.get("ARC_BIN")
    assert binary and Path(binary).is_file(), "ARC_BIN must name the arc binary (./test sets it)"
    mission = REPO / "missions" / "silos.json"
    out = tmp_path / "silos-m.json"
    done = subprocess.run(
        [binary, "plan", "--scenario", "silos", "--mission", str(mission), "--out", str(out)],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    world = ac.Map.scenario("silos")
    plan = ac.Plan.read(out)
    raw = json.loads(out.read_text())
    marks = [(i, w["goal"], w.get("hold_s", 0.0)) for i, w in enumerate(raw["waypoints"]) if "goal" in w]
    goals = json.loads(mission.read_text())["goals"]
    assert [g for _, g, _ in marks] == list(range(len(goals)))
    for (i, k, hold), goal in zip(marks, goals):
        assert np.linalg.norm(plan.heads[i] - np.array(goal["position"])) <= goal.get("tolerance", 0.3)
        assert hold == goal.get("hold_s", 0.0)
    assert ac.verify(world, plan).ok
    flight = ac.simulate(world, plan)
    assert flight.success, flight.report
    # The head rests at every inspection goal for its hold.
    heads = flight.unit_positions[:, 0, :]
    for (i, _, hold), goal in zip(marks, goals):
        if hold <= 0:
            continue
        near = np.linalg.norm(heads - plan.heads[i], axis=1) < 0.02
        assert np.count_nonzero(near) * np.median(np.diff(flight.t)) >= hold
    written = ac.export(world, plan, tmp_path / "silos.tlog")
    assert written > 0


def test_python_plans_a_goal_pose_and_a_mission():
    world = ac.Map.scenario("window")
    plan = ac.plan(world, units=5, goal_shape="PN", goal_yaw=0.5)
    assert abs(plan.waypoints[-1, 3] - 0.5) < 1e-6
    assert ac.verify(world, plan).ok
    maze = ac.Map.scenario("maze")
    mission = ac.plan(maze, mission=REPO / "missions" / "maze.json")
    raw = json.loads(mission.to_json())
    assert [w["goal"] for w in raw["waypoints"] if "goal" in w] == list(range(6))
    try:
        ac.plan(world, units=5, goal_shape="XX")
    except ac.PlanError as e:
        assert "goal_shape" in str(e)
    else:
        raise AssertionError("a goal shape that is no shape was taken")
