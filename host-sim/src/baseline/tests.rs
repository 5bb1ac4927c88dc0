//! Tests of the full-state PRM: an easy query solved and verified, bad settings and
//! queries refused, a too sparse roadmap failing cleanly, the time limit honoured.

use std::sync::Arc;
use std::time::Duration;

use aerial_chain_core::{ChainParams, Shape};
use nalgebra::Point3;

use super::*;
use crate::collision::{verify_plan, CollisionContext, DEFAULT_CLEARANCE};
use crate::map::distance::DistanceField;
use crate::plan_file::MapSection;
use crate::planner::dist;
use crate::planner::motion::to_plan;
use crate::problem::scenarios;

fn window_ctx(units: u8) -> (CollisionContext, scenarios::Scenario) {
    let sc = scenarios::build("window").unwrap();
    let field = Arc::new(DistanceField::new(sc.grid.clone()));
    let ctx = CollisionContext::new(field, ChainParams::new(units), DEFAULT_CLEARANCE).unwrap();
    (ctx, sc)
}

/// An easy query in the window scenario's first room (no window to pass).
fn easy(
    units: u8,
    seed: u64,
) -> (
    Result<PrmSolution, PrmError>,
    CollisionContext,
    scenarios::Scenario,
) {
    let (ctx, sc) = window_ctx(units);
    let settings = PrmSettings {
        vertices: 600,
        seed,
        ..Default::default()
    };
    let mut prm = FullStatePrm::new(ctx.clone(), settings).unwrap();
    let start = Point3::new(2.0, 4.0, 1.5);
    let shape = Shape::line(units, std::f32::consts::FRAC_PI_2);
    let goal = Point3::new(2.5, 2.0, 1.5);
    let stop = Termination {
        time_limit: Some(Duration::from_secs(60)),
    };
    (prm.solve(&Query::new(start, shape, goal), stop), ctx, sc)
}

#[test]
fn solves_an_easy_query_and_the_plan_verifies() {
    let (res, ctx, sc) = easy(3, 3);
    let sol = res.expect("an open room is easy for 600 vertices");
    assert!(sol.steps.len() >= 2);
    let last = sol.steps.last().unwrap().xi;
    assert!(dist(last, [2.5, 2.0, 1.5]) <= 0.3 + 1e-12);
    assert_eq!(sol.stats.vertices, 600);
    assert!(sol.stats.edges_checked >= sol.stats.path_edges);
    let plan = to_plan(&sol, ctx.params(), MapSection::new(0.1, true));
    plan.check().unwrap();
    let report = verify_plan(&sc.grid, &plan);
    assert!(report.ok, "{:?}", report.violation);
    assert_eq!(plan.stats["planner"], "full-state lazy PRM");
}

#[test]
fn same_seed_same_answer_other_seed_other_roadmap() {
    let (a, _, _) = easy(3, 5);
    let (b, _, _) = easy(3, 5);
    let (a, b) = (a.unwrap(), b.unwrap());
    assert_eq!(a.steps, b.steps);
    assert_eq!(a.stats.iterations, b.stats.iterations);
    assert_eq!(a.stats.edges_checked, b.stats.edges_checked);
    assert_eq!(a.stats.sample_tries, b.stats.sample_tries);
    let (c, _, _) = easy(3, 6);
    assert_ne!(a.stats.sample_tries, c.unwrap().stats.sample_tries);
}

#[test]
fn same_answer_on_other_threads() {
    let (a, _, _) = easy(3, 9);
    let b = std::thread::spawn(|| easy(3, 9).0).join().unwrap();
    assert_eq!(a.unwrap().steps, b.unwrap().steps);
}

