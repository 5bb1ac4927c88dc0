//! Trajectories: limits and validity checked at every sample by code that knows
//! nothing of the generator, blends refused where they would touch the map, the
//! checker's verdicts, and the file.

use aerial_chain_core::{ChainParams, Shape};

use super::*;
use crate::collision::exact::check_config_exact;
use crate::map::{Cell, Grid};
use crate::plan_file::{Waypoint, FORMAT as PLAN_FORMAT};

pub(super) fn plan(params: &ChainParams, points: &[([f64; 3], Shape)]) -> Plan {
    Plan {
        format: PLAN_FORMAT.into(),
        chain: ChainSection::from_params(params),
        map: MapSection::new(0.1, true),
        waypoints: points.iter().map(|(h, s)| Waypoint::new(*h, s)).collect(),
        stats: Default::default(),
    }
}

/// A free room of 4 x 4 x 2 m.
pub(super) fn room() -> Grid {
    Grid::new(0.1, [0, 0, 0], [40, 40, 20], Cell::Free, true).unwrap()
}

/// Translation, yaw rotation, translation at a right angle, a climb.
fn tour(params: &ChainParams) -> Plan {
    let s = Shape::line(3, 0.0);
    let r = s.rotated(0.6);
    plan(
        params,
        &[
            ([1.5, 1.0, 1.0], s),
            ([2.8, 1.0, 1.0], s),
            ([2.8, 1.0, 1.0], r),
            ([2.8, 2.6, 1.0], r),
            ([2.8, 2.6, 1.5], r),
        ],
    )
}

/// Unit centres by paper Eq. 2, written out here so the test does not lean on the
/// library's kinematics.
fn units(l: f64, z: &[f64]) -> Vec<[f64; 3]> {
    let mut p = vec![[z[0], z[1], z[2]]];
    for k in 0..(z.len() - 4) / 2 {
        let (th, ps) = (z[4 + 2 * k], z[5 + 2 * k]);
        let q = p[k];
        p.push([
            q[0] - l * ps.cos() * th.cos(),
            q[1] - l * ps.sin() * th.cos(),
            q[2] + l * th.sin(),
        ]);
    }
    p
}

/// The trajectory of `plan` on `grid` with the default settings.
pub(super) fn built(plan: &Plan, grid: &Grid) -> Trajectory {
    build(plan, grid, &Settings::default()).unwrap()
}

/// Every limit `tr` was made within at every sample by differences, and every sample
/// valid by the exact test: the test's own reading of docs/model.md, independent of the generator.
pub(super) fn assert_respects_limits(grid: &Grid, tr: &Trajectory) {
    let (t, z) = (tr.times(), tr.zetas());
    assert_samples_respect_limits(grid, tr.params(), &tr.settings().limits, t, z);
}

