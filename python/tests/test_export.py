"""Exports checked by independent readers: ROS 2 bags decoded by mcap-ros2-support,
MAVLink logs by pymavlink, every message field by field against the trajectory and the
flight that `arc trajectory` and `arc sim` write for the same plan (docs/model.md,
"Exports"). The `arc` binary is the one `cargo test` built; `./test` names it in
ARC_BIN."""

import json
import math
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest
from mcap_ros2.reader import read_ros2_messages
from pymavlink import mavutil

import aerial_chain as ac

N = 4
RATE = 50.0  # the default: one tick per trajectory sample (dt = 0.02 s)
MM = 1e-3
DEG = math.radians(0.1)


def arc(*args):
    binary = os.environ.get("ARC_BIN")
    assert binary and Path(binary).is_file(), "ARC_BIN must name the arc binary (./test sets it)"
    done = subprocess.run([binary, *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


def wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def yaw_of(x, y, z, w):
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def second_differences(p, t):
    """docs/model.md's acceleration of a trajectory: the second divided difference at
    every inner sample, zero at the ends; `p` is (T, N, 3)."""
    h = np.diff(t)
    a = np.zeros_like(p)
    inner = (p[2:] - p[1:-1]) / h[1:, None, None] - (p[1:-1] - p[:-2]) / h[:-1, None, None]
    a[1:-1] = 2 * inner / (t[2:] - t[:-2])[:, None, None]
    return a


def stamp(t):
    return t.sec + t.nanosec * 1e-9


def load(d, name, world, plan_file):
    arc("trajectory", "--scenario", name, "--plan", plan_file, "--out", d / "traj.json")
    traj = json.loads((d / "traj.json").read_text())
    t = np.array([s["t"] for s in traj["samples"]])
    p = np.array([s["p"] for s in traj["samples"]])  # (T, N, 3)
    zeta = np.array([s["zeta"] for s in traj["samples"]])
    plan = ac.Plan.read(plan_file)
    return {"dir": d, "name": name, "world": world, "plan": plan, "n": plan.units,
            "t": t, "p": p, "zeta": zeta}


@pytest.fixture(scope="module", params=["window", "maze", "silos", "corridor"])
def case(request, tmp_path_factory):
    """A built-in scenario planned by `arc plan` with its defaults, and its trajectory."""
    name = request.param
    d = tmp_path_factory.mktemp(name)
    arc("plan", "--scenario", name, "--out", d / "plan.json")
    arc("export", "--scenario", name, "--plan", d / "plan.json", "--to", d / "plan.mcap")
    arc("export", "--scenario", name, "--plan", d / "plan.json", "--to", d / "plan.tlog",
        "--sysid-base", 7)
    return load(d, name, ac.Map.scenario(name), d / "plan.json")


@pytest.fixture(scope="module")
def window(tmp_path_factory):
    """Scenario window planned from Python with N = 4, and its trajectory."""
    d = tmp_path_factory.mktemp("python-window")
    world = ac.Map.scenario("window")
    ac.plan(world, units=N).write(d / "plan.json")
    return load(d, "window", world, d / "plan.json")


def bag(path):
    by_topic = {}
    for m in read_ros2_messages(str(path)):
        by_topic.setdefault(m.channel.topic, []).append(m)
    return by_topic


def test_bag_decodes_field_by_field(case):
    d, t, p, zeta, n = case["dir"], case["t"], case["p"], case["zeta"], case["n"]
    topics = bag(d / "plan.mcap")
    paths = {f"/arc/unit_{i + 1}/path" for i in range(n)}
    assert set(topics) == {"/arc/map", "/arc/trajectory", "/tf", "/arc/chain"} | paths
    assert len(topics["/tf"]) == len(topics["/arc/chain"]) == len(t)
    for k, m in enumerate(topics["/tf"]):
        assert m.log_time_ns == round(t[k] * 1e9)
        assert [x.child_frame_id for x in m.ros_msg.transforms] == [f"unit_{i + 1}" for i in range(n)]
        for u, x in enumerate(m.ros_msg.transforms):
            assert x.header.frame_id == "map"
            assert abs(stamp(x.header.stamp) - t[k]) < 1e-9
            tr, q = x.transform.translation, x.transform.rotation
            assert np.allclose([tr.x, tr.y, tr.z], p[k, u], atol=MM, rtol=0)
            assert abs(wrap(yaw_of(q.x, q.y, q.z, q.w) - zeta[k, 3])) < DEG
            assert abs(q.x) < 1e-9 and abs(q.y) < 1e-9  # every unit holds the head's yaw only


def test_bag_trajectory_velocities_paths_markers(case):
    d, t, p, zeta, n = case["dir"], case["t"], case["p"], case["zeta"], case["n"]
    topics = bag(d / "plan.mcap")
    (traj,) = topics["/arc/trajectory"]
    msg = traj.ros_msg
    assert msg.joint_names == [f"unit_{i + 1}" for i in range(n)]
    assert len(msg.points) == len(t)
    v = np.gradient(p, t, axis=0)  # central differences, one-sided at the ends
    a = second_differences(p, t)
    yaw_rate = np.gradient(zeta[:, 3], t)
    for k, point in enumerate(msg.points):
        assert abs(stamp(point.time_from_start) - (t[k] - t[0])) < 1e-9
        for u in range(n):
            tr = point.transforms[u].translation
            assert np.allclose([tr.x, tr.y, tr.z], p[k, u], atol=MM, rtol=0)
            lin = point.velocities[u].linear
            assert np.allclose([lin.x, lin.y, lin.z], v[k, u], atol=1e-6, rtol=0)
            acc = point.accelerations[u].linear
            assert np.allclose([acc.x, acc.y, acc.z], a[k, u], atol=1e-6, rtol=0)
            assert abs(point.velocities[u].angular.z - yaw_rate[k]) < 1e-6
    for u in range(n):
        (path,) = topics[f"/arc/unit_{u + 1}/path"]
        poses = path.ros_msg.poses
        assert len(poses) == len(t)
        got = np.array([[s.pose.position.x, s.pose.position.y, s.pose.position.z] for s in poses])
        assert np.allclose(got, p[:, u], atol=MM, rtol=0)
    chain = case["plan"].chain
    for k, m in enumerate(topics["/arc/chain"]):
        spheres, links = m.ros_msg.markers
        assert spheres.type == 7 and links.type == 5
        assert spheres.scale.x == pytest.approx(2 * chain["unit_radius"])
        assert links.scale.x == pytest.approx(2 * chain["link_radius"])
        got = np.array([[q.x, q.y, q.z] for q in spheres.points])
        assert np.allclose(got, p[k], atol=MM, rtol=0)
        assert len(links.points) == 2 * (n - 1)


def test_bag_map_is_the_octomap_stream(case):
    d, name = case["dir"], case["name"]
    topics = bag(d / "plan.mcap")
    (m,) = topics["/arc/map"]
    msg = m.ros_msg
    assert msg.binary and msg.id == "OcTree"
    assert msg.resolution == pytest.approx(case["world"].resolution)
    arc("map", "export", "--scenario", name, "--out", d / "map.bt")
    bt = (d / "map.bt").read_bytes()
    stream = bt[bt.index(b"\ndata\n") + len(b"\ndata\n") :]
    assert bytes(b & 0xFF for b in msg.data) == stream


def messages(path):
    log = mavutil.mavlink_connection(str(path), dialect="common")
    out = []
    while True:
        m = log.recv_match()
        if m is None:
            return out
        out.append(m)


def test_tlog_setpoints_per_unit_in_ned(case):
    d, t, p, zeta, n = case["dir"], case["t"], case["p"], case["zeta"], case["n"]
    ms = messages(d / "plan.tlog")
    assert all(m.get_srcSystem() == 255 and m.get_srcComponent() == 191 for m in ms)
    assert not [m for m in ms if m.get_type() == "COMMAND_LONG"]  # only with --arm
    beats = [m._timestamp for m in ms if m.get_type() == "HEARTBEAT"]
    assert np.allclose(np.diff(beats), 1.0) and beats[0] == 0.0
    hold = 1.0
    v = np.gradient(p, t, axis=0)
    a = second_differences(p, t)
    yaw_rate = np.gradient(zeta[:, 3], t)
    for u in range(n):
        sp = [m for m in ms if m.get_type() == "SET_POSITION_TARGET_LOCAL_NED" and m.target_system == 7 + u]
        times = np.array([m._timestamp for m in sp])
        assert np.all(np.abs(np.diff(times) - 1 / RATE) < 2e-6)  # 50 Hz, well above 2 Hz
        held = [m for m in sp if m._timestamp < hold - 1e-9]
        assert len(held) == hold * RATE
        assert beats[-1] <= times[-1] < beats[-1] + 1.0
        moving = sp[len(held):]
        assert len(moving) == len(t)
        for m in held:
            assert np.allclose([m.x, m.y, m.z], [p[0, u, 1], p[0, u, 0], -p[0, u, 2]], atol=MM)
        for k, m in enumerate(moving):
            assert m.target_component == 1 and m.coordinate_frame == 1  # MAV_FRAME_LOCAL_NED
            assert abs(m._timestamp - (hold + t[k])) < 2e-6
            assert m.time_boot_ms == round((hold + t[k]) * 1e3)
            assert np.allclose([m.x, m.y, m.z], [p[k, u, 1], p[k, u, 0], -p[k, u, 2]], atol=MM, rtol=0)
            assert np.allclose([m.vx, m.vy, m.vz], [v[k, u, 1], v[k, u, 0], -v[k, u, 2]], atol=1e-4)
            assert np.allclose([m.afx, m.afy, m.afz], [a[k, u, 1], a[k, u, 0], -a[k, u, 2]], atol=1e-3)
            assert abs(wrap(m.yaw - (math.pi / 2 - zeta[k, 3]))) < DEG
            assert abs(m.yaw_rate + yaw_rate[k]) < 1e-4
            assert m.type_mask == 0  # position, velocity, acceleration, yaw, yaw rate


def test_tlog_arms_after_a_second_of_setpoints(window):
    d = window["dir"]
    arc("export", "--scenario", "window", "--plan", d / "plan.json", "--to", d / "arm.tlog", "--arm")
    ms = messages(d / "arm.tlog")
    for u in range(N):
        sys_id = 1 + u
        sp = [m._timestamp for m in ms if m.get_type() == "SET_POSITION_TARGET_LOCAL_NED" and m.target_system == sys_id]
        cmds = [m for m in ms if m.get_type() == "COMMAND_LONG" and m.target_system == sys_id]
        assert [c.command for c in cmds] == [176, 400]  # DO_SET_MODE, then ARM
        assert cmds[0].param1 == 1 and cmds[0].param2 == 6  # custom mode: PX4 OFFBOARD
        assert cmds[1].param1 == 1
        assert min(c._timestamp for c in cmds) - sp[0] >= 1.0 - 1e-6


def test_flight_exports_attitude_targets(window):
    d = window["dir"]
    arc("sim", "--scenario", "window", "--plan", d / "plan.json", "--out", d / "flight.json")
    flight = json.loads((d / "flight.json").read_text())
    arc("export", "--scenario", "window", "--flight", d / "flight.json", "--to", d / "flight.tlog",
        "--hold-s", 0)
    ms = messages(d / "flight.tlog")
    samples = flight["samples"]
    att = [m for m in ms if m.get_type() == "SET_ATTITUDE_TARGET" and m.target_system == 1]
    pos = [m for m in ms if m.get_type() == "SET_POSITION_TARGET_LOCAL_NED" and m.target_system == 1]
    assert len(att) == len(pos) == len(samples)  # records at 50 Hz: one tick each
    enu_to_ned = np.array([[0, 1, 0], [1, 0, 0], [0, 0, -1.0]])
    frd_to_flu = np.diag([1.0, -1, -1])
    for s, a, q in zip(samples, att, pos):
        head = s["units"][0]
        assert np.allclose([q.x, q.y, q.z], [head["p"][1], head["p"][0], -head["p"][2]], atol=MM)
        assert a.thrust == pytest.approx(min(max(s["thrust"][0] / 24.0, 0), 1), abs=1e-6)
        roll, pitch, yaw = s["attitude_cmd"][0]
        cr, sr, cp, sp_, cy, sy = map(float, (np.cos(roll), np.sin(roll), np.cos(pitch),
                                              np.sin(pitch), np.cos(yaw), np.sin(yaw)))
        r_enu = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]]) @ np.array(
            [[cp, 0, sp_], [0, 1, 0], [-sp_, 0, cp]]) @ np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
        want = enu_to_ned @ r_enu @ frd_to_flu
        w, x, y, z = a.q
        got = np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ])
        assert np.allclose(got, want, atol=2e-3)  # 0.1 degree


