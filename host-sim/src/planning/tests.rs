//! The facade's tests: the same plan as the steps it stands for, and its errors.

use aerial_chain_core::{ChainParams, Shape};
use nalgebra::Point3;

use super::*;
use crate::collision::verify_plan;
use crate::planner::{Settings, Termination};
use crate::problem::scenarios;
use crate::tables::TableSettings;

/// The `window` scenario for a chain of 3 and options with small tables (fast).
fn window() -> (Request, PlanOptions) {
    let sc = scenarios::build("window").unwrap();
    let params = ChainParams::new(3);
    let query = Query::new(sc.start, sc.start_shape(3).unwrap(), sc.goal);
    let options = PlanOptions {
        srs: 60,
        ..PlanOptions::default()
    };
    (Request::new(sc.grid.clone(), params, query), options)
}

#[test]
fn the_facade_plans_as_search_refine_and_annotate_do_one_by_one() {
    let (request, options) = window();
    let planned = plan(&request, None, &options).unwrap();
    // The same steps by hand, as `arc plan` ran them before the facade.
    let tables = ShapeTables::build(
        request.params,
        &TableSettings {
            srs: 60,
            ..TableSettings::default()
        },
        &AtomicUsize::new(0),
    )
    .unwrap();
    let ctx = CollisionContext::new(request.field.clone(), request.params, options.clearance);
    let mut planner = ArcPlanner::new(ctx.unwrap(), tables, Settings::default()).unwrap();
    let raw = planner
        .solve(&request.query, Termination::default())
        .unwrap();
    let (refined, r) = planner.refine(&raw, None);
    let mut by_hand = to_plan(&refined, &request.params, request.map.clone());
    annotate_quality(&mut by_hand, &Quality::of(&refined.steps), Some(&r));
    assert_eq!(planned.plan.waypoints, by_hand.waypoints);
    assert_eq!(planned.plan.stats["quality"], by_hand.stats["quality"]);
    assert!(planned.plan.stats.contains_key("refinement"));
    assert_eq!(planned.quality, Quality::of(&refined.steps));
    assert!(verify_plan(request.grid(), &planned.plan).ok);
    assert!(planned.trajectory.is_none());
}

#[test]
fn without_smoothing_the_plan_is_the_searchs_and_a_trajectory_comes_when_asked() {
    let (request, mut options) = window();
    options.no_smooth = true;
    options.trajectory = Some(crate::trajectory::Settings::default());
    let planned = plan(&request, None, &options).unwrap();
    assert!(planned.refinement.is_none());
    assert!(!planned.plan.stats.contains_key("refinement"));
    let tr = planned.trajectory.expect("asked for").expect("admissible");
    assert!(tr.duration() > 0.0);
}

#[test]
fn bad_input_and_no_plan_are_told_apart() {
    let (request, options) = window();
    let bad_clearance = PlanOptions {
        clearance: -1.0,
        ..options.clone()
    };
    let e = plan(&request, None, &bad_clearance).unwrap_err();
    assert!(
        e.is_input() && e.to_string().starts_with("clearance = -1"),
        "{e}"
    );
    let mut in_wall = request.clone();
    in_wall.query.start = Point3::new(4.1, 1.0, 1.5);
    let e = plan(&in_wall, None, &options).unwrap_err();
    assert!(
        e.is_input() && e.to_string().contains("start is invalid"),
        "{e}"
    );
    let other_chain = ShapeTables::build(
        ChainParams::new(4),
        &options.table_settings(),
        &AtomicUsize::new(0),
    )
    .unwrap();
    let e = plan(&request, Some(other_chain), &options).unwrap_err();
    assert!(e.is_input(), "{e}");
    // A microsecond: far less than the window's query takes.
    let short = PlanOptions {
        time_limit_s: Some(1e-6),
        ..options
    };
    let e = plan(&request, None, &short).unwrap_err();
    assert!(!e.is_input(), "{e}");
    let s = e.to_string();
    assert!(s.starts_with("no plan: time limit reached"), "{s}");
    assert!(s.contains("time limit stopped it after trying"), "{s}");
}

