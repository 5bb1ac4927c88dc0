//! Exact clearance of lattice points: the distance field's proven bound where it
//! decides, the distance to the obstacle voxel cubes one by one where it does not
//! ([`exact_clearance`](crate::collision::point_clearance::exact_clearance)).

use super::HeadLattice;
use crate::collision::point_clearance::exact_clearance_above;
use crate::collision::FK_TOLERANCE;
use crate::map::distance::DistanceField;

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
        exact_clearance_above(field, p.into(), self.r_min, self.r_pref + self.h)
    }

    /// Whether `p` is inside the map's box (by the FK tolerance).
    pub(super) fn inside(&self, p: [f64; 3]) -> bool {
        (0..3).all(|a| p[a] >= self.lo[a] + FK_TOLERANCE && p[a] <= self.hi[a] - FK_TOLERANCE)
    }

    /// Whether the sphere of radius `r_min` is free at `p` (exact test).
    #[cfg(test)]
    pub fn is_free(&self, field: &DistanceField, p: [f64; 3]) -> bool {
        self.point_clearance(field, p).is_some()
    }
}
