//! Tests of `linked`: the rule against exact distances, shafts, solvable instances.

use super::*;

const RULE: LinkRule = LinkRule {
    link: 0.5,
    theta_max: std::f64::consts::FRAC_PI_3,
    radius: 0.2,
};

/// Two storeys of `room` m (x, y) by 2 m, joined by a square hatch of side `w`
/// through a floor `depth` thick, at resolution `r`, the rest occupied.
fn storeys(r: f64, w: f64, depth: f64) -> (DistanceField, [f64; 3], [f64; 3]) {
    let room = 3.0;
    let h = 2.0;
    let n = |m: f64| (m / r).round() as usize;
    let dims = [n(room) + 2, n(room) + 2, n(2.0 * h + depth) + 2];
    let mut g = Grid::new(r, [-1, -1, -1], dims, Cell::Occupied, true).unwrap();
    let c = room / 2.0;
    g.fill_where(Cell::Free, |p| {
        let inside = (0.0..room).contains(&p.x) && (0.0..room).contains(&p.y);
        let lower = (0.0..h).contains(&p.z);
        let upper = (h + depth..2.0 * h + depth).contains(&p.z);
        let hatch = (p.x - c).abs() < w / 2.0 && (p.y - c).abs() < w / 2.0;
        inside && (lower || upper || hatch)
    });
    let start = [c, c, h / 2.0];
    let goal = [c, c, h + depth + h / 2.0];
    (DistanceField::new(g), start, goal)
}

#[test]
fn a_shaft_deeper_than_a_tilted_link_can_leave_is_proved_closed() {
    // Within reach of the rule at 0.025-0.087 m (at 0.1 m, a voxel's extent hides
    // the margin of this hatch: 0.45 m against the 0.477 m a link would need).
    for r in [0.025, 0.05, 0.087] {
        let (field, start, goal) = storeys(r, 0.45, 1.5);
        let check = LinkCheck::new(field.grid().resolution(), RULE);
        let flood = LinkFlood::new(&field, &check, None);
        let proof = flood
            .separated(&[start, goal], goal, 0.3, None)
            .unwrap_or_else(|| panic!("no proof at {r} m"));
        assert!(
            proof.stretch.0.z > 2.0 && proof.stretch.1.z < 3.5,
            "{proof:?}"
        );
        assert_eq!(proof.cell_m, r * ((0.2 / (3.0 * r)).floor()).max(1.0));
    }
}

#[test]
fn a_coarse_map_is_cut_finer_around_the_narrowest_point_where_its_voxels_hide_the_margin() {
    // The planner's radius: r_u plus its checks' tolerance. A 0.4 m hatch through a
    // metre of floor; at 0.087 and 0.1 m a voxel is over half that radius.
    let rule = LinkRule {
        radius: 0.1501,
        ..RULE
    };
    for res in [0.025, 0.05, 0.087, 0.1] {
        let sc =
            crate::problem::scenarios::build(&format!("shaft:w=0.4,depth=1,res={res}")).unwrap();
        let field = DistanceField::new(sc.grid.clone());
        let check = LinkCheck::new(res, rule);
        let route: Vec<[f64; 3]> = sc.route.iter().map(|p| [p.x, p.y, p.z]).collect();
        let goal = [sc.goal.x, sc.goal.y, sc.goal.z];
        // The hatch's lower end, where the head route is narrowest.
        let below = [route[1][0], route[1][1], 2.6];
        let coarse = LinkFlood::new(&field, &check, None).separated(&route, goal, 0.3, None);
        let refined =
            LinkFlood::new(&field, &check, Some(below)).separated(&route, goal, 0.3, None);
        assert_eq!(check.scale > 1, res > 0.06, "{res}");
        assert_eq!(coarse.is_some(), res < 0.06, "{res}: {coarse:?}");
        let proof = refined.unwrap_or_else(|| panic!("no proof at {res} m"));
        assert!(
            proof.stretch.0.z > 2.8 && proof.stretch.1.z < 3.4,
            "{proof:?}"
        );
    }
}

#[test]
fn a_hatch_in_a_thin_floor_is_not_closed() {
    // A link at 60 degrees crosses 0.2 m of floor within 0.12 m aside.
    let (field, start, goal) = storeys(0.05, 0.6, 0.2);
    let check = LinkCheck::new(field.grid().resolution(), RULE);
    let flood = LinkFlood::new(&field, &check, None);
    assert!(flood.blocked_stretch(&[start, goal]).is_none());
    assert!(flood.separated(&[start, goal], goal, 0.3, None).is_none());
}

#[test]
fn open_air_holds_a_link_everywhere() {
    let g = Grid::new(0.05, [0, 0, 0], [40, 40, 40], Cell::Free, false).unwrap();
    let field = DistanceField::new(g);
    let check = LinkCheck::new(field.grid().resolution(), RULE);
    let flood = LinkFlood::new(&field, &check, None);
    for i in [[20, 20, 20], [5, 5, 5], [0, 0, 0]] {
        assert!(!flood.blocked(i), "{i:?}");
    }
}

