//! Criterion benches of the shape-table build: `G_SRS` from the same random shapes with
//! the two candidate searches (head-yaw window, k-d tree), which give the same roadmap.
//!
//! `cargo bench -p aerial-chain --bench tables`

use std::hint::black_box;
use std::time::Duration;

use aerial_chain::tables::{roadmap, CandidateSearch};
use aerial_chain_core::srs::{Sampler, SrsSettings};
use aerial_chain_core::{ChainParams, Shape};
use criterion::{criterion_group, criterion_main, Criterion};

/// Random shapes as `arc tables build` samples them, and the default radius.
fn random_shapes(units: u8, count: usize) -> (ChainParams, Vec<Shape>, f32) {
    let params = ChainParams::new(units);
    let settings = SrsSettings::new(units, count, 1);
    let mut sampler = Sampler::new(params, settings.seed, settings.max_tries_per_shape);
    let shapes = (0..count)
        .map(|_| sampler.next_shape().expect("valid shapes"))
        .collect();
    (params, shapes, settings.r_s)
}

fn srs_roadmap(c: &mut Criterion) {
    let mut g = c.benchmark_group("tables");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    for (units, count) in [(3u8, 8_000usize), (6, 4_000)] {
        let (params, shapes, r_s) = random_shapes(units, count);
        for (name, search) in [
            ("yaw_window", CandidateSearch::YawWindow),
            ("kd_tree", CandidateSearch::KdTree),
        ] {
            g.bench_function(format!("srs_roadmap/n{units}_{count}/{name}"), |b| {
                b.iter(|| black_box(roadmap(&params, &shapes, r_s, search)))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, srs_roadmap);
criterion_main!(benches);