def test_python_export_matches_the_command_line(window):
    d, world, plan = window["dir"], window["world"], window["plan"]
    arc("export", "--scenario", "window", "--plan", d / "plan.json", "--to", d / "cli.mcap")
    arc("export", "--scenario", "window", "--plan", d / "plan.json", "--to", d / "cli.tlog",
        "--sysid-base", 7)
    written = ac.export(world, plan, d / "py.mcap")
    assert written == (d / "py.mcap").stat().st_size
    assert (d / "py.mcap").read_bytes() == (d / "cli.mcap").read_bytes()
    ac.export(world, plan, d / "py.tlog", sysid_base=7)
    assert (d / "py.tlog").read_bytes() == (d / "cli.tlog").read_bytes()


def test_python_export_of_a_flight(window):
    world, plan, d = window["world"], window["plan"], window["dir"]
    flight = ac.simulate(world, plan)
    ac.export(world, flight, d / "sim.tlog", hold_s=0.0)
    ms = messages(d / "sim.tlog")
    att = [m for m in ms if m.get_type() == "SET_ATTITUDE_TARGET"]
    assert len(att) == N * len(flight)
    assert all(0 <= m.thrust <= 1 for m in att)


@pytest.mark.parametrize(
    "path, kwargs, words",
    [
        ("out.txt", {}, ".mcap"),
        ("out.tlog", {"rate": 2.0}, "rate 2"),
        ("out.tlog", {"sysid_base": 253}, "sysid_base = 253"),
        ("out.tlog", {"arm": True, "hold_s": 0.5}, "hold = 0.5"),
        ("out.tlog", {"autopilot": "apm"}, "autopilot"),
    ],
)
def test_python_export_refuses_bad_input(window, path, kwargs, words):
    d = window["dir"]
    with pytest.raises(ac.ExportError, match=words.replace(".", r"\.")):
        ac.export(window["world"], window["plan"], d / path, **kwargs)
    assert not (d / path).exists()