/// [`assert_respects_limits`] of samples `z` at times `t` of chain `params` within `lim`.
pub(super) fn assert_samples_respect_limits(
    grid: &Grid,
    params: &ChainParams,
    lim: &Limits,
    t: &[f64],
    z: &[Vec<f64>],
) {
    let l = params.link_length as f64;
    let slack = 1.0 + 1e-6;
    let angle = |a: f64| {
        (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
    };
    // The head yaw (angle 3 of zeta) has limits of its own.
    let rate = |i: usize| {
        if i == 3 {
            lim.yaw_rate
        } else {
            lim.angular_rate
        }
    };
    let accel = |i: usize| {
        if i == 3 {
            lim.yaw_accel
        } else {
            lim.angular_accel
        }
    };
    for j in 0..z.len() {
        let head = [z[j][0], z[j][1], z[j][2]];
        check_config_exact(grid, params, head, &z[j][3..], 0.0)
            .unwrap_or_else(|v| panic!("sample {j} at {} s: {v}", t[j]));
        if j + 1 == z.len() {
            continue;
        }
        let h = t[j + 1] - t[j];
        assert!(h > 0.0);
        let (a, b) = (units(l, &z[j]), units(l, &z[j + 1]));
        for (u, (p, q)) in a.iter().zip(&b).enumerate() {
            let v =
                ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt() / h;
            assert!(v <= lim.speed * slack, "unit {u} at {v} m/s, t = {}", t[j]);
        }
        for (i, (x0, x1)) in z[j].iter().zip(&z[j + 1]).enumerate().skip(3) {
            let w = angle(x1 - x0).abs() / h;
            assert!(w <= rate(i) * slack, "angle {i} at {w} rad/s");
        }
        if j > 0 {
            let h0 = t[j] - t[j - 1];
            let acc = |i: usize| {
                2.0 * ((z[j + 1][i] - z[j][i]) / h - (z[j][i] - z[j - 1][i]) / h0) / (h + h0)
            };
            let a = (acc(0).powi(2) + acc(1).powi(2) + acc(2).powi(2)).sqrt();
            assert!(a <= lim.accel * slack, "head at {a} m/s^2, t = {}", t[j]);
            for i in 3..z[j].len() {
                assert!(
                    acc(i).abs() <= accel(i) * slack,
                    "angle {i} accelerates at {}",
                    acc(i)
                );
            }
        }
    }
}

#[test]
fn blended_tour_keeps_every_limit_and_is_faster() {
    let params = ChainParams::new(3);
    let (grid, plan) = (room(), tour(&params));
    let s = Settings::default();
    let tr = built(&plan, &grid);
    assert_eq!(tr.corners(), 3);
    assert_eq!(
        tr.merged(),
        1,
        "the first translation and the rotation fly at once"
    );
    assert_eq!(tr.blended(), 2, "a free room admits every blend");
    assert!(
        tr.duration() < 0.8 * tr.stop_go_duration(),
        "{} vs {}",
        tr.duration(),
        tr.stop_go_duration()
    );
    assert_respects_limits(&grid, &tr);
    let rep = check_samples(&grid, &params, &s.limits, tr.times(), tr.zetas(), 0.5);
    assert!(rep.ok, "{:?}", rep.violation);
    // Starts at the plan's start, ends at rest at its end.
    let (first, last) = (&tr.zetas()[0], tr.zetas().last().unwrap());
    assert_eq!(first, &plan.waypoints[0].zeta);
    let goal = &plan.waypoints[4].zeta;
    for i in 0..goal.len() {
        let d = crate::collision::verify::wrap(last[i] - goal[i]);
        assert!(
            d.abs() < 1e-9,
            "zeta[{i}] ends at {} not {}",
            last[i],
            goal[i]
        );
    }
    let n = tr.zetas().len();
    let moved = (0..3)
        .map(|i| (last[i] - tr.zetas()[n - 2][i]).abs())
        .fold(0.0, f64::max);
    assert!(
        moved / s.dt < 1e-3,
        "at rest at the end: {} m/s",
        moved / s.dt
    );
    // Without blends: the stop-and-go timing, every corner at rest.
    let plain = build(&plan, &grid, &Settings { blend: false, ..s }).unwrap();
    assert_eq!((plain.blended(), plain.merged()), (0, 0));
    assert!((plain.duration() - plain.stop_go_duration()).abs() <= 4.0 * s.dt);
    assert_respects_limits(&grid, &plain);
}

/// Head along +x, then up: the chain's tail rounds the corner below a voxel that the
/// plan's own edges pass at 5 mm.
fn corner(params: &ChainParams) -> Plan {
    corner_below(params, 0.0)
}

/// `corner` flown `drop` (m) lower.
fn corner_below(params: &ChainParams, drop: f64) -> Plan {
    let s = Shape::line(3, 0.0);
    let z = 1.045 - drop;
    plan(
        params,
        &[
            ([1.6, 1.0, z], s),
            ([2.955, 1.0, z], s),
            ([2.955, 1.0, 1.8], s),
        ],
    )
}

#[test]
fn a_blend_that_would_touch_the_map_is_not_flown() {
    let params = ChainParams::new(3);
    let s = Settings::default();
    let free = built(&corner(&params), &room());
    assert_eq!(free.blended(), 1);
    let mut grid = room();
    grid.fill_box([1.71, 0.51, 1.21], [1.79, 1.49, 1.29], Cell::Occupied);
    let blocked = built(&corner(&params), &grid);
    assert_eq!(
        blocked.blended(),
        0,
        "the rounded corner brings the tail onto the voxel"
    );
    assert_respects_limits(&grid, &blocked);
    // The blended one does touch it: the check says where.
    let rep = check_samples(&grid, &params, &s.limits, free.times(), free.zetas(), 0.0);
    let v = rep.violation.expect("the blend touches the voxel");
    assert!(matches!(v.problem, Problem::Invalid(_)), "{v}");
}

#[test]
fn a_deadline_that_has_passed_keeps_the_plan_stop_and_go() {
    let params = ChainParams::new(3);
    let s = Settings::default();
    let mut grid = room();
    grid.fill_box([1.71, 0.51, 1.21], [1.79, 1.49, 1.29], Cell::Occupied);
    for (plan, grid) in [(tour(&params), room()), (corner(&params), grid)] {
        let full = built(&plan, &grid);
        let later = std::time::Instant::now() + std::time::Duration::from_secs(600);
        let within = build_until(&plan, &grid, &s, Some(later)).unwrap();
        assert!(!within.cut_short());
        assert_eq!(
            (within.times(), within.zetas()),
            (full.times(), full.zetas()),
            "below the deadline the trajectory is build's"
        );
        let cut = build_until(&plan, &grid, &s, Some(std::time::Instant::now())).unwrap();
        assert!(cut.cut_short());
        assert_eq!((cut.blended(), cut.merged()), (0, 0));
        assert!((cut.duration() - cut.stop_go_duration()).abs() <= 4.0 * s.dt);
        assert_eq!(cut.stages().reports()[0].rounds, 1, "one round, the last");
        let rep = check_samples(&grid, &params, &s.limits, cut.times(), cut.zetas(), 0.0);
        assert!(rep.ok, "{:?}", rep.violation);
        assert_respects_limits(&grid, &cut);
    }
}

/// The head yaw is held to its own limits and the link angles to theirs: a turn at
/// 0.6 rad/s (between the two rate limits) passes for the head yaw and fails for a
/// link's yaw, and one faster than the head yaw's limit fails naming that limit.
#[test]
fn the_check_holds_the_head_yaw_and_the_links_to_their_own_limits() {
    let params = ChainParams::new(3);
    let grid = room();
    let lim = Limits::default();
    assert!(lim.angular_rate < 0.6 && 0.6 < lim.yaw_rate && lim.yaw_rate < 0.9);
    let base = tour(&params).waypoints[0].zeta.clone();
    let dt = 0.02;
    let times: Vec<f64> = (0..10).map(|k| f64::from(k) * dt).collect();
    // Angle `j` of zeta turning at a constant `rate` (no acceleration).
    let turning = |j: usize, rate: f64| -> Vec<Vec<f64>> {
        times
            .iter()
            .map(|t| {
                let mut z = base.clone();
                z[j] += rate * t;
                z
            })
            .collect()
    };
    let check = |z: &[Vec<f64>]| check_samples(&grid, &params, &lim, &times, z, 0.0);
    let head = check(&turning(3, 0.6));
    assert!(head.ok, "{:?}", head.violation);
    assert!((head.peaks.yaw_rate - 0.6).abs() < 1e-9 && head.peaks.angular_rate == 0.0);
    let rate_problem = |z: &[Vec<f64>]| match check(z).violation.map(|v| v.problem) {
        Some(Problem::AngularRate { angle, limit, .. }) => (angle, limit),
        other => panic!("{other:?}"),
    };
    assert_eq!(
        rate_problem(&turning(5, 0.6)),
        ("psi1".to_string(), lim.angular_rate)
    );
    assert_eq!(
        rate_problem(&turning(3, 0.9)),
        ("psi1_r".to_string(), lim.yaw_rate)
    );
}

/// A trajectory file or settings file written before the head yaw had limits of its
/// own reads them as the defaults; a limit that is not positive is refused by name.
#[test]
fn limits_without_the_head_yaws_read_the_defaults_and_bad_ones_are_named() {
    let old: Limits = serde_json::from_str(
        r#"{"speed": 0.5, "accel": 0.5, "angular_rate": 0.4, "angular_accel": 0.5}"#,
    )
    .unwrap();
    assert_eq!(old, Limits::default());
    for (name, bad) in [
        (
            "yaw_rate",
            Limits {
                yaw_rate: 0.0,
                ..Limits::default()
            },
        ),
        (
            "yaw_accel",
            Limits {
                yaw_accel: f64::NAN,
                ..Limits::default()
            },
        ),
    ] {
        match bad.validate() {
            Err(TrajectoryError::Limit { name: n, .. }) => assert_eq!(n, name),
            other => panic!("{name}: {other:?}"),
        }
    }
}

#[test]
fn the_check_names_what_is_wrong() {
    let params = ChainParams::new(3);
    let grid = room();
    let lim = Limits::default();
    let tr = built(&tour(&params), &grid);
    let (t, z) = (tr.times().to_vec(), tr.zetas().to_vec());
    let check = |t: &[f64], z: &[Vec<f64>]| {
        check_samples(&grid, &params, &lim, t, z, 0.0)
            .violation
            .map(|v| v.problem)
    };
    assert_eq!(check(&t, &z), None);
    let fast: Vec<f64> = t.iter().map(|x| x * 0.6).collect();
    assert!(matches!(
        check(&fast, &z),
        Some(
            Problem::Speed { .. }
                | Problem::Accel { .. }
                | Problem::AngularRate { .. }
                | Problem::AngularAccel { .. }
        )
    ));
    let mut back = t.clone();
    back[5] = back[4];
    assert!(matches!(check(&back, &z), Some(Problem::Time { .. })));
    let mut short = z.clone();
    short[7].pop();
    assert!(matches!(check(&t, &short), Some(Problem::Sample { .. })));
    let mut out = z.clone();
    let j = z.len() / 2;
    out[j][2] = 1.95;
    out[j + 1][2] = 1.95;
    let p = check(&t, &out).unwrap();
    assert!(
        matches!(
            p,
            Problem::Invalid(_) | Problem::Speed { .. } | Problem::Accel { .. }
        ),
        "{p}"
    );
    // Slow enough for the limits, but the jump passes through the ceiling.
    let slow: Vec<f64> = t.iter().map(|x| x * 1000.0).collect();
    assert!(matches!(check(&slow, &out), Some(Problem::Invalid(_))));
}

#[test]
fn file_round_trips_and_refuses_bad_records() {
    let params = ChainParams::new(3);
    let plan = tour(&params);
    let tr = built(&plan, &room());
    let file = TrajectoryFile::new(&tr, &plan);
    let text = serde_json::to_string(&file).unwrap();
    let back = TrajectoryFile::parse(&text, "t.json").unwrap();
    assert_eq!(back, file, "numbers read back exactly");
    assert_eq!(back.zetas(), tr.zetas());
    let csv = file.to_csv();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), tr.times().len() + 1);
    let cols = lines[0].split(',').count();
    assert_eq!(cols, 1 + 8 + 3 * 7);
    assert!(lines.iter().all(|l| l.split(',').count() == cols));
    let mut bad = file.clone();
    bad.samples[3].p[1][0] += 0.01;
    let e = TrajectoryFile::parse(&serde_json::to_string(&bad).unwrap(), "t.json").unwrap_err();
    assert!(e.to_string().contains("samples[3].p[1]"), "{e}");
    let mut bad = file.clone();
    let last = bad.samples.len() - 1;
    bad.samples[last].q[0] = [1.0, 0.0, 0.0, 0.0];
    let e = TrajectoryFile::parse(&serde_json::to_string(&bad).unwrap(), "t.json").unwrap_err();
    assert!(
        e.to_string().contains(&format!("samples[{last}].q[0]")),
        "{e}"
    );
    let e = TrajectoryFile::parse(
        &text.replace("arc-trajectory/1", "arc-trajectory/9"),
        "t.json",
    )
    .unwrap_err();
    assert!(e.to_string().contains("format"), "{e}");
    assert!(TrajectoryFile::parse("{}", "t.json").is_err());
}

