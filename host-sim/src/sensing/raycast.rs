//! Exact ray casting into the true map: where a ray first enters an obstacle voxel's
//! closed cube.
//!
//! A voxel is an obstacle as [`Grid::is_obstacle`] says: occupied, or unknown (inside
//! the grid or anywhere outside it) when the grid's `unknown_is_occupied` is set. A
//! truth map read with unknown space occupied therefore returns on the first unknown
//! voxel, and a ray leaving the map's box hits its edge; with unknown space free, rays
//! pass through unknown space.
//!
//! The traversal is Amanatides and Woo's voxel walk; at every voxel it visits, the
//! obstacle voxels among the cubes that contain the point where the walk enters it are
//! tested with the slab test on their closed cubes `[i r_v, (i + 1) r_v]`: the voxel
//! itself and, along each axis where that point lies on (or within `1e-6 r_v` of) a
//! face, the neighbour across it. Between two such points the ray is strictly inside
//! the walk's voxel along every axis it moves in, and along an axis it does not move in
//! it keeps the coordinate it has at every entry point; so every closed cube the ray
//! touches, including those it only grazes along a face, edge or corner (which the walk
//! itself steps past), contains one of those points and is tested. The walk stops once
//! it is past the nearest entry found, or past the maximum range. The result is the
//! smallest slab entry distance over the obstacle cubes, the same number a test of every
//! cube gives (a property test holds it to that).
//!
//! Returns closer than the sensor's minimum range are reported as
//! [`RayReturn::TooClose`], not dropped as no return: a depth camera sees nothing valid
//! there, and fusing such a ray as a miss would clear space through the very obstacle
//! in front of the sensor. The fusion skips such rays.

use nalgebra::{Point3, Vector3};

use super::sensor::{DepthSensor, UnitPose};
use crate::map::Grid;

/// What one ray measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RayReturn {
    /// An obstacle cube entered at `distance` (m along the unit direction), within
    /// `[min_range, max_range]`; `voxel` is the cube's lattice index (of the cubes
    /// entered at that distance, the first the walk met).
    Hit {
        /// Distance from the origin to the entry point (m).
        distance: f64,
        /// The obstacle voxel entered.
        voxel: [i32; 3],
    },
    /// An obstacle entered closer than the minimum range: the sensor measures nothing
    /// valid along this ray.
    TooClose {
        /// Distance from the origin to the entry point (m), below the minimum range.
        distance: f64,
        /// The obstacle voxel entered.
        voxel: [i32; 3],
    },
    /// No obstacle within the maximum range.
    Nothing,
}

/// One ray of a scan: its unit direction in W and what it measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Unit direction in W.
    pub direction: Vector3<f64>,
    /// The measurement.
    pub ret: RayReturn,
}

/// All rays of one sensor at one pose.
#[derive(Clone, Debug, PartialEq)]
pub struct Scan {
    /// The sensor's origin in W.
    pub origin: Point3<f64>,
    /// The sensor's maximum range (m).
    pub max_range: f64,
    /// The rays, in [`DepthSensor::body_rays`]'s order.
    pub rays: Vec<Ray>,
}

/// The entry and exit parameters of the ray `o + t d` through the closed cube of lattice
/// voxel `i` (edge `r`), or `None` when it misses the cube. `t` is not clipped at 0.
/// An axis along which `d` is zero constrains nothing when `o` lies within the slab
/// (faces included) and excludes the cube otherwise.
pub fn slab(o: &Point3<f64>, d: &Vector3<f64>, i: [i32; 3], r: f64) -> Option<(f64, f64)> {
    let (mut enter, mut exit) = (f64::NEG_INFINITY, f64::INFINITY);
    for a in 0..3 {
        let lo = f64::from(i[a]) * r;
        let hi = (f64::from(i[a]) + 1.0) * r;
        if d[a] == 0.0 {
            if o[a] < lo || o[a] > hi {
                return None;
            }
            continue;
        }
        let (t1, t2) = ((lo - o[a]) / d[a], (hi - o[a]) / d[a]);
        enter = enter.max(t1.min(t2));
        exit = exit.min(t1.max(t2));
    }
    (enter <= exit).then_some((enter, exit))
}

/// Where the ray from `o` along unit `d` first enters an obstacle's closed cube within
/// `[0, max_range]`: `(distance, voxel)`, or `None`. An origin inside or on an obstacle
/// cube gives distance 0.
pub fn first_obstacle(
    grid: &Grid,
    o: &Point3<f64>,
    d: &Vector3<f64>,
    max_range: f64,
) -> Option<(f64, [i32; 3])> {
    if max_range.is_nan() || max_range < 0.0 || !o.iter().chain(d.iter()).all(|v| v.is_finite()) {
        return None;
    }
    let mut best: Option<(f64, [i32; 3])> = None;
    let mut walk = Walk::new(grid, o, d, max_range);
    while let Some((voxel, t_in)) = walk.next() {
        // A cube first touched later contains a point where the walk enters later.
        let limit = best.map_or(max_range, |b| b.0);
        if t_in > limit + 1e-9 * (1.0 + limit) {
            break;
        }
        for n in touching(voxel, &(o + d * t_in), grid.resolution()) {
            if !grid.is_obstacle(n) {
                continue;
            }
            let Some((enter, exit)) = slab(o, d, n, grid.resolution()) else {
                continue;
            };
            let entry = enter.max(0.0);
            if exit < 0.0 || entry > max_range {
                continue;
            }
            if best.is_none_or(|b| entry < b.0) {
                best = Some((entry, n));
            }
        }
    }
    best
}

