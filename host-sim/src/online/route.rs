//! The head's route to the goal through the box, unknown space free (optimistic, as
//! FASTER searches): an A* over voxel centres of a distance field, and the proof that
//! no route exists.
//!
//! # Radii
//! A valid configuration keeps the head's sphere grown by the clearance, radius
//! `R = r_u + c`, off every obstacle cube. A voxel centre lies within `sqrt(3)/2 r_v`
//! of any point of its cube, and the field's bound loses at most `sqrt(3)/2 r_v` (its
//! `G(n)` table), so a centre some head position passes through has a bound of at least
//! `R - sqrt(3) r_v`: the **proof radius**. Voxels 26-connected at the proof radius are
//! a superset of where the head can go, so when the search at that radius reaches no
//! voxel near the goal, no plan exists even if every unknown voxel were free (the
//! separation proof's head flood, made on the optimistic map). The **route radius**
//! `R` keeps the route where the head fits at the voxel centres; the search tries it
//! first and falls back to the proof radius.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use nalgebra::Point3;

use crate::map::DistanceField;

/// A route of voxel centres from the head's voxel to a voxel near the goal.
#[derive(Clone, Debug, PartialEq)]
pub struct Route {
    /// Voxel centres, the head's voxel first.
    pub points: Vec<Point3<f64>>,
    /// The radius every point but the first keeps on the field searched (m).
    pub radius: f64,
}

impl Route {
    /// Its length (m).
    pub fn length(&self) -> f64 {
        self.points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
    }

    /// Whether `field` still lets the head through every point after the first.
    pub fn holds(&self, field: &DistanceField) -> bool {
        self.points
            .iter()
            .skip(1)
            .all(|p| field.voxel_clearance(field.grid().lattice_index(*p)) >= self.radius)
    }

    /// The point `ahead` metres along the route from point `from` (the last point
    /// when the route is shorter).
    pub fn point_after(&self, from: usize, ahead: f64) -> Point3<f64> {
        let mut left = ahead;
        for w in self.points[from.min(self.points.len() - 1)..].windows(2) {
            let d = (w[1] - w[0]).norm();
            if d >= left {
                return w[0] + (w[1] - w[0]) * (left / d);
            }
            left -= d;
        }
        *self.points.last().expect("a route has points")
    }
}

/// What a search found.
#[derive(Clone, Debug, PartialEq)]
pub enum Found {
    /// A route at the route radius, or at the proof radius when there is none.
    Route(Route),
    /// No route even at the proof radius: the goal is out of reach. The voxels the
    /// search reached are counted.
    Sealed {
        /// Voxels reached from the head.
        reached: usize,
    },
}

/// The radii of a search (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Radii {
    /// Where the head fits at voxel centres: `r_u + c`.
    pub route: f64,
    /// The proof radius, `r_u + c - sqrt(3) r_v` (see the module docs).
    pub proof: f64,
}

impl Radii {
    /// The radii for a head sphere of `r_u + c` = `grown` on a map of resolution `r_v`.
    pub fn new(grown: f64, r_v: f64) -> Self {
        Self {
            route: grown,
            proof: grown - 3f64.sqrt() * r_v,
        }
    }
}

/// Searches `field` from `from` to within `tol` of `goal`: at the route radius, then
/// at the proof radius.
pub fn search(
    field: &DistanceField,
    from: Point3<f64>,
    goal: Point3<f64>,
    tol: f64,
    radii: Radii,
) -> Found {
    if let Ok(points) = astar(field, from, goal, tol, radii.route) {
        return Found::Route(Route {
            points,
            radius: radii.route,
        });
    }
    match astar(field, from, goal, tol, radii.proof) {
        Ok(points) => Found::Route(Route {
            points,
            radius: radii.proof,
        }),
        Err(reached) => Found::Sealed { reached },
    }
}

/// A* over the 26-connected voxels whose bound is at least `radius` (the start voxel
/// always), Euclidean costs. Goal voxels: centres within `tol` plus half a voxel
/// diagonal of `goal`, so that every head position within `tol` has its voxel among
/// them. `Err` holds the number of voxels reached.
fn astar(
    field: &DistanceField,
    from: Point3<f64>,
    goal: Point3<f64>,
    tol: f64,
    radius: f64,
) -> Result<Vec<Point3<f64>>, usize> {
    let grid = field.grid();
    let dims = grid.dims();
    let r_v = grid.resolution();
    let reach = tol + 3f64.sqrt() / 2.0 * r_v;
    let Some(start) = grid.local(grid.lattice_index(from)) else {
        return Err(0);
    };
    let linear = |l: [usize; 3]| grid.linear(l);
    let lattice = |l: [usize; 3]| {
        let o = grid.origin();
        [0, 1, 2].map(|a| o[a] + l[a] as i32)
    };
    let centre = |l: [usize; 3]| grid.voxel_center(lattice(l));
    let h = |l: [usize; 3]| ((centre(l) - goal).norm() - reach).max(0.0);
    let mut g = std::collections::HashMap::<usize, (f64, usize)>::new();
    let mut heap = BinaryHeap::new();
    let s = linear(start);
    g.insert(s, (0.0, usize::MAX));
    heap.push(Reverse((key(h(start)), s)));
    while let Some(Reverse((_, k))) = heap.pop() {
        let l = [
            k % dims[0],
            (k / dims[0]) % dims[1],
            k / (dims[0] * dims[1]),
        ];
        let gk = g[&k].0;
        if (centre(l) - goal).norm() <= reach {
            return Ok(walk_back(&g, k, |k| {
                centre([
                    k % dims[0],
                    (k / dims[0]) % dims[1],
                    k / (dims[0] * dims[1]),
                ])
            }));
        }
        for d in NEIGHBOURS {
            let Some(m) = step(l, d, dims) else { continue };
            let km = linear(m);
            if field.voxel_clearance(lattice(m)) < radius {
                continue;
            }
            let len = r_v * ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) as f64).sqrt();
            let gm = gk + len;
            if g.get(&km).is_none_or(|&(old, _)| gm < old) {
                g.insert(km, (gm, k));
                heap.push(Reverse((key(gm + h(m)), km)));
            }
        }
    }
    Err(g.len())
}