#[test]
fn blended_reference_is_smooth_and_within_limits_between_samples() {
    let params = ChainParams::new(3);
    let tr = built(&tour(&params), &room());
    let r = tr.reference();
    let lim = Limits::default();
    let (h, mut t) = (1e-5, 0.01);
    while t < r.duration() {
        let (a, b, c) = (r.sample(t - h), r.sample(t), r.sample(t + h));
        assert!(((c.p - a.p) / (2.0 * h) - b.v).norm() < 1e-5, "t = {t}");
        assert!(((c.v - a.v) / (2.0 * h) - b.a).norm() < 1e-3, "t = {t}");
        assert!(b.a.norm() <= lim.accel * (1.0 + 1e-9) && b.v.norm() <= lim.speed * (1.0 + 1e-9));
        for k in 0..2 {
            let d = (c.links[k].yaw - a.links[k].yaw) / (2.0 * h) - b.links[k].yaw_rate;
            assert!(d.abs() < 1e-5);
            assert!(b.links[k].yaw_acc.abs() <= lim.angular_accel * (1.0 + 1e-9));
            assert!(b.links[k].yaw_rate.abs() <= lim.angular_rate * (1.0 + 1e-9));
        }
        t += 0.0173;
    }
}

#[test]
fn bad_settings_and_plans_are_refused() {
    let params = ChainParams::new(3);
    let grid = room();
    let s = Settings {
        dt: 0.0,
        ..Settings::default()
    };
    assert!(matches!(
        build(&tour(&params), &grid, &s),
        Err(TrajectoryError::Dt(_))
    ));
    let s = Settings {
        limits: Limits {
            speed: -1.0,
            ..Limits::default()
        },
        ..Settings::default()
    };
    assert!(matches!(
        build(&tour(&params), &grid, &s),
        Err(TrajectoryError::Limit { .. })
    ));
    let mut mixed = tour(&params);
    mixed.waypoints[1].zeta[4] = 0.3;
    let e = build(&mixed, &grid, &Settings::default()).unwrap_err();
    assert!(e.to_string().contains("changes both"), "{e}");
    // A plan through a wall is inadmissible with or without blends.
    let mut wall = room();
    wall.fill_box([2.0, 0.0, 0.0], [2.1, 4.0, 2.0], Cell::Occupied);
    assert!(matches!(
        build(&tour(&params), &wall, &Settings::default()),
        Err(TrajectoryError::Inadmissible(_))
    ));
}