#[test]
fn every_edge_is_shape_change_then_translation() {
    let (res, _, _) = easy(4, 2);
    let sol = res.unwrap();
    for w in sol.steps.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        if b.shape_change {
            assert_eq!(a.xi, b.xi);
        } else {
            assert_eq!(a.shape, b.shape);
        }
    }
    assert_eq!(
        sol.stats.shape_changes,
        sol.steps.iter().filter(|s| s.shape_change).count()
    );
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let (ctx, sc) = window_ctx(3);
    let bad = PrmSettings {
        vertices: 0,
        ..Default::default()
    };
    assert!(matches!(
        FullStatePrm::new(ctx.clone(), bad),
        Err(PrmError::BadSettings(_))
    ));
    let bad_k = PrmSettings {
        k: Some(0),
        ..Default::default()
    };
    assert!(FullStatePrm::new(ctx.clone(), bad_k).is_err());
    let mut prm = prm_of(ctx, 50);
    let stop = Termination::default();
    let yaw = sc.start_yaw as f32;
    // Another chain's shape.
    let r = prm.solve(&Query::new(sc.start, Shape::line(5, yaw), sc.goal), stop);
    assert!(matches!(r, Err(PrmError::StartInvalid(_))));
    // Start inside the wall.
    let r = prm.solve(
        &Query::new(Point3::new(4.1, 1.0, 1.5), Shape::line(3, yaw), sc.goal),
        stop,
    );
    assert!(matches!(r, Err(PrmError::StartInvalid(_))));
    // Goal outside the map, or not finite.
    let s = Shape::line(3, yaw);
    assert!(matches!(
        prm.solve(&Query::new(sc.start, s, Point3::new(100.0, 0.0, 0.0)), stop),
        Err(PrmError::GoalInvalid(_))
    ));
    assert!(matches!(
        prm.solve(
            &Query::new(sc.start, s, Point3::new(f64::NAN, 0.0, 0.0)),
            stop
        ),
        Err(PrmError::GoalInvalid(_))
    ));
    // A goal tolerance that is not a number.
    let bad_tol = Query {
        goal_tol: f64::NAN,
        ..Query::new(sc.start, s, sc.goal)
    };
    assert!(matches!(
        prm.solve(&bad_tol, stop),
        Err(PrmError::GoalInvalid(_))
    ));
    // A start within the goal tolerance is solved by itself.
    let sol = prm.solve(&Query::new(sc.start, s, sc.start), stop).unwrap();
    assert_eq!(sol.steps.len(), 1);
}

/// A PRM of `vertices` vertices, the other settings the defaults.
fn prm_of(ctx: CollisionContext, vertices: usize) -> FullStatePrm {
    let settings = PrmSettings {
        vertices,
        ..Default::default()
    };
    FullStatePrm::new(ctx, settings).expect("valid settings")
}

#[test]
fn too_sparse_roadmap_fails_cleanly() {
    let (ctx, sc) = window_ctx(5);
    let mut prm = prm_of(ctx, 20);
    let shape = sc.start_shape(5).unwrap();
    let r = prm.solve(
        &Query::new(sc.start, shape, sc.goal),
        Termination::default(),
    );
    assert!(matches!(r, Err(PrmError::NoPath { .. })), "{r:?}");
}

#[test]
fn time_limit_caps_build_and_query() {
    let (ctx, sc) = window_ctx(5);
    let mut prm = FullStatePrm::new(
        ctx,
        PrmSettings {
            vertices: 1_000_000,
            k: Some(2),
            ..Default::default()
        },
    )
    .unwrap();
    let shape = sc.start_shape(5).unwrap();
    let stop = Termination {
        time_limit: Some(Duration::from_millis(100)),
    };
    let t = std::time::Instant::now();
    let r = prm.solve(&Query::new(sc.start, shape, sc.goal), stop);
    assert!(r.is_err());
    assert!(prm.roadmap_stats().build_capped);
    assert!(prm.roadmap_stats().vertices < 1_000_000);
    assert!(t.elapsed() < Duration::from_secs(30));
}

#[test]
fn prm_star_k_grows_with_n() {
    assert!(prm_star_k(1500, 12) < prm_star_k(15000, 12));
    assert_eq!(prm_star_k(0, 0), prm_star_k(2, 1));
    assert_eq!(prm_star_k(1500, 12), 22);
}
