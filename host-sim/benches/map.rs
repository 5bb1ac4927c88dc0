//! Map and collision benchmarks: loading a 20 m x 20 m x 5 m map at 0.1 m from a `.bt`
//! file into a grid and distance field, the planner's conservative checks of a 6-unit
//! chain in clutter, and the distance field's update after one depth scan against a
//! recomputation (`field_update`).

use std::hint::black_box;
use std::sync::Arc;

use aerial_chain::collision::CollisionContext;
use aerial_chain::map::DistanceField;
use aerial_chain::map::OcTree;
use aerial_chain::map::{Cell, Grid};
use aerial_chain_core::{ChainParams, Shape};
use criterion::{criterion_group, criterion_main, BatchSize, Criterion};

/// A small deterministic generator (no dependency needed for a benchmark's clutter).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// 20 x 20 x 5 m at 0.1 m: floor, ceiling, outer walls, 60 pillars and 40 floating
/// boxes; everything else free.
fn clutter() -> Grid {
    let mut g = Grid::new(0.1, [0, 0, 0], [200, 200, 50], Cell::Free, true).unwrap();
    g.fill_box([0.0, 0.0, 0.0], [20.0, 20.0, 0.2], Cell::Occupied);
    g.fill_box([0.0, 0.0, 4.8], [20.0, 20.0, 5.0], Cell::Occupied);
    for (lo, hi) in [
        ([0.0, 0.0, 0.0], [0.2, 20.0, 5.0]),
        ([19.8, 0.0, 0.0], [20.0, 20.0, 5.0]),
        ([0.0, 0.0, 0.0], [20.0, 0.2, 5.0]),
        ([0.0, 19.8, 0.0], [20.0, 20.0, 5.0]),
    ] {
        g.fill_box(lo, hi, Cell::Occupied);
    }
    let mut r = Lcg(7);
    for k in 0..100 {
        let (x, y) = (1.0 + 18.0 * r.next(), 1.0 + 18.0 * r.next());
        let (w, d) = (0.3 + 0.7 * r.next(), 0.3 + 0.7 * r.next());
        let (z0, z1) = if k < 60 {
            (0.0, 5.0)
        } else {
            let z = 0.5 + 3.5 * r.next();
            (z, z + 0.3 + 0.5 * r.next())
        };
        g.fill_box([x, y, z0], [x + w, y + d, z1], Cell::Occupied);
    }
    g
}