/// Follow-the-leader of a chain of 4 units along an arc of radius `radius` about
/// (2, 2, 1), as threading makes it: the body laid on the circle, then a translation
/// of `step` along the chord; `steps` of them from the head at angle 0.
fn arc_follow(radius: f64, step: f64, steps: usize) -> Plan {
    let params = &ChainParams::new(4);
    let l = params.link_length as f64;
    let spacing = 2.0 * (l / (2.0 * radius)).asin();
    let at = |phi: f64| [2.0 + radius * phi.cos(), 2.0 + radius * phi.sin(), 1.0];
    let laid = |phi: f64| {
        let mut s = Shape::line(params.units, 0.0);
        for k in 0..params.links() {
            let (p, q) = (
                at(phi - spacing * k as f64),
                at(phi - spacing * (k + 1) as f64),
            );
            s.set_link(k, 0.0, (p[1] - q[1]).atan2(p[0] - q[0]) as f32);
        }
        s.set_head_yaw(s.yaw(0));
        s
    };
    let dphi = step / radius;
    let mut points = vec![(at(0.0), laid(0.0))];
    for j in 1..=steps {
        let phi = j as f64 * dphi;
        points.push((at(phi), laid(phi - dphi)));
        points.push((at(phi), laid(phi)));
    }
    plan(params, &points)
}