/// A non-negative cost as an ordered integer (IEEE order of non-negative floats).
fn key(cost: f64) -> u64 {
    cost.max(0.0).to_bits()
}

/// The route ending at voxel `k`, first voxel first.
fn walk_back(
    g: &std::collections::HashMap<usize, (f64, usize)>,
    mut k: usize,
    centre: impl Fn(usize) -> Point3<f64>,
) -> Vec<Point3<f64>> {
    let mut points = vec![centre(k)];
    while let Some(&(_, parent)) = g.get(&k) {
        if parent == usize::MAX {
            break;
        }
        points.push(centre(parent));
        k = parent;
    }
    points.reverse();
    points
}

/// The 26 neighbour offsets.
const NEIGHBOURS: [[i64; 3]; 26] = {
    let mut out = [[0i64; 3]; 26];
    let mut n = 0;
    let mut z = -1;
    while z <= 1 {
        let mut y = -1;
        while y <= 1 {
            let mut x = -1;
            while x <= 1 {
                if x != 0 || y != 0 || z != 0 {
                    out[n] = [x, y, z];
                    n += 1;
                }
                x += 1;
            }
            y += 1;
        }
        z += 1;
    }
    out
};

/// Local voxel `l` moved by `d`, if inside `dims`.
fn step(l: [usize; 3], d: [i64; 3], dims: [usize; 3]) -> Option<[usize; 3]> {
    let mut out = [0usize; 3];
    for a in 0..3 {
        let v = l[a] as i64 + d[a];
        if v < 0 || v >= dims[a] as i64 {
            return None;
        }
        out[a] = v as usize;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::{Cell, Grid};

    /// A 4 x 2 x 2 m box at 0.1 m, free, with a wall at x = 2 m that has a hole of
    /// `hole` m square (none when 0).
    fn walled(hole: f64) -> DistanceField {
        let mut g = Grid::new(0.1, [0, 0, 0], [40, 20, 20], Cell::Free, true).unwrap();
        g.fill_where(Cell::Occupied, |p| {
            let in_hole = (p.y - 1.0).abs() < hole / 2.0 && (p.z - 1.0).abs() < hole / 2.0;
            (p.x - 2.05).abs() < 0.1 && !in_hole
        });
        DistanceField::new(g)
    }

    #[test]
    fn a_route_goes_through_the_hole_and_keeps_its_radius() {
        let field = walled(0.8);
        let radii = Radii::new(0.2, 0.1);
        let from = Point3::new(0.5, 1.0, 1.0);
        let goal = Point3::new(3.5, 1.0, 1.0);
        let Found::Route(route) = search(&field, from, goal, 0.3, radii) else {
            panic!("no route");
        };
        assert_eq!(route.radius, radii.route);
        assert!(route.holds(&field));
        assert!((route.points.last().unwrap() - goal).norm() <= 0.3 + 0.09);
        assert!(
            route.length() >= 2.6 && route.length() < 3.6,
            "{}",
            route.length()
        );
    }

    #[test]
    fn a_sealed_wall_is_proven_sealed_and_a_slit_is_left_to_the_planner() {
        let radii = Radii::new(0.2, 0.1);
        let from = Point3::new(0.5, 1.0, 1.0);
        let goal = Point3::new(3.5, 1.0, 1.0);
        let found = search(&walled(0.0), from, goal, 0.3, radii);
        assert!(
            matches!(found, Found::Sealed { reached } if reached > 1000),
            "{found:?}"
        );
        // A one-voxel slit is too narrow for the head, but the proof radius is
        // conservative by two half diagonals: the route goes through it at that radius
        // and the piece planner, exact, finds no way.
        let Found::Route(r) = search(&walled(0.1), from, goal, 0.3, radii) else {
            panic!("the proof cannot seal a slit");
        };
        assert_eq!(r.radius, radii.proof);
    }

    #[test]
    fn unknown_space_is_free_on_the_optimistic_field() {
        let g = Grid::new(0.1, [0, 0, 0], [40, 20, 20], Cell::Unknown, false).unwrap();
        let field = DistanceField::new(g);
        let found = search(
            &field,
            Point3::new(0.5, 1.0, 1.0),
            Point3::new(3.5, 1.0, 1.0),
            0.3,
            Radii::new(0.2, 0.1),
        );
        assert!(matches!(found, Found::Route(_)));
    }
}
