//! Core benchmarks: SRS sampling with roadmap, table decode + CRC, forward
//! kinematics. Run with `cargo bench -p aerial-chain-core --bench core`.

use std::hint::black_box;

use aerial_chain_core::kinematics::offsets;
use aerial_chain_core::lsc::library;
use aerial_chain_core::srs::{Srs, SrsSettings};
use aerial_chain_core::table::{encode_into, TableView};
use aerial_chain_core::{ChainParams, Shape};
use criterion::{criterion_group, criterion_main, Criterion};

/// Capacity of the benchmarked SRS and its roadmap degree (the host's defaults).
type Srs500 = Srs<500, 12>;

fn srs_sampling(c: &mut Criterion) {
    let p = ChainParams::new(6);
    let mut g = c.benchmark_group("srs");
    g.sample_size(20);
    g.bench_function("sample_and_roadmap_n6_500", |b| {
        b.iter(|| Srs500::generate(black_box(p), &SrsSettings::new(6, 500, 1)).unwrap())
    });
    g.finish();
}

fn table_decode(c: &mut Criterion) {
    let p = ChainParams::new(6);
    let srs = Srs500::generate(p, &SrsSettings::new(6, 500, 1)).unwrap();
    let lib = library(&p);
    let mut buf = vec![0u8; 64 * 1024];
    let len = encode_into(&mut buf, &p, &lib.entries, &srs.shapes, &srs.adjacency).unwrap();
    println!(
        "table N=6, N_SRS=500: {len} bytes ({:.1} KiB)",
        len as f64 / 1024.0
    );
    let blob = &buf[..len];
    c.bench_function("table/open_check_crc_n6_500", |b| {
        b.iter(|| TableView::open(black_box(blob), Some(&p)).unwrap())
    });
    c.bench_function("table/open_and_copy_srs_n6_500", |b| {
        b.iter(|| {
            TableView::open(black_box(blob), Some(&p))
                .unwrap()
                .to_srs::<500, 12>()
                .unwrap()
        })
    });
}

fn forward_kinematics(c: &mut Criterion) {
    let p = ChainParams::new(16);
    let mut s = Shape::line(16, 0.0);
    for k in 0..15 {
        s.set_link(k, 0.05 * k as f32 - 0.3, 0.2 * k as f32);
    }
    c.bench_function("kinematics/offsets_n16", |b| {
        b.iter(|| offsets(black_box(&p), black_box(&s)))
    });
}

criterion_group!(benches, srs_sampling, table_decode, forward_kinematics);
criterion_main!(benches);