#[test]
fn follow_the_leader_steps_fly_as_runs() {
    let s = Settings::default();
    // A quarter turn of radius 1.2 m in 2 cm steps: 2 x 94 edges.
    let plan = arc_follow(1.2, 0.02, 94);
    let grid = room();
    let tr = built(&plan, &grid);
    let motions = tr.corners() + 1 - tr.merged();
    assert!(
        motions * 8 <= tr.corners() + 1,
        "{motions} motions for {} edges",
        tr.corners() + 1
    );
    // Flown as runs the arc takes little more than its length at the speed limit
    // (edge by edge, every step's turn would bring the chain nearly to rest).
    let path = tr.head_path_m() / s.limits.speed;
    assert!(
        tr.duration() < 1.6 * path,
        "{} s for {path} s",
        tr.duration()
    );
    assert_respects_limits(&grid, &tr);
    // A tighter arc bends the links faster: shorter runs.
    let tight = built(&arc_follow(0.6, 0.02, 47), &grid);
    let tight_motions = tight.corners() + 1 - tight.merged();
    assert!(
        tight_motions * 94 > motions * 47,
        "{tight_motions} vs {motions}"
    );
}

#[test]
fn a_run_that_would_touch_the_map_is_halved() {
    let plan = arc_follow(1.2, 0.02, 94);
    let free = built(&plan, &room());
    // On a 2 cm grid, a voxel just inside the arc: its far corner is 1.016 m from the
    // centre, so the plan's own edges pass it at 2-3 cm (a translation carries the
    // units behind the head inwards, off the circle), under the margin that every
    // merged motion must keep there.
    let mut grid = Grid::new(0.02, [0, 0, 0], [200, 200, 100], Cell::Free, true).unwrap();
    grid.fill_box([2.801, 2.581, 0.99], [2.819, 2.599, 1.01], Cell::Occupied);
    let near = built(&plan, &grid);
    assert!(
        near.merged() < free.merged(),
        "{} vs {}",
        near.merged(),
        free.merged()
    );
    assert_respects_limits(&grid, &near);
}