#[test]
fn tuning_settings_reach_the_search_post_processing_and_the_trajectory() {
    let (request, mut options) = window();
    options.trajectory = Some(crate::trajectory::Settings::default());
    let base = plan(&request, None, &options).unwrap();
    let widen = |p: &Planned| p.refinement.as_ref().expect("refined").widening;
    // Widening with one measurement moves nothing: what widening trades is its budget.
    let mut tight = options.clone();
    tight.refine.widen.budget = 1;
    let t = plan(&request, None, &tight).unwrap();
    assert!(widen(&base).moves > 0, "{:?}", widen(&base));
    assert_eq!(widen(&t).moves, 0, "{:?}", widen(&t));
    assert!(widen(&t).after < widen(&base).after);
    // A lattice search that may not jump through open space expands more points.
    let mut short = options.clone();
    short.planner.lattice.max_jump = 1.0;
    let e = plan(&request, None, &short).unwrap();
    let expanded = (base.stats.lattice_expanded, e.stats.lattice_expanded);
    assert!(expanded.1 > expanded.0, "{expanded:?}");
    // A trajectory whose runs join one edge merges no corner.
    let mut single = options.clone();
    single.trajectory = Some(crate::trajectory::Settings {
        max_run: 1,
        ..crate::trajectory::Settings::default()
    });
    let s = plan(&request, None, &single).unwrap();
    let merged = |p: &Planned| p.trajectory.as_ref().unwrap().as_ref().unwrap().merged();
    assert!(merged(&s) <= merged(&base));
    // Out of range: refused as bad input, naming the field.
    let mut bad = options.clone();
    bad.refine.widen.centred = 2.0;
    let err = plan(&request, None, &bad).unwrap_err();
    assert!(
        err.is_input() && err.to_string().contains("refine.widen.centred"),
        "{err}"
    );
}

/// A room 4 x 4 x 2 m at 0.05 m whose wall at `y = 0` is `gap` from a chain of 4 at
/// rest whose links point straight at it, the head 1.5 m into the room: the start's
/// units keep less than the clearance, its head far more.
fn tail_at_a_wall(gap: f64) -> Request {
    use crate::map::grid::Cell;
    let params = ChainParams::new(4);
    let eta = [
        0.0f32,
        0.0,
        std::f32::consts::FRAC_PI_2,
        0.0,
        std::f32::consts::FRAC_PI_2,
        0.0,
        std::f32::consts::FRAC_PI_2,
    ];
    let shape = Shape::from_slice(4, &eta).unwrap();
    let offsets = aerial_chain_core::kinematics::offsets(&params, &shape);
    let reach = offsets
        .iter()
        .take(4)
        .map(|o| -o.y as f64)
        .fold(0.0, f64::max);
    let mut grid = Grid::new(0.05, [0, 0, 0], [80, 80, 40], Cell::Free, false).unwrap();
    for x in 0..80 {
        for z in 0..40 {
            grid.set([x, 0, z], Cell::Occupied);
        }
    }
    // The wall's face is at y = 0.05; the tail's centre `r_u + gap` from it.
    let head_y = 0.05 + params.unit_radius as f64 + gap + reach;
    let query = Query::new(
        Point3::new(1.0, head_y, 1.0),
        shape,
        Point3::new(2.5, head_y, 1.0),
    );
    Request::new(grid, params, query)
}

#[test]
fn a_start_within_the_clearance_is_left_keeping_what_it_keeps() {
    let request = tail_at_a_wall(0.02);
    let options = PlanOptions {
        srs: 60,
        ..PlanOptions::default()
    };
    assert!(request
        .query
        .check(&CollisionContext::new(request.field.clone(), request.params, 0.0).unwrap())
        .is_ok());
    let planned = plan(&request, None, &options).unwrap();
    // The head route from the start keeps the clearance, so the chain leaves along it:
    // no uniform roadmap is sampled for another way out.
    assert_eq!(planned.stats.roadmap_vertices, 0);
    let report = verify_plan(request.grid(), &planned.plan);
    assert!(report.ok, "{:?}", report.violation);
    assert!(report.min_clearance >= 0.019, "{}", report.min_clearance);
    assert!(
        planned.stats.min_margin >= 0.019,
        "{}",
        planned.stats.min_margin
    );
}