fn bench(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("clutter.bt");
    let grid = clutter();
    grid.to_octree().unwrap().write_bt(&path).unwrap();

    let mut g = c.benchmark_group("map");
    g.sample_size(20);
    g.bench_function("load_20x20x5_bt_grid_and_field", |b| {
        b.iter(|| {
            let tree = OcTree::read_bt(&path).unwrap();
            let grid = Grid::from_octree(&tree, true).unwrap();
            black_box(DistanceField::new(grid))
        })
    });
    // The largest map the issue names: 100 m x 20 m x 5 m at 0.1 m (10 M voxels).
    let mut big = Grid::new(0.1, [0, 0, 0], [1000, 200, 50], Cell::Free, true).unwrap();
    for k in 0..50 {
        let x = 1.0 + 2.0 * k as f64;
        big.fill_box(
            [x, 0.0, 0.0],
            [x + 0.2, 15.0 - (k % 3) as f64 * 2.0, 5.0],
            Cell::Occupied,
        );
    }
    g.sample_size(10);
    g.bench_function("field_100x20x5", |b| {
        b.iter(|| black_box(DistanceField::new(big.clone())))
    });
    g.finish();
    let mut f = DistanceField::new(big);
    let plain = f.memory_bytes();
    f.prepare_updates();
    eprintln!(
        "field_100x20x5: memory {plain} B, {} B with what updates keep",
        f.memory_bytes()
    );

    let field = Arc::new(DistanceField::new(grid));
    let ctx = CollisionContext::new(field, ChainParams::new(6), 0.05).unwrap();
    // A bent 6-unit chain (valid shape) and places for it in the clutter.
    let shape = Shape::from_slice(
        6,
        &[0.3, 0.0, 0.3, 0.2, 0.8, -0.1, 0.2, 0.0, -0.5, 0.1, 0.1],
    )
    .unwrap();
    assert!(aerial_chain_core::validity::check_shape(ctx.params(), &shape).is_ok());
    let mut r = Lcg(11);
    let mut configs = Vec::new();
    let mut edges = Vec::new();
    while configs.len() < 64 || edges.len() < 64 {
        let h = [
            1.0 + 18.0 * r.next(),
            1.0 + 18.0 * r.next(),
            0.8 + 3.4 * r.next(),
        ];
        if ctx.check_config(h, &shape).is_err() {
            continue;
        }
        if configs.len() < 64 {
            configs.push(h);
        }
        // A 2 m translation in a random horizontal direction.
        let a = std::f64::consts::TAU * r.next();
        let to = [h[0] + 2.0 * a.cos(), h[1] + 2.0 * a.sin(), h[2]];
        if edges.len() < 64 && ctx.check_translation(h, to, &shape).is_ok() {
            edges.push((h, to));
        }
    }
    let mut g = c.benchmark_group("collision");
    let mut i = 0;
    g.bench_function("check_config_6_units", |b| {
        b.iter(|| {
            i = (i + 1) % configs.len();
            black_box(ctx.check_config(black_box(configs[i]), &shape))
        })
    });
    // Alternating between two shapes defeats the per-thread cache of the last shape's
    // limits/self-collision answer: the full cost of a first check.
    let other = shape.rotated(0.5);
    let both: Vec<[f64; 3]> = configs
        .iter()
        .copied()
        .filter(|h| ctx.check_config(*h, &other).is_ok())
        .collect();
    assert!(both.len() > 8);
    let mut i3 = 0;
    g.bench_function("check_config_6_units_new_shape_each_call", |b| {
        b.iter(|| {
            i3 += 1;
            let s = if i3 % 2 == 0 { &shape } else { &other };
            black_box(ctx.check_config(black_box(both[(i3 / 2) % both.len()]), s))
        })
    });
    let mut i2 = 0;
    g.bench_function("check_placement_6_units", |b| {
        b.iter(|| {
            i2 = (i2 + 1) % configs.len();
            black_box(ctx.check_placement(black_box(configs[i2]), &shape))
        })
    });
    g.bench_function("head_segment_2m", |b| {
        b.iter(|| {
            i2 = (i2 + 1) % edges.len();
            let (a, t) = edges[i2];
            black_box(ctx.is_head_segment_free(black_box(a), t))
        })
    });
    let mut j = 0;
    g.bench_function("check_translation_2m_6_units_clutter", |b| {
        b.iter(|| {
            j = (j + 1) % edges.len();
            let (a, t) = edges[j];
            black_box(ctx.check_translation(black_box(a), t, &shape))
        })
    });
    let bent = shape.rotated(1.0);
    let mut k = 0;
    g.bench_function("check_shape_change_6_units_clutter", |b| {
        b.iter(|| {
            k = (k + 1) % configs.len();
            black_box(ctx.check_shape_change(black_box(configs[k]), &shape, &bent))
        })
    });
    g.finish();
}