/// How close to a face (as a fraction of the voxel edge) a point counts as on it: far
/// above the rounding of the walk's entry points, so no touched cube is missed (a cube
/// too many is harmless: the slab test decides).
const FACE_TOLERANCE: f64 = 1e-6;

/// Voxel `v` and the neighbours whose closed cubes contain `p` (a point in or on `v`'s
/// cube), by the faces `p` lies on within [`FACE_TOLERANCE`].
fn touching(v: [i32; 3], p: &Point3<f64>, r: f64) -> impl Iterator<Item = [i32; 3]> {
    let eps = FACE_TOLERANCE * r;
    let range = |a: usize| {
        let lo = f64::from(v[a]) * r;
        let hi = (f64::from(v[a]) + 1.0) * r;
        let from = if p[a] <= lo + eps { -1 } else { 0 };
        let to = if p[a] >= hi - eps { 1 } else { 0 };
        (from, to)
    };
    let (x, y, z) = (range(0), range(1), range(2));
    (z.0..=z.1).flat_map(move |k| {
        (y.0..=y.1).flat_map(move |j| {
            (x.0..=x.1).map(move |i| {
                [
                    v[0].saturating_add(i),
                    v[1].saturating_add(j),
                    v[2].saturating_add(k),
                ]
            })
        })
    })
}

/// Amanatides and Woo's walk over the voxels along `o + t d`, `t` in `[t0, t1]`: the
/// ray clipped to the grid's box grown by two voxels when unknown space is free (no
/// obstacle lies beyond), else to `[0, max_range]`.
struct Walk {
    voxel: [i32; 3],
    step: [i32; 3],
    t_max: [f64; 3],
    t_delta: [f64; 3],
    t_in: f64,
    t_end: f64,
    first: bool,
}

impl Walk {
    fn new(grid: &Grid, o: &Point3<f64>, d: &Vector3<f64>, max_range: f64) -> Walk {
        let r = grid.resolution();
        let (mut t0, mut t1) = (0.0f64, max_range);
        if !grid.unknown_is_occupied() {
            let (lo, hi) = (grid.origin(), grid.dims());
            for a in 0..3 {
                let l = (f64::from(lo[a]) - 2.0) * r;
                let h = (f64::from(lo[a]) + hi[a] as f64 + 2.0) * r;
                if d[a] == 0.0 {
                    if o[a] < l || o[a] > h {
                        t1 = f64::NEG_INFINITY;
                    }
                    continue;
                }
                let (a1, a2) = ((l - o[a]) / d[a], (h - o[a]) / d[a]);
                t0 = t0.max(a1.min(a2));
                t1 = t1.min(a1.max(a2));
            }
        }
        let start = o + d * t0;
        let voxel = grid.lattice_index(start);
        let mut w = Walk {
            voxel,
            step: [0; 3],
            t_max: [f64::INFINITY; 3],
            t_delta: [f64::INFINITY; 3],
            t_in: t0,
            t_end: t1,
            first: true,
        };
        for a in 0..3 {
            if d[a] == 0.0 {
                continue;
            }
            w.step[a] = if d[a] > 0.0 { 1 } else { -1 };
            let border = if d[a] > 0.0 {
                (f64::from(voxel[a]) + 1.0) * r
            } else {
                f64::from(voxel[a]) * r
            };
            w.t_max[a] = ((border - o[a]) / d[a]).max(t0);
            w.t_delta[a] = r / d[a].abs();
        }
        w
    }

    /// The next voxel and the parameter where the walk enters it.
    fn next(&mut self) -> Option<([i32; 3], f64)> {
        if self.t_in > self.t_end {
            return None;
        }
        if self.first {
            self.first = false;
            return Some((self.voxel, self.t_in));
        }
        let a = argmin(&self.t_max);
        if !self.t_max[a].is_finite() {
            return None;
        }
        self.t_in = self.t_max[a];
        if self.t_in > self.t_end {
            return None;
        }
        self.voxel[a] = self.voxel[a].saturating_add(self.step[a]);
        self.t_max[a] += self.t_delta[a];
        Some((self.voxel, self.t_in))
    }
}

fn argmin(t: &[f64; 3]) -> usize {
    if t[0] <= t[1] && t[0] <= t[2] {
        0
    } else if t[1] <= t[2] {
        1
    } else {
        2
    }
}

/// What the ray from `o` along unit `d` measures in `grid` with `sensor`'s ranges.
pub fn cast(grid: &Grid, sensor: &DepthSensor, o: &Point3<f64>, d: &Vector3<f64>) -> RayReturn {
    match first_obstacle(grid, o, d, sensor.max_range) {
        Some((distance, voxel)) if distance < sensor.min_range => {
            RayReturn::TooClose { distance, voxel }
        }
        Some((distance, voxel)) => RayReturn::Hit { distance, voxel },
        None => RayReturn::Nothing,
    }
}

/// Every ray of `sensor` on a unit at `pose`, cast into `grid`. Invalid sensor settings
/// give a scan without rays (validate them first: [`DepthSensor::validate`]).
pub fn scan(grid: &Grid, sensor: &DepthSensor, pose: &UnitPose) -> Scan {
    let origin = sensor.origin(pose);
    let rays = sensor
        .world_rays(pose)
        .into_iter()
        .map(|direction| Ray {
            direction,
            ret: cast(grid, sensor, &origin, &direction),
        })
        .collect();
    Scan {
        origin,
        max_range: sensor.max_range,
        rays,
    }
}

#[cfg(test)]
#[path = "raycast_tests.rs"]
mod tests;
