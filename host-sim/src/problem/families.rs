//! Two more parametric families: a forest of trunks and a tilted slot.
//!
//! `forest:KEY=VALUE,...`: a 27 x 10 x 4 m clearing at 0.1 m by default, vertical
//! trunks 0.2-0.6 m across standing on a jittered grid between x = 6 m and x = 22 m;
//! the head flies 20 m from (4, 5, 1.5) to (24, 5, 1.5), starting along +x.
//!
//! | key | default | meaning |
//! |---|---|---|
//! | `spacing` | 1.25 | grid spacing of the trunks (m), 1 to 1.5; each trunk is moved up to a quarter of it either way |
//! | `seed` | 1 | seed of the jitter and the diameters, 0 to 1e9 |
//! | `res` | 0.1 | map resolution (m), 0.05 to 0.1 |
//!
//! `slot:KEY=VALUE,...`: the passage family's room (at 0.05 m by default) split by a
//! 0.2 m wall holding one 0.5 m x 1.5 m slot, its long side tilted off the vertical,
//! approached obliquely.
//!
//! | key | default | meaning |
//! |---|---|---|
//! | `tilt` | 30 | the slot's tilt off the vertical (degrees), 0 to 60 |
//! | `angle` | 30 | approach angle off the wall's normal (degrees), -60 to 60 |
//! | `res` | 0.05 | map resolution (m), 0.025 to 0.1 |
//!
//! A slot's route runs through the slot's centre along the wall's normal (a witness:
//! a chain in a line follows it through the 0.5 m side); a forest's route is the
//! straight line from start to goal, which trunks may cross: the forest has no
//! witness, and the benchmarks count its queries as answered, not as solvable.

use rand::{Rng, SeedableRng};

use super::scenarios::{fill, points, shell_box, Scenario};
use super::spec::{
    Family, Key,
    Values::{Real, Whole},
};
use super::ProblemError;
use crate::map::grid::{Cell, Grid};

/// Parameters of one forest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForestSpec {
    /// Grid spacing of the trunks (m).
    pub spacing: f64,
    /// Seed of the jitter and the diameters.
    pub seed: u64,
    /// Map resolution (m).
    pub res: f64,
}

impl Default for ForestSpec {
    fn default() -> Self {
        Self {
            spacing: 1.25,
            seed: 1,
            res: 0.1,
        }
    }
}

impl Family for ForestSpec {
    const FAMILY: &'static str = "forest";
    const KEYS: &'static [Key<Self>] = &[
        Key::new("spacing", Real(1.0, 1.5), |s| &mut s.spacing),
        Key::new("seed", Whole(0.0, 1e9), |s| &mut s.seed),
        Key::new("res", Real(0.05, 0.1), |s| &mut s.res),
    ];
}

/// The clearing (m): x, y, z.
const FOREST: [f64; 3] = [27.0, 10.0, 4.0];
/// Where trunks stand along x (m).
const TRUNKS_X: (f64, f64) = (6.0, 22.0);
/// Trunk diameters (m).
const TRUNK_D: (f64, f64) = (0.2, 0.6);
/// The flight's height (m).
const FOREST_Z: f64 = 1.5;

impl ForestSpec {
    /// Trunk centres `(x, y)` and diameters, drawn from the seed.
    pub fn trunks(&self) -> Vec<([f64; 2], f64)> {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(self.seed);
        let s = self.spacing;
        let jitter = s / 4.0;
        let mut out = Vec::new();
        let mut x = TRUNKS_X.0;
        while x <= TRUNKS_X.1 + 1e-9 {
            let mut y = s / 2.0;
            while y < FOREST[1] - s / 2.0 + 1e-9 {
                let c = [
                    x + rng.gen_range(-jitter..=jitter),
                    y + rng.gen_range(-jitter..=jitter),
                ];
                out.push((c, rng.gen_range(TRUNK_D.0..=TRUNK_D.1)));
                y += s;
            }
            x += s;
        }
        out
    }

    /// The scenario.
    pub fn build(&self) -> Result<Scenario, ProblemError> {
        self.check()?;
        let mut g = shell_box(FOREST, self.res, 0.2);
        for (c, d) in self.trunks() {
            trunk(&mut g, c, d / 2.0);
        }
        let (start, goal) = ([4.0, 5.0, FOREST_Z], [24.0, 5.0, FOREST_Z]);
        Ok(Scenario {
            name: self.name(),
            description: format!(
                "A 27 x 10 x 4 m clearing at {} m with trunks {}-{} m across on a {} m grid \
                 (jittered by a quarter of it, seed {}); the head flies 20 m through them.",
                self.res, TRUNK_D.0, TRUNK_D.1, self.spacing, self.seed
            ),
            grid: g,
            start: start.into(),
            start_yaw: 0.0,
            goal: goal.into(),
            default_units: 7,
            route: points(&[start, goal]),
        })
    }
}

/// Occupies the voxels whose centres lie in the vertical cylinder of radius `r`
/// around `(c[0], c[1])`, floor to ceiling.
fn trunk(g: &mut Grid, c: [f64; 2], r: f64) {
    let lo = g.lattice_index([c[0] - r, c[1] - r, 0.0]);
    let hi = g.lattice_index([c[0] + r, c[1] + r, FOREST[2]]);
    for z in lo[2]..=hi[2] {
        for y in lo[1]..=hi[1] {
            for x in lo[0]..=hi[0] {
                let p = g.voxel_center([x, y, z]);
                if (p.x - c[0]).powi(2) + (p.y - c[1]).powi(2) <= r * r {
                    g.set([x, y, z], Cell::Occupied);
                }
            }
        }
    }
}