#[test]
fn a_pair_that_would_touch_the_map_flies_less_of_its_translation() {
    // 2 m along x, then the chain turns by 0.6 rad about its head, swinging its tail
    // towards -y. Merged with the whole translation, the tail would start to swing at
    // the start and pass a box beside the first metre of the head's track; merged with
    // the last metre or half metre only, it swings clear of it.
    let params = ChainParams::new(4);
    let line = Shape::line(4, 0.0);
    let plan = plan(
        &params,
        &[
            ([2.0, 2.0, 1.0], line),
            ([4.0, 2.0, 1.0], line),
            ([4.0, 2.0, 1.0], line.rotated(0.6)),
        ],
    );
    let mut grid = Grid::new(0.1, [0, 0, 0], [60, 40, 20], Cell::Free, true).unwrap();
    let free = built(&plan, &grid);
    assert_eq!((free.corners(), free.merged()), (1, 1));
    grid.fill_box([1.0, 1.2, 0.8], [1.4, 1.45, 1.2], Cell::Occupied);
    let near = built(&plan, &grid);
    let apart = build(
        &plan,
        &grid,
        &Settings {
            blend: false,
            ..Settings::default()
        },
    )
    .unwrap();
    assert_eq!(
        near.merged(),
        1,
        "the pair is kept, on part of the translation"
    );
    assert!(
        near.duration() < apart.duration() - 1.0 && near.duration() > free.duration(),
        "{} s between {} and {} s",
        near.duration(),
        free.duration(),
        apart.duration()
    );
    assert_respects_limits(&grid, &near);
}

