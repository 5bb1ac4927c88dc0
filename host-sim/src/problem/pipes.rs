//! Pipes and tunnels: a round or square bore along a horizontal axis, straight, with
//! one 90 degree elbow, or an S-bend (two opposite elbows), in solid rock.
//!
//! `pipe:KEY=VALUE,...`:
//!
//! | key | default | meaning |
//! |---|---|---|
//! | `d` | 0.76 | bore (m), 0.6 to 1.2: the round pipe's diameter, the square one's side |
//! | `square` | 0 | 1: a square bore (a tunnel) instead of a round one |
//! | `bends` | 1 | 0 straight, 1 an elbow (left), 2 an S-bend (left, then right) |
//! | `radius` | 1 | bend radius of the axis (m), 0.8 to 2 |
//! | `res` | 0.05 | map resolution (m), 0.025 to 0.1 |
//!
//! The axis runs 4.2 m straight from the closed end, then through its bends, then
//! 2.5 m straight to the open air beyond the pipe's end. The chain starts on the axis
//! 3.9 m in, looking along it (room behind for N = 8), and the goal is on the axis 1 m
//! before the end. The route is the axis itself: a chain in a line that follows its
//! head along it keeps `d / 2 - r_u` from the wall, and is the witness.

use std::f64::consts::FRAC_PI_2;

use nalgebra::{Point3, Vector2};

use super::scenarios::Scenario;
use super::spec::{
    Family, Key,
    Values::{Flag, Real, Whole},
};
use super::ProblemError;
use crate::map::grid::{Cell, Grid};

/// Parameters of one pipe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PipeSpec {
    /// Bore (m).
    pub d: f64,
    /// A square bore instead of a round one.
    pub square: bool,
    /// 0 straight, 1 an elbow, 2 an S-bend.
    pub bends: u8,
    /// Bend radius of the axis (m).
    pub radius: f64,
    /// Map resolution (m).
    pub res: f64,
}

impl Default for PipeSpec {
    fn default() -> Self {
        Self {
            d: 0.76,
            square: false,
            bends: 1,
            radius: 1.0,
            res: 0.05,
        }
    }
}

impl Family for PipeSpec {
    const FAMILY: &'static str = "pipe";
    const KEYS: &'static [Key<Self>] = &[
        Key::new("d", Real(0.6, 1.2), |s| &mut s.d),
        Key::new("square", Flag, |s| &mut s.square),
        Key::new("bends", Whole(0.0, 2.0), |s| &mut s.bends),
        Key::new("radius", Real(0.8, 2.0), |s| &mut s.radius),
        Key::new("res", Real(0.025, 0.1), |s| &mut s.res),
    ];
}

/// Straight run from the closed end to the first bend, and after the last (m).
const RUN_IN: f64 = 4.2;
const RUN_OUT: f64 = 2.5;
/// Where the head starts along the axis (m).
const START_AT: f64 = 3.9;
/// The axis's height, and the rock around the bore (m).
const AXIS_Z: f64 = 1.2;
const ROCK: f64 = 0.3;

impl PipeSpec {
    /// The axis in the horizontal plane, sampled every `step` m from the closed end
    /// (x = 0) to the open end.
    fn axis(&self, step: f64) -> Vec<Vector2<f64>> {
        let mut pts = vec![Vector2::new(0.0, 0.0)];
        let mut heading = 0.0f64;
        let go = |pts: &mut Vec<Vector2<f64>>, heading: f64, len: f64| {
            let n = (len / step).ceil().max(1.0) as usize;
            let from = *pts.last().expect("non-empty");
            let dir = Vector2::new(heading.cos(), heading.sin());
            pts.extend((1..=n).map(|i| from + dir * (len * i as f64 / n as f64)));
        };
        go(&mut pts, heading, RUN_IN);
        for turn in [1.0, -1.0].iter().take(self.bends as usize) {
            let from = *pts.last().expect("non-empty");
            let left = Vector2::new(-heading.sin(), heading.cos()) * *turn;
            let centre = from + left * self.radius;
            let n = ((FRAC_PI_2 * self.radius) / step).ceil() as usize;
            for i in 1..=n {
                let a = heading + turn * FRAC_PI_2 * i as f64 / n as f64;
                let out = Vector2::new(a.sin(), -a.cos()) * *turn;
                pts.push(centre + out * self.radius);
            }
            heading += turn * FRAC_PI_2;
        }
        go(&mut pts, heading, RUN_OUT);
        pts
    }

