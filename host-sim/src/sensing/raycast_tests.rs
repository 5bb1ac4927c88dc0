use super::*;
use crate::map::Cell;
use proptest::prelude::*;

/// The reference: the slab test on every obstacle voxel that the ray can reach: those of
/// the grid and a margin around it, and every voxel within the maximum range of the
/// origin's voxel (with unknown space free, nothing outside the grid is an obstacle).
fn brute_force(grid: &Grid, o: &Point3<f64>, d: &Vector3<f64>, max: f64) -> Option<f64> {
    let (lo, dims) = (grid.origin(), grid.dims());
    let reach = 2 + (max / grid.resolution()).ceil() as i32;
    let start = grid.lattice_index(*o);
    // The grid with a margin, and every voxel within reach of the origin.
    let range = |a: usize| {
        let from = (lo[a] - 2).min(start[a] - reach);
        let to = (lo[a] + dims[a] as i32 + 2).max(start[a] + reach);
        from..=to
    };
    let mut best: Option<f64> = None;
    for z in range(2) {
        for y in range(1) {
            for x in range(0) {
                if !grid.is_obstacle([x, y, z]) {
                    continue;
                }
                if let Some((enter, exit)) = slab(o, d, [x, y, z], grid.resolution()) {
                    let entry = enter.max(0.0);
                    if exit >= 0.0 && entry <= max && best.is_none_or(|b| entry < b) {
                        best = Some(entry);
                    }
                }
            }
        }
    }
    best
}

/// A small random grid: cells from `raw` (0 free, 1 occupied, 2 unknown, mostly free).
fn grid_of(raw: &[u8], origin: [i32; 3], unknown_occ: bool, res: f64) -> Grid {
    let mut g = Grid::new(res, origin, [5, 4, 3], Cell::Free, unknown_occ).unwrap();
    for (k, &v) in raw.iter().enumerate() {
        let i = [
            origin[0] + (k % 5) as i32,
            origin[1] + ((k / 5) % 4) as i32,
            origin[2] + (k / 20) as i32,
        ];
        g.set(
            i,
            match v % 8 {
                0 => Cell::Occupied,
                1 => Cell::Unknown,
                _ => Cell::Free,
            },
        );
    }
    g
}

/// Directions including axis-aligned and diagonal ones (exact zeros and ties).
fn direction() -> impl Strategy<Value = Vector3<f64>> {
    prop_oneof![
        proptest::array::uniform3(-1.0f64..1.0).prop_map(Vector3::from),
        proptest::array::uniform3(-1i8..=1).prop_map(|v| Vector3::new(
            f64::from(v[0]),
            f64::from(v[1]),
            f64::from(v[2])
        )),
    ]
    .prop_filter("non-zero", |d| d.norm() > 1e-3)
    .prop_map(|d| d.normalize())
}