#[test]
fn runs_of_short_steps_may_cut_their_corners_by_more() {
    // A quarter turn of radius 0.6 m in 2 cm steps: the straight move through many of
    // them passes their waypoints 2-6 cm off, which short steps allow and long edges
    // do not (with 2 cm for these too, the turn took 5 motions).
    let grid = room();
    let tight = built(&arc_follow(0.6, 0.02, 47), &grid);
    let motions = tight.corners() + 1 - tight.merged();
    assert!(motions <= 2, "{motions} motions");
    assert_respects_limits(&grid, &tight);
    // The same turn in 3 steps of 0.3 m: no run joins two of them (each step's shape
    // change and translation fly as a pair).
    let long = built(&arc_follow(0.6, 0.3, 3), &grid);
    assert_eq!(long.corners() + 1 - long.merged(), 3);
}

/// The smallest clearance any body keeps along the plan's own edges (the verifier's,
/// which knows nothing of the generator), and along the trajectory's samples.
fn plan_and_flown_clearance(grid: &Grid, plan: &Plan, tr: &Trajectory) -> (f64, f64) {
    let own = crate::collision::verify::verify_plan(grid, plan);
    assert!(own.ok, "{:?}", own.violation);
    let params = *tr.params();
    let lim = &tr.settings().limits;
    let flown = check_samples(grid, &params, lim, tr.times(), tr.zetas(), 1.0);
    assert!(flown.ok, "{:?}", flown.violation);
    (own.min_clearance, flown.min_clearance)
}

/// Three units along +x beside a wall whose face the bodies pass at 3 cm, less than
/// the 5 cm margin: the plan's two edges lie on one line.
fn along_a_close_wall(params: &ChainParams) -> (Plan, Grid) {
    let s = Shape::line(3, 0.0);
    let plan = plan(
        params,
        &[
            ([1.6, 1.02, 1.0], s),
            ([2.3, 1.02, 1.0], s),
            ([3.0, 1.02, 1.0], s),
        ],
    );
    let mut grid = room();
    grid.fill_box([0.51, 1.21, 0.51], [3.49, 1.29, 1.49], Cell::Occupied);
    (plan, grid)
}

#[test]
fn a_blend_beside_a_wall_the_plan_keeps_close_keeps_what_the_plan_keeps() {
    let params = ChainParams::new(3);
    let (plan, grid) = along_a_close_wall(&params);
    let tr = built(&plan, &grid);
    // Straight on: the corner is flown without a stop, as in a free room.
    assert_eq!(
        tr.blended() + tr.merged(),
        1,
        "the corner is not flown through"
    );
    let free = built(&plan, &room());
    assert!((tr.duration() - free.duration()).abs() < 1e-9);
    let (own, flown) = plan_and_flown_clearance(&grid, &plan, &tr);
    assert!((own - 0.03).abs() < 1e-6, "the plan keeps {own}");
    assert!(flown >= own - 1e-9, "flown {flown} < the plan's {own}");
}

#[test]
fn a_blend_that_comes_closer_than_the_plan_below_the_margin_is_not_flown() {
    let params = ChainParams::new(3);
    // The corner of `corner` 3 cm lower, its voxel 10 cm further back: the plan's own
    // edges keep 3.5 cm from it, and the rounded corner lifts the tail closer.
    let mut grid = room();
    grid.fill_box([1.61, 0.51, 1.21], [1.69, 1.49, 1.29], Cell::Occupied);
    let plan = corner_below(&params, 0.03);
    let tr = built(&plan, &grid);
    assert_eq!(
        tr.blended(),
        0,
        "the rounded corner comes closer than the plan"
    );
    let (own, flown) = plan_and_flown_clearance(&grid, &plan, &tr);
    assert!(own < Settings::default().clearance, "the plan keeps {own}");
    assert!(flown >= own - 1e-9, "flown {flown} < the plan's {own}");
    // Blended, it would keep less than the plan: the rule, not the map, refuses it.
    let free = built(&plan, &room());
    assert_eq!(free.blended(), 1);
    let lim = &free.settings().limits;
    let blended = check_samples(&grid, &params, lim, free.times(), free.zetas(), 1.0);
    assert!(blended.ok, "{:?}", blended.violation);
    assert!(
        blended.min_clearance < own,
        "{} >= {own}",
        blended.min_clearance
    );
}
