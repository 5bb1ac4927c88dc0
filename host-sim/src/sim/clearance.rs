//! The exact clearance of the flown chain to a map, with the project's exact checker
//! ([`crate::collision::exact::nearest_obstacle`]: point and segment to voxel-cube
//! distances), for [`super::flight::Obstacles`].

use aerial_chain_core::ChainParams;
use nalgebra::Point3;

use super::dynamics::V3;
use super::flight::Obstacles;
use crate::collision::exact::nearest_obstacle;
use crate::collision::OutOfBounds;
use crate::map::grid::Grid;

/// How far beyond a body's radius obstacles are searched (m): the clearance reported is
/// `min(true clearance, HORIZON)`.
pub const HORIZON: f64 = 0.5;

/// A map and a chain: exact clearance of unit spheres and link capsules.
pub struct MapClearance<'a> {
    grid: &'a Grid,
    unit_radius: f64,
    link_radius: f64,
}

impl<'a> MapClearance<'a> {
    /// Clearance of the chain `params` in `grid` (unknown space as the grid says).
    pub fn new(grid: &'a Grid, params: &ChainParams) -> Self {
        Self {
            grid,
            unit_radius: params.unit_radius as f64,
            link_radius: params.link_radius as f64,
        }
    }
}

impl Obstacles for MapClearance<'_> {
    fn clearance(&self, units: &[V3]) -> (f64, String) {
        let mut best = (HORIZON, String::from("nothing within the search horizon"));
        for (i, p) in units.iter().enumerate() {
            if !self.grid.in_bounds(Point3::from(*p)) {
                let outside = OutOfBounds::unit(i, Point3::from(*p));
                return (-self.unit_radius, outside.to_string());
            }
        }
        let unit_bodies = units
            .iter()
            .enumerate()
            .map(|(i, p)| ("unit", i, p, p, self.unit_radius));
        let link_bodies = units
            .windows(2)
            .enumerate()
            .map(|(k, w)| ("link", k, &w[0], &w[1], self.link_radius));
        for (kind, i, a, b, radius) in unit_bodies.chain(link_bodies) {
            // The body's core is the segment a-b (a point for a unit).
            if let Some(n) = nearest_obstacle(
                self.grid,
                Point3::from(*a),
                Point3::from(*b),
                HORIZON + radius,
            ) {
                let c = n.distance - radius;
                if c < best.0 {
                    let v = n.voxel;
                    best = (
                        c,
                        format!(
                            "{kind} {} near the voxel at ({:.2}, {:.2}, {:.2})",
                            i + 1,
                            v[0],
                            v[1],
                            v[2]
                        ),
                    );
                }
            }
        }
        best
    }

    fn check_spacing(&self) -> f64 {
        // docs/model.md's edge sampling rule: no body point moves more than r_v / 4.
        self.grid.resolution() / 4.0
    }
}