    /// The scenario.
    pub fn build(&self) -> Result<Scenario, ProblemError> {
        self.check()?;
        let r = self.res;
        let axis = self.axis(r / 2.0);
        let half = self.d / 2.0;
        let pad = half + ROCK;
        let (mut lo, mut hi) = (axis[0], axis[0]);
        for p in &axis {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        // The box: the bore and its rock, but open where the pipe ends.
        let origin = [lo.x - pad, lo.y - pad, AXIS_Z - pad].map(|v| (v / r).floor() as i32);
        let top = [hi.x + pad, hi.y + pad, AXIS_Z + pad].map(|v| (v / r).ceil() as i32);
        let dims = [0, 1, 2].map(|a| (top[a] - origin[a]).max(1) as usize);
        let mut g = Grid::new(r, origin, dims, Cell::Occupied, true)?;
        for w in axis.windows(2) {
            self.bore(&mut g, w[0], w[1]);
        }
        let along = |s: f64| {
            let k = ((s / (r / 2.0)).round() as usize).min(axis.len() - 1);
            axis[k]
        };
        let start = along(START_AT);
        let length = (axis.len() - 1) as f64 * r / 2.0;
        let route: Vec<Point3<f64>> = axis
            .iter()
            .enumerate()
            .filter(|(k, _)| {
                let s = *k as f64 * r / 2.0;
                s >= START_AT - 1e-9 && s <= length - 1.0 + 1e-9
            })
            .map(|(_, p)| Point3::new(p.x, p.y, AXIS_Z))
            .collect();
        let goal = *route.last().expect("the axis is longer than its ends");
        let next = along(START_AT + 0.1) - start;
        Ok(Scenario {
            name: self.name(),
            description: format!(
                "A {} bore {} m across at {r} m, {} along its axis (bend radius {} m); the head \
                 flies the axis from 3.9 m in to 1 m before the open end.",
                if self.square { "square" } else { "round" },
                self.d,
                ["straight", "one elbow", "an S-bend"][self.bends as usize],
                self.radius
            ),
            grid: g,
            start: Point3::new(start.x, start.y, AXIS_Z),
            start_yaw: next.y.atan2(next.x),
            goal,
            default_units: 6,
            route,
        })
    }

    /// Frees the voxels whose centres lie in the bore around the axis segment `a b`.
    fn bore(&self, g: &mut Grid, a: Vector2<f64>, b: Vector2<f64>) {
        let half = self.d / 2.0;
        let lo = g.lattice_index([a.x.min(b.x) - half, a.y.min(b.y) - half, AXIS_Z - half]);
        let hi = g.lattice_index([a.x.max(b.x) + half, a.y.max(b.y) + half, AXIS_Z + half]);
        let ab = b - a;
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let c = g.voxel_center([x, y, z]);
                    let p = Vector2::new(c.x, c.y);
                    let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                    let h = (p - (a + ab * t)).norm();
                    let v = c.z - AXIS_Z;
                    let inside = match self.square {
                        true => h <= half && v.abs() <= half,
                        false => h * h + v * v <= half * half,
                    };
                    if inside {
                        g.set([x, y, z], Cell::Free);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bore_is_open_on_its_axis_and_closed_beyond_its_wall() {
        for (square, bends) in [(false, 0), (false, 1), (true, 2)] {
            let p = PipeSpec {
                square,
                bends,
                ..PipeSpec::default()
            };
            let sc = p.build().unwrap();
            let g = &sc.grid;
            for q in &sc.route {
                assert!(!g.is_obstacle_at(*q), "{} on the axis at {q}", p.name());
            }
            // Above the axis: open within the bore, rock beyond it.
            let q = sc.route[sc.route.len() / 2];
            assert!(!g.is_obstacle_at([q.x, q.y, q.z + 0.3]));
            assert!(g.is_obstacle_at([q.x, q.y, q.z + 0.45]));
            assert!((sc.start - sc.route[0]).norm() < 1e-9);
        }
        // An elbow turns the axis a quarter: it ends heading +y.
        let sc = PipeSpec::default().build().unwrap();
        let n = sc.route.len();
        let d = sc.route[n - 1] - sc.route[n - 3];
        assert!(d.x.abs() < 1e-9 && d.y > 0.0, "{d}");
    }
}