/// Origins anywhere around the grid, or on voxel faces and edges (grazing rays).
fn origin(res: f64) -> impl Strategy<Value = Point3<f64>> {
    prop_oneof![
        proptest::array::uniform3(-0.3f64..0.8).prop_map(Point3::from),
        proptest::array::uniform3(-3i32..8)
            .prop_map(move |v| Point3::from(v.map(|k| f64::from(k) * res))),
        (proptest::array::uniform3(-3i32..8), 0.0f64..1.0).prop_map(move |(v, u)| Point3::new(
            f64::from(v[0]) * res,
            f64::from(v[1]) * res,
            (f64::from(v[2]) + u) * res
        )),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// The walk with its neighbour tests finds the same first entry as testing every cube.
    #[test]
    fn first_entry_matches_brute_force(
        raw in proptest::collection::vec(any::<u8>(), 60),
        origin_idx in proptest::array::uniform3(-2i32..2),
        unknown_occ in any::<bool>(),
        (res, o) in prop_oneof![Just(0.1f64), Just(0.087), Just(0.05)]
            .prop_flat_map(|r| (Just(r), origin(r))),
        d in direction(),
        max in 0.0f64..1.0,
    ) {
        let g = grid_of(&raw, origin_idx, unknown_occ, res);
        let ours = first_obstacle(&g, &o, &d, max);
        let reference = brute_force(&g, &o, &d, max);
        prop_assert_eq!(ours.map(|h| h.0), reference, "origin {} dir {}", o, d);
        if let Some((t, v)) = ours {
            prop_assert!(g.is_obstacle(v));
            let (enter, _) = slab(&o, &d, v, res).unwrap();
            prop_assert_eq!(enter.max(0.0), t);
        }
    }
}

fn room() -> Grid {
    // 1 m cube of free space at 0.1 m, a wall of occupied voxels at x in [0.8, 0.9].
    let mut g = Grid::new(0.1, [0, 0, 0], [10, 10, 10], Cell::Free, true).unwrap();
    g.fill_box([0.85, 0.0, 0.0], [0.85, 1.0, 1.0], Cell::Occupied);
    g
}

#[test]
fn a_wall_returns_at_its_face() {
    let g = room();
    let s = DepthSensor::default();
    let o = Point3::new(0.25, 0.55, 0.55);
    match cast(&g, &s, &o, &Vector3::x()) {
        RayReturn::Hit { distance, voxel } => {
            assert!((distance - 0.55).abs() < 1e-12);
            assert_eq!(voxel, [8, 5, 5]);
        }
        other => panic!("{other:?}"),
    }
    // Too close: 0.05 m from the wall, under the 0.2 m minimum.
    let near = Point3::new(0.75, 0.55, 0.55);
    assert!(matches!(
        cast(&g, &s, &near, &Vector3::x()),
        RayReturn::TooClose {
            voxel: [8, 5, 5],
            ..
        }
    ));
    // Beyond the maximum range: nothing.
    let short = DepthSensor {
        max_range: 0.5,
        ..s.clone()
    };
    assert_eq!(cast(&g, &short, &o, &Vector3::x()), RayReturn::Nothing);
    // Away from the wall, the box's edge: unknown space beyond it is occupied here ...
    match cast(&g, &s, &o, &-Vector3::x()) {
        RayReturn::Hit { distance, voxel } => {
            assert!((distance - 0.25).abs() < 1e-12);
            assert_eq!(voxel, [-1, 5, 5]);
        }
        other => panic!("{other:?}"),
    }
    // ... and free when the grid says so.
    let mut open = g.clone();
    open.set_unknown_is_occupied(false);
    assert_eq!(cast(&open, &s, &o, &-Vector3::x()), RayReturn::Nothing);
}

#[test]
fn a_ray_along_a_face_touches_the_cubes_beside_it() {
    // A ray in the plane y = 0.5 (a face between rows 4 and 5), an occupied voxel in row 4
    // only: the closed cube is touched, though the walk's own voxels are in row 5.
    let mut g = Grid::new(0.1, [0, 0, 0], [10, 10, 10], Cell::Free, false).unwrap();
    g.set([6, 4, 5], Cell::Occupied);
    let o = Point3::new(0.05, 0.5, 0.55);
    let (t, v) = first_obstacle(&g, &o, &Vector3::x(), 5.0).unwrap();
    assert!((t - 0.55).abs() < 1e-12);
    assert_eq!(v, [6, 4, 5]);
}

#[test]
fn a_scan_of_the_room() {
    let g = room();
    let s = DepthSensor::default();
    let scan = scan(&g, &s, &UnitPose::level([0.3, 0.55, 0.55], 0.0));
    assert_eq!(scan.rays.len(), 59 * 39);
    // Looking at the wall, the middle ray returns from it; every ray returns (closed box).
    let mid = scan.rays[19 * 59 + 29];
    assert!(matches!(
        mid.ret,
        RayReturn::Hit {
            voxel: [8, 5, 5],
            ..
        }
    ));
    assert!(scan
        .rays
        .iter()
        .all(|r| !matches!(r.ret, RayReturn::Nothing)));
    let bad = DepthSensor {
        fov_h_deg: 0.0,
        ..s
    };
    assert!(
        super::scan(&g, &bad, &UnitPose::level([0.3, 0.55, 0.55], 0.0))
            .rays
            .is_empty()
    );
}