/// A room of 16 x 12 x 3 m at 0.1 m (160 x 120 x 30 voxels: floor, ceiling, walls, a
/// row of pillars, a box floating at x = 6.1-6.3 m) and the map of it explored so far:
/// the same for x < 6 m, unknown beyond.
fn explored_room() -> (Grid, Grid) {
    let mut world = Grid::new(0.1, [0, 0, 0], [160, 120, 30], Cell::Free, true).unwrap();
    for (lo, hi) in [
        ([0.0, 0.0, 0.0], [16.0, 12.0, 0.2]),
        ([0.0, 0.0, 2.8], [16.0, 12.0, 3.0]),
        ([0.0, 0.0, 0.0], [0.2, 12.0, 3.0]),
        ([15.8, 0.0, 0.0], [16.0, 12.0, 3.0]),
        ([0.0, 0.0, 0.0], [16.0, 0.2, 3.0]),
        ([0.0, 11.8, 0.0], [16.0, 12.0, 3.0]),
        ([6.1, 5.2, 1.2], [6.3, 5.5, 1.6]),
    ] {
        world.fill_box(lo, hi, Cell::Occupied);
    }
    for k in 0..7 {
        let x = 1.5 + 2.0 * k as f64;
        world.fill_box([x, 2.0, 0.0], [x + 0.4, 2.4, 3.0], Cell::Occupied);
    }
    let mut map = world.clone();
    map.fill_box([6.0, 0.0, 0.0], [16.0, 12.0, 3.0], Cell::Unknown);
    (world, map)
}

/// One simulated depth scan of `world` into `map` from (4, 6, 1.5) m looking along +x
/// (87 x 58 degrees, 2.3 m range): every voxel whose centre is in the frustum and that
/// `map` does not know takes its state in `world` (no occlusion: the frustum's shape
/// and size are what matter here).
fn depth_scan(world: &Grid, map: &Grid) -> Vec<([i32; 3], Cell)> {
    let (s, range) = ([4.0, 6.0, 1.5], 2.3f64);
    let (h, v) = (43.5f64.to_radians().tan(), 29f64.to_radians().tan());
    let mut changes = Vec::new();
    for z in 0..30 {
        for y in 0..120 {
            for x in 0..160 {
                let i = [x, y, z];
                let c = map.voxel_center(i);
                let d = [c.x - s[0], c.y - s[1], c.z - s[2]];
                let inside = d[0] > 0.0
                    && d[1].abs() <= h * d[0]
                    && d[2].abs() <= v * d[0]
                    && d.iter().map(|v| v * v).sum::<f64>() <= range * range;
                if inside && map.cell(i) == Cell::Unknown {
                    changes.push((i, world.cell(i)));
                }
            }
        }
    }
    changes
}

/// The field updated after one depth scan against the field recomputed.
fn bench_update(c: &mut Criterion) {
    let (world, map) = explored_room();
    let changes = depth_scan(&world, &map);
    let occupied = changes.iter().filter(|(_, s)| *s == Cell::Occupied).count();
    let free = changes.len() - occupied;
    assert!((100..1000).contains(&free) && (10..100).contains(&occupied));
    let mut after = map.clone();
    for &(i, s) in &changes {
        after.set(i, s);
    }
    let mut field = DistanceField::new(map);
    let plain = field.memory_bytes();
    field.prepare_updates();
    let mut updated = field.clone();
    let stats = updated.update(&changes).unwrap();
    let fresh = DistanceField::new(after.clone());
    for i in (0..30).flat_map(|z| (0..120).flat_map(move |y| (0..160).map(move |x| [x, y, z]))) {
        let (a, b) = (updated.voxel_clearance(i), fresh.voxel_clearance(i));
        assert_eq!(a.to_bits(), b.to_bits(), "voxel {i:?}");
    }
    eprintln!(
        "field_update: {free} voxels turned free, {occupied} occupied; {stats:?}; \
         memory {plain} B, {} B with the kept passes",
        field.memory_bytes()
    );
    let mut g = c.benchmark_group("field_update");
    g.sample_size(30);
    g.bench_function("one_scan_160x120x30", |b| {
        b.iter_batched_ref(
            || field.clone(),
            |f| black_box(f.update(&changes).unwrap()),
            BatchSize::LargeInput,
        )
    });
    g.bench_function("recompute_160x120x30", |b| {
        b.iter_batched(
            || after.clone(),
            |g| black_box(DistanceField::new(g)),
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

criterion_group!(benches, bench, bench_update);
criterion_main!(benches);