/// Parameters of one tilted slot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlotSpec {
    /// The slot's tilt off the vertical (degrees).
    pub tilt_deg: f64,
    /// Approach angle off the wall's normal (degrees).
    pub angle_deg: f64,
    /// Map resolution (m).
    pub res: f64,
}

impl Default for SlotSpec {
    fn default() -> Self {
        Self {
            tilt_deg: 30.0,
            angle_deg: 30.0,
            res: 0.05,
        }
    }
}

impl Family for SlotSpec {
    const FAMILY: &'static str = "slot";
    const KEYS: &'static [Key<Self>] = &[
        Key::new("tilt", Real(0.0, 60.0), |s| &mut s.tilt_deg),
        Key::new("angle", Real(-60.0, 60.0), |s| &mut s.angle_deg),
        Key::new("res", Real(0.025, 0.1), |s| &mut s.res),
    ];
}

/// The room (m): x, y, z; the wall's near face and thickness (m).
const ROOM: [f64; 3] = [10.5, 10.0, 2.6];
const SLOT_WALL: (f64, f64) = (6.0, 0.2);
/// The slot: width and height (m).
const SLOT: (f64, f64) = (0.5, 1.5);

impl SlotSpec {
    /// The scenario.
    pub fn build(&self) -> Result<Scenario, ProblemError> {
        self.check()?;
        let mut g = shell_box(ROOM, self.res, 0.2);
        let (x0, t) = SLOT_WALL;
        fill(
            &mut g,
            [x0, 0.0, 0.0],
            [x0 + t, ROOM[1], ROOM[2]],
            Cell::Occupied,
        );
        let (yc, zc) = (ROOM[1] / 2.0, ROOM[2] / 2.0);
        let tilt = self.tilt_deg.to_radians();
        let (sin, cos) = tilt.sin_cos();
        let in_slot = |p: nalgebra::Point3<f64>| {
            let (dy, dz) = (p.y - yc, p.z - zc);
            let across = dy * cos + dz * sin;
            let along = -dy * sin + dz * cos;
            p.x > x0 && p.x < x0 + t && across.abs() <= SLOT.0 / 2.0 && along.abs() <= SLOT.1 / 2.0
        };
        let lo = g.lattice_index([x0, yc - SLOT.1, zc - SLOT.1]);
        let hi = g.lattice_index([x0 + t, yc + SLOT.1, zc + SLOT.1]);
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    if in_slot(g.voxel_center([x, y, z])) {
                        g.set([x, y, z], Cell::Free);
                    }
                }
            }
        }
        let a = self.angle_deg.to_radians();
        let turn = [x0 - 1.0, yc, zc];
        let start = [turn[0] - a.cos(), turn[1] - a.sin(), zc];
        let goal = [x0 + t + 1.5, yc, zc];
        Ok(Scenario {
            name: self.name(),
            description: format!(
                "A room at {} m with a {t} m wall holding a {} m x {} m slot tilted {} degrees \
                 off the vertical, approached at {} degrees off its normal.",
                self.res, SLOT.0, SLOT.1, self.tilt_deg, self.angle_deg
            ),
            grid: g,
            start: start.into(),
            start_yaw: a,
            goal: goal.into(),
            default_units: 5,
            route: points(&[start, turn, [x0 + t + 0.8, yc, zc], goal]),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forests_are_drawn_from_their_seed() {
        let f = ForestSpec::parse("spacing=1,seed=7,res=0.1").unwrap();
        assert_eq!(f.trunks(), f.trunks());
        assert_ne!(f.trunks(), ForestSpec { seed: 8, ..f }.trunks());
        let sc = f.build().unwrap();
        // Columns x = 6..22 and rows y = 0.5..9.5, 1 m apart.
        assert_eq!(f.trunks().len(), 17 * 10);
        for (c, d) in f.trunks() {
            assert!((TRUNK_D.0..=TRUNK_D.1).contains(&d));
            assert!(sc.grid.is_obstacle_at([c[0], c[1], 1.0]));
        }
        assert!(!sc.grid.is_obstacle_at(sc.start));
        assert!(!sc.grid.is_obstacle_at(sc.goal));
        assert!((sc.goal - sc.start).norm() == 20.0);
    }

    #[test]
    fn a_slot_is_open_along_its_tilted_long_side_and_closed_across_it() {
        let s = SlotSpec::parse("tilt=45,angle=-20,res=0.05").unwrap();
        let sc = s.build().unwrap();
        let g = &sc.grid;
        let (x, yc, zc) = (6.1, 5.0, 1.3);
        assert!(!g.is_obstacle_at([x, yc, zc]));
        // 0.6 m along the long side, tilted 45 degrees: (-sin, cos) of the tilt.
        let h = 0.6 / 2f64.sqrt();
        assert!(!g.is_obstacle_at([x, yc - h, zc + h]));
        // 0.4 m across it: outside the 0.5 m side.
        let a = 0.4 / 2f64.sqrt();
        assert!(g.is_obstacle_at([x, yc + a, zc + a]));
        assert!(g.is_obstacle_at([x, yc, zc + 1.0]));
    }
}