#[test]
fn the_stencil_keeps_within_the_pitch_limit() {
    let r = 0.05;
    let s = stencil(r, &RULE);
    let h = RULE.link * RULE.theta_max.sin();
    assert!(s.iter().all(|k| (k[2].abs() - 1) as f64 * r <= h));
    // Straight up is out of reach, level in every direction is in.
    assert!(!s.contains(&[0, 0, 10]));
    for k in [[10, 0, 0], [-10, 0, 0], [0, 10, 0], [0, -10, 0], [7, 7, 0]] {
        assert!(s.contains(&k), "{k:?}");
    }
    assert_eq!(s[0][2], 0, "level offsets come first");
}

#[test]
fn no_instance_with_a_verified_witness_is_refused() {
    // Passages, tunnels, a door behind a window, a slot, pipes: each has a
    // follow-the-leader witness the exact verifier accepts (their own tests), so
    // the rule must find no cut along their routes.
    let rule = LinkRule {
        radius: 0.15,
        ..RULE
    };
    for name in [
        "passage:w=0.4,angle=45,res=0.1",
        "passage:w=0.45,angle=30,wall=1.2,res=0.025",
        "passage:w=0.5,angle=-45,door=0.6,door_offset=1.5,gap=1",
        "slot:tilt=60,angle=30",
        "pipe:d=0.6,bends=2,radius=0.8",
        "pipe:d=0.6,square=1,bends=1,res=0.087",
        "window",
        "maze",
    ] {
        let sc = crate::problem::scenarios::build(name).unwrap();
        let field = DistanceField::new(sc.grid.clone());
        let route: Vec<[f64; 3]> = sc.route.iter().map(|p| [p.x, p.y, p.z]).collect();
        let check = LinkCheck::new(field.grid().resolution(), rule);
        let flood = LinkFlood::new(&field, &check, None);
        let goal = [sc.goal.x, sc.goal.y, sc.goal.z];
        assert_eq!(flood.separated(&route, goal, 0.3, None), None, "{name}");
    }
}

/// The exact distance from `p` to the obstacle cubes of `g` (and to the space
/// outside it, where unknown space is occupied), by brute force.
fn exact_distance(g: &Grid, p: Point3<f64>) -> f64 {
    let (lo, hi) = g.bounds();
    let r = g.resolution();
    let mut best = f64::INFINITY;
    if g.unknown_is_occupied() {
        for a in 0..3 {
            best = best.min((p[a] - lo[a]).min(hi[a] - p[a]).max(0.0));
        }
    }
    let (o, dims) = (g.origin(), g.dims());
    for z in 0..dims[2] as i32 {
        for y in 0..dims[1] as i32 {
            for x in 0..dims[0] as i32 {
                let i = [o[0] + x, o[1] + y, o[2] + z];
                if g.is_obstacle(i) {
                    let c = g.voxel_center(i);
                    let d: f64 = (0..3)
                        .map(|a| ((p[a] - c[a]).abs() - r / 2.0).max(0.0).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    best = best.min(d);
                }
            }
        }
    }
    best
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]

    /// A voxel the rule closes holds no unit with its link: at points all over it
    /// (corners included) and at every yaw and pitch within the limit (the limit
    /// included), the unit or the unit at the link's other end is within the radius
    /// of an obstacle, measured exactly. The map is cut three times finer around a
    /// drawn point (0.1 m voxels against a 0.12 m radius), as on a coarse scan.
    #[test]
    fn a_closed_voxel_holds_no_unit_with_its_link(
        g in crate::map::random_grids::grids(3..10, |b| if b < 60 { Cell::Occupied } else { Cell::Free }),
        pick in proptest::array::uniform3(0usize..10),
        refine in proptest::array::uniform3(0usize..10),
    ) {
        let rule = LinkRule { link: 0.3, theta_max: std::f64::consts::FRAC_PI_3, radius: 0.12 };
        let field = DistanceField::new(g.clone());
        let check = LinkCheck::new(field.grid().resolution(), rule);
        proptest::prop_assert_eq!(check.scale, 3);
        let dims = g.dims();
        let v = g.index_of_local([0, 1, 2].map(|a| pick[a] % dims[a]));
        let at = g.voxel_center(g.index_of_local([0, 1, 2].map(|a| refine[a] % dims[a])));
        let flood = LinkFlood::new(&field, &check, Some([at.x, at.y, at.z]));
        if flood.blocked(v) {
            let (c, r) = (g.voxel_center(v), g.resolution());
            for k in 0..27 {
                let f = [k % 3, (k / 3) % 3, k / 9].map(|t| (t as f64 - 1.0) * r / 2.0);
                let p = c + nalgebra::Vector3::from(f);
                let own = exact_distance(&g, p);
                if own <= rule.radius {
                    continue;
                }
                for yaw in 0..16 {
                    for pitch in -3..=3 {
                        let (psi, th) = (yaw as f64 * std::f64::consts::TAU / 16.0, pitch as f64 / 3.0 * rule.theta_max);
                        let d = nalgebra::Vector3::new(th.cos() * psi.cos(), th.cos() * psi.sin(), th.sin());
                        let q = p + d * rule.link;
                        proptest::prop_assert!(
                            exact_distance(&g, q) <= rule.radius + 1e-9,
                            "voxel {v:?} closed, but a unit at {p:?} holds a link to {q:?}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn a_map_finer_than_the_rule_allows_is_not_asked() {
    let r = RULE.link / MAX_LINK_VOXELS / 2.0;
    let check = LinkCheck::new(r, RULE);
    assert!(!check.asked);
    assert!(check.closure.stencil.get().is_none(), "no stencil made");
    assert!(LinkCheck::new(0.05, RULE).asked);
}
