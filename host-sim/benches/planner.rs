//! Criterion benches of the planner's parts: the uniform head roadmap's build on
//! `window` and on a seen room of it, one ARCplanner query on `window` with N = 5,
//! batches of translation and shape-change checks, and the full-state PRM's roadmap
//! build for comparison.
//!
//! `cargo bench -p aerial-chain --bench planner`

use std::hint::black_box;
use std::sync::atomic::AtomicUsize;
use std::sync::Arc;
use std::time::Duration;

use aerial_chain::baseline::{FullStatePrm, PrmSettings};
use aerial_chain::collision::{CollisionContext, DEFAULT_CLEARANCE};
use aerial_chain::map::{Cell, DistanceField};
use aerial_chain::planner::{ArcPlanner, Planner, Query, Settings, Termination};
use aerial_chain::problem::scenarios::{self, Scenario};
use aerial_chain::tables::{ShapeTables, TableSettings};
use aerial_chain_core::{ChainParams, Shape};
use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use rand::{Rng, SeedableRng};

fn window(units: u8) -> (Scenario, CollisionContext, ShapeTables) {
    let sc = scenarios::build("window").expect("built-in scenario");
    let field = Arc::new(DistanceField::new(sc.grid.clone()));
    let params = ChainParams::new(units);
    let ctx = CollisionContext::new(field, params, DEFAULT_CLEARANCE).expect("valid chain");
    let tables = ShapeTables::build(params, &TableSettings::default(), &AtomicUsize::new(0))
        .expect("tables");
    (sc, ctx, tables)
}

fn planner(ctx: &CollisionContext, tables: &ShapeTables, settings: &Settings) -> ArcPlanner {
    ArcPlanner::new(ctx.clone(), tables.clone(), settings.clone()).expect("same chain")
}

/// The uniform head roadmap's 1500 vertices (the paper's planner: with the head
/// lattice off, `setup` builds it) on the whole `window` map, and on `window` where
/// only a 3 x 2.5 x 2 m room about the start is free, as on a map seen early in a
/// flight with unknown space occupied: there hundreds of vertices lie within `r_T`
/// of each.
fn roadmap_build(c: &mut Criterion) {
    let (sc, ctx, tables) = window(5);
    let mut g = c.benchmark_group("planner");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    let query = Query::new(sc.start, sc.start_shape(5).expect("N = 5"), sc.goal);
    let settings = Settings {
        head_lattice: false,
        ..Settings::default()
    };
    let mut room = sc.grid.clone();
    let s = sc.start;
    room.fill_where(Cell::Occupied, |p| {
        (p.x - s.x).abs() > 1.5 || (p.y - s.y).abs() > 1.25 || (p.z - s.z).abs() > 1.0
    });
    let field = Arc::new(DistanceField::new(room));
    let seen = CollisionContext::new(field, *ctx.params(), DEFAULT_CLEARANCE).expect("chain");
    for (name, ctx) in [("window", &ctx), ("seen_room", &seen)] {
        g.bench_function(format!("roadmap_build/{name}_1500"), |b| {
            b.iter_batched(
                || planner(ctx, &tables, &settings),
                |mut p| {
                    p.setup(&query, Termination::default());
                    p
                },
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

fn query_and_prm(c: &mut Criterion) {
    let (sc, ctx, tables) = window(5);
    let mut g = c.benchmark_group("planner");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    let shape = sc.start_shape(5).expect("N = 5");
    let query = Query::new(sc.start, shape, sc.goal);
    g.bench_function("solve/window_n5", |b| {
        b.iter_batched(
            || {
                let mut p = planner(&ctx, &tables, &Settings::default());
                p.setup(&query, Termination::default());
                p
            },
            |mut p| {
                let r = p.solve(&query, Termination::default());
                black_box(r.is_ok())
            },
            BatchSize::LargeInput,
        )
    });
    g.bench_function("prm_roadmap_build/window_n5_1500", |b| {
        b.iter_batched(
            || FullStatePrm::new(ctx.clone(), PrmSettings::default()).expect("settings"),
            |mut p| {
                p.setup(&query, Termination::default());
                p
            },
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

/// 200 valid placements of SRS shapes in `window`, each with a translation target
/// 0.5 m away and another SRS shape to change to.
fn cases(ctx: &CollisionContext, tables: &ShapeTables) -> Vec<([f64; 3], [f64; 3], Shape, Shape)> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
    let (lo, hi) = ctx.field().grid().bounds();
    let mut v = Vec::new();
    while v.len() < 200 {
        let p = [
            rng.gen_range(lo[0]..hi[0]),
            rng.gen_range(lo[1]..hi[1]),
            rng.gen_range(lo[2]..hi[2]),
        ];
        let s = tables.srs[rng.gen_range(0..tables.srs.len())];
        if ctx.check_placement(p, &s).is_err() {
            continue;
        }
        let a: f64 = rng.gen_range(0.0..std::f64::consts::TAU);
        let q = [p[0] + 0.5 * a.cos(), p[1] + 0.5 * a.sin(), p[2]];
        let t = tables.srs[rng.gen_range(0..tables.srs.len())];
        v.push((p, q, s, t));
    }
    v
}

fn checks(c: &mut Criterion) {
    let (_, ctx, tables) = window(5);
    let cases = cases(&ctx, &tables);
    let mut g = c.benchmark_group("checks");
    g.sample_size(20).measurement_time(Duration::from_secs(3));
    g.bench_function("translation_x200/window_n5", |b| {
        b.iter(|| {
            cases
                .iter()
                .filter(|(p, q, s, _)| ctx.check_translation(*p, *q, s).is_ok())
                .count()
        })
    });
    g.bench_function("shape_change_x200/window_n5", |b| {
        b.iter(|| {
            cases
                .iter()
                .filter(|(p, _, s, t)| ctx.check_shape_change(*p, s, t).is_ok())
                .count()
        })
    });
    g.bench_function("placement_x200/window_n5", |b| {
        b.iter(|| {
            cases
                .iter()
                .filter(|(p, _, s, _)| ctx.check_placement(*p, s).is_ok())
                .count()
        })
    });
    g.finish();
}

criterion_group!(benches, roadmap_build, query_and_prm, checks);
criterion_main!(benches);
