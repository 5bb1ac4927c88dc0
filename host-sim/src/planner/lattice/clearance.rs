//! Exact clearance of lattice points: the distance field's proven bound where it
//! decides, the distance to the obstacle voxel cubes one by one where it does not.

use super::HeadLattice;
use crate::collision::exact::point_box_distance;
use crate::collision::FK_TOLERANCE;
use crate::map::distance::DistanceField;

/// The exact distance from `p` to the nearest obstacle voxel cube of the field's grid,
/// when it is above `stop` and below `cap`; otherwise some value `<= stop` (the first
/// cube found within `stop`) or `>= cap`. The voxels are visited in rings around the
/// one holding `p`, nearest first, so a blocked point is settled after a few.
pub fn exact_clearance(field: &DistanceField, p: [f64; 3], stop: f64, cap: f64) -> f64 {
    let g = field.grid();
    let r = g.resolution();
    let c0 = g.lattice_index(p);
    let rings = (cap / r).ceil() as i32 + 1;
    let mut best = cap;
    for k in 0..=rings {
        // Every cube of ring k is at least (k - 1) r away.
        if (k - 1) as f64 * r >= best {
            break;
        }
        for dz in -k..=k {
            for dy in -k..=k {
                for dx in -k..=k {
                    if dx.abs().max(dy.abs()).max(dz.abs()) != k {
                        continue;
                    }
                    let i = [c0[0] + dx, c0[1] + dy, c0[2] + dz];
                    if !g.is_obstacle(i) {
                        continue;
                    }
                    let c = g.voxel_center(i);
                    let d = point_box_distance(
                        p,
                        [c[0] - r / 2.0, c[1] - r / 2.0, c[2] - r / 2.0],
                        [c[0] + r / 2.0, c[1] + r / 2.0, c[2] + r / 2.0],
                    );
                    if d < best {
                        best = d;
                        if d <= stop {
                            return d;
                        }
                    }
                }
            }
        }
    }
    best
}

impl HeadLattice {
    /// The clearance at `p` (a proven lower bound from the field where that decides,
    /// the exact distance to the obstacle cubes otherwise) when the sphere of radius
    /// `r_min` is free there and `p` is inside the box; `None` otherwise.
    pub fn point_clearance(&self, field: &DistanceField, p: [f64; 3]) -> Option<f64> {
        if !self.inside(p) {
            return None;
        }
        let c = field.clearance(p);
        if c > self.r_min {
            return Some(c);
        }
        // The field's bound is below the true distance by at most r_v sqrt(3)
        // (map::distance): far below the radius, the exact test cannot pass.
        let r_v = field.grid().resolution();
        if c + r_v * 3f64.sqrt() < self.r_min {
            return None;
        }
        let e = exact_clearance(field, p, self.r_min, self.r_pref + self.h);
        (e > self.r_min).then_some(e)
    }

    /// Whether `p` is inside the map's box (by the FK tolerance).
    pub(super) fn inside(&self, p: [f64; 3]) -> bool {
        (0..3).all(|a| p[a] >= self.lo[a] + FK_TOLERANCE && p[a] <= self.hi[a] - FK_TOLERANCE)
    }

    /// Whether the sphere of radius `r_min` is free at `p` (exact test).
    pub fn is_free(&self, field: &DistanceField, p: [f64; 3]) -> bool {
        self.point_clearance(field, p).is_some()
    }
}
