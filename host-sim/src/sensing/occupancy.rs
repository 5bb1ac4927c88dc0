//! The map that grows: OctoMap's probabilistic occupancy model, fused scan by scan.
//!
//! Per voxel a log-odds value `L = log(p / (1 - p))`, kept in `f32` and updated with
//! `f32` arithmetic as OctoMap's nodes are. A voxel never updated is unknown; else it is
//! occupied when `L >= log(t / (1 - t))` for the occupancy threshold `t`, free below.
//! Inserting a [`PointCloud`] follows OctoMap's `insertPointCloud(cloud, origin,
//! maxrange)` (not discretised, no bounding box), see [`OccupancyMap::insert`]; the
//! keys of a ray are OctoMap's own ([`super::ray_keys`]). A test compiles a program
//! against OctoMap and holds the free, occupied and unknown voxels equal after the same
//! scans (`host-sim/tests/fusion_octomap.rs`).
//!
//! Storage is sparse, a hash map from lattice index to log-odds: the seen map grows in
//! every direction as the chain flies, from nothing, with no box known in advance; a
//! dense grid would have to be reallocated and copied as it grows, and would hold the
//! unknown space around a long thin flight. Only seen voxels cost memory (about 30 bytes
//! each). [`OccupancyMap::to_grid`] makes the dense [`Grid`] a planner reads.

use std::collections::HashMap;
use std::path::Path;

use nalgebra::Point3;

use super::cloud::PointCloud;
use super::ray_keys::{norm_f32, point_to_index, ray_keys, sub_f32};
use crate::map::{Cell, Grid, GridError, MapFileError, OcTree};

/// Most voxels [`OccupancyMap::mark_free_sphere`] examines (the sphere's bounding cube).
pub const MAX_SPHERE_VOXELS: usize = 10_000_000;

/// OctoMap's sensor model, as probabilities. Defaults are OctoMap's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OccupancyParams {
    /// Probability an end point's voxel is occupied (default 0.7).
    pub prob_hit: f64,
    /// Probability a traversed voxel is occupied (default 0.4).
    pub prob_miss: f64,
    /// Lower clamping bound (default 0.1192).
    pub clamping_min: f64,
    /// Upper clamping bound (default 0.971).
    pub clamping_max: f64,
    /// Occupancy threshold (default 0.5).
    pub occupancy_threshold: f64,
}

impl Default for OccupancyParams {
    fn default() -> Self {
        OccupancyParams {
            prob_hit: 0.7,
            prob_miss: 0.4,
            clamping_min: 0.1192,
            clamping_max: 0.971,
            occupancy_threshold: 0.5,
        }
    }
}

/// OctoMap's `logodds`: `log(p / (1 - p))` in `f64`, rounded to `f32`.
pub fn logodds(p: f64) -> f32 {
    (p / (1.0 - p)).ln() as f32
}

/// The parameters in log-odds, as OctoMap holds them (`f32`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogOddsParams {
    /// Added for a hit.
    pub hit: f32,
    /// Added for a miss.
    pub miss: f32,
    /// Lower clamping bound.
    pub min: f32,
    /// Upper clamping bound.
    pub max: f32,
    /// Occupied at or above this.
    pub threshold: f32,
}

/// Why a map or an insertion is refused: the field, its value and the rule.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{field} = {value}: {rule}")]
pub struct FusionError {
    /// The argument or parameter's name.
    pub field: &'static str,
    /// The value given, as text.
    pub value: String,
    /// What it must be.
    pub rule: &'static str,
}

fn refuse(field: &'static str, value: impl std::fmt::Debug, rule: &'static str) -> FusionError {
    FusionError {
        field,
        value: format!("{value:?}"),
        rule,
    }
}

impl OccupancyParams {
    /// The log-odds form, or the first parameter out of its range.
    pub fn log_odds(&self) -> Result<LogOddsParams, FusionError> {
        let open = |field, v: f64| {
            if v > 0.0 && v < 1.0 {
                Ok(())
            } else {
                Err(refuse(field, v, "must be a probability in (0, 1)"))
            }
        };
        open("prob_hit", self.prob_hit)?;
        open("prob_miss", self.prob_miss)?;
        open("clamping_min", self.clamping_min)?;
        open("clamping_max", self.clamping_max)?;
        open("occupancy_threshold", self.occupancy_threshold)?;
        if self.prob_hit < 0.5 {
            return Err(refuse("prob_hit", self.prob_hit, "must be at least 0.5"));
        }
        if self.prob_miss > 0.5 {
            return Err(refuse("prob_miss", self.prob_miss, "must be at most 0.5"));
        }
        if self.clamping_min >= self.clamping_max {
            return Err(refuse(
                "clamping_min",
                self.clamping_min,
                "must be below clamping_max",
            ));
        }
        Ok(LogOddsParams {
            hit: logodds(self.prob_hit),
            miss: logodds(self.prob_miss),
            min: logodds(self.clamping_min),
            max: logodds(self.clamping_max),
            threshold: logodds(self.occupancy_threshold),
        })
    }
}

/// A voxel whose state an insertion changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct VoxelChange {
    /// Lattice index.
    pub voxel: [i32; 3],
    /// State before.
    pub old: Cell,
    /// State after.
    pub new: Cell,
}

/// A growing occupancy map on OctoMap's lattice (see the module's documentation).
#[derive(Clone, Debug)]
pub struct OccupancyMap {
    resolution: f64,
    params: LogOddsParams,
    voxels: HashMap<[i32; 3], f32>,
}

impl OccupancyMap {
    /// An empty map (all unknown) of voxel edge `resolution` with OctoMap's defaults.
    pub fn new(resolution: f64) -> Result<OccupancyMap, FusionError> {
        OccupancyMap::with_params(resolution, OccupancyParams::default())
    }

    /// An empty map with the given sensor model.
    pub fn with_params(
        resolution: f64,
        params: OccupancyParams,
    ) -> Result<OccupancyMap, FusionError> {
        if !(resolution.is_finite() && resolution > 0.0) {
            return Err(refuse(
                "resolution",
                resolution,
                "must be a positive number of metres",
            ));
        }
        Ok(OccupancyMap {
            resolution,
            params: params.log_odds()?,
            voxels: HashMap::new(),
        })
    }

    /// Voxel edge (m).
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// The sensor model in log-odds.
    pub fn params(&self) -> LogOddsParams {
        self.params
    }

    /// Number of voxels ever updated (free or occupied).
    pub fn known(&self) -> usize {
        self.voxels.len()
    }

    /// The log-odds of lattice voxel `i`, `None` where unknown.
    pub fn log_odds(&self, i: [i32; 3]) -> Option<f32> {
        self.voxels.get(&i).copied()
    }

    /// The state of lattice voxel `i`.
    pub fn state(&self, i: [i32; 3]) -> Cell {
        self.voxels
            .get(&i)
            .map_or(Cell::Unknown, |&l| self.classify(l))
    }

    fn classify(&self, l: f32) -> Cell {
        if l >= self.params.threshold {
            Cell::Occupied
        } else {
            Cell::Free
        }
    }

    /// Every known voxel and its state, in no particular order.
    pub fn voxels(&self) -> impl Iterator<Item = ([i32; 3], Cell)> + '_ {
        self.voxels.iter().map(|(&i, &l)| (i, self.classify(l)))
    }

    /// Fuses one cloud as OctoMap's `insertPointCloud(cloud, origin, max_range)` does,
    /// and returns the voxels whose state changed, sorted by index:
    /// 1. per end point `p`, when `|p - origin| <= max_range` (OctoMap's `f32` norm):
    ///    the keys of the ray from the origin to `p` ([`ray_keys`], end excluded) are
    ///    free, and `p`'s key occupied; else the ray is cut at `origin + d * max_range`
    ///    (`d` the `f32` unit direction) and its keys are free, with no end point;
    /// 2. a key both free and occupied in this cloud is occupied only;
    /// 3. every free key gets one miss and every occupied key one hit:
    ///    `L = clamp(L + update)` in `f32` (a new voxel starts at 0).
    ///
    /// `max_range` must be positive (infinite: no limit, OctoMap's negative maxrange).
    /// Points outside OctoMap's key range contribute nothing, as in OctoMap.
    pub fn insert(
        &mut self,
        cloud: &PointCloud,
        max_range: f64,
    ) -> Result<Vec<VoxelChange>, FusionError> {
        if max_range.is_nan() || max_range <= 0.0 {
            return Err(refuse(
                "max_range",
                max_range,
                "must be a positive number of metres",
            ));
        }
        let (mut free, mut occupied) = self.update_keys(cloud, max_range);
        free.sort_unstable();
        free.dedup();
        occupied.sort_unstable();
        occupied.dedup();
        free.retain(|k| occupied.binary_search(k).is_err());
        let mut changes = Vec::new();
        for (keys, update) in [(&free, self.params.miss), (&occupied, self.params.hit)] {
            for &k in keys {
                if let Some(c) = self.update(unpack(k), update) {
                    changes.push(c);
                }
            }
        }
        changes.sort_unstable_by_key(|c| c.voxel);
        Ok(changes)
    }

    /// The free keys (with repeats) and occupied keys of a cloud, before step 2, packed
    /// ([`pack`]: sorting tens of thousands of keys per scan is the fusion's main cost).
    fn update_keys(&self, cloud: &PointCloud, max_range: f64) -> (Vec<u64>, Vec<u64>) {
        let (mut free, mut occupied) = (Vec::new(), Vec::new());
        let mut ray = Vec::new();
        let o = cloud.origin;
        for &p in &cloud.points {
            let diff = sub_f32(p, o);
            let length = norm_f32(diff);
            if length <= max_range {
                if ray_keys(o, p, self.resolution, &mut ray) {
                    free.extend(ray.iter().map(|&k| pack(k)));
                }
                if let Some(k) = point_to_index(p, 1.0 / self.resolution) {
                    occupied.push(pack(k));
                }
            } else {
                // OctoMap's `normalized()`: divide by the f64 norm rounded to f32.
                let d = if length > 0.0 {
                    diff.map(|c| c / length as f32)
                } else {
                    diff
                };
                let m = max_range as f32;
                let end = [0, 1, 2].map(|a| o[a] + d[a] * m);
                if ray_keys(o, end, self.resolution, &mut ray) {
                    free.extend(ray.iter().map(|&k| pack(k)));
                }
            }
        }
        (free, occupied)
    }

    /// Adds `update` to voxel `k`'s log-odds with clamping; the change of state, if any.
    fn update(&mut self, k: [i32; 3], update: f32) -> Option<VoxelChange> {
        let (min, max) = (self.params.min, self.params.max);
        let old = self.voxels.get(&k).copied();
        let mut l = old.unwrap_or(0.0) + update;
        if l < min {
            l = min;
        } else if l > max {
            l = max;
        }
        self.voxels.insert(k, l);
        self.change(k, old, l)
    }

    fn change(&self, voxel: [i32; 3], old: Option<f32>, new: f32) -> Option<VoxelChange> {
        let old = old.map_or(Cell::Unknown, |l| self.classify(l));
        let new = self.classify(new);
        (old != new).then_some(VoxelChange { voxel, old, new })
    }

    /// Takes voxel `i` as known in `state` (a prior map's voxel): log-odds at the
    /// clamping bound of that state; unknown forgets it. Returns the change, if any.
    pub fn assume(&mut self, i: [i32; 3], state: Cell) -> Option<VoxelChange> {
        let l = match state {
            Cell::Occupied => self.params.max,
            Cell::Free => self.params.min,
            Cell::Unknown => {
                let old = self.voxels.remove(&i)?;
                let old = self.classify(old);
                return Some(VoxelChange {
                    voxel: i,
                    old,
                    new: Cell::Unknown,
                });
            }
        };
        let old = self.voxels.insert(i, l);
        self.change(i, old, l)
    }

    /// Marks as observed free every voxel whose closed cube lies inside the closed ball
    /// of `radius` around `centre` (all eight corners within `radius`): the space a body
    /// of the chain fills, or keeps clear, is free. Each such voxel's log-odds is set to
    /// the lower clamping bound (the most certain free value OctoMap holds), whatever it
    /// was. Returns the changes of state, sorted by index.
    pub fn mark_free_sphere(
        &mut self,
        centre: impl Into<Point3<f64>>,
        radius: f64,
    ) -> Result<Vec<VoxelChange>, FusionError> {
        let c = centre.into();
        if !c.iter().all(|v| v.is_finite()) {
            return Err(refuse("centre", c.coords.as_slice(), "must be finite"));
        }
        check_radius(radius)?;
        let r = self.resolution;
        let lo = c.map(|v| (v - radius) / r).map(f64::floor);
        let hi = c.map(|v| (v + radius) / r).map(f64::ceil);
        let r2 = radius * radius;
        self.mark_free_in([lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z], radius, |m, i| {
            m.farthest_corner_sq(i, &c) <= r2
        })
    }

    /// Marks as observed free every voxel whose closed cube comes within `radius` of the
    /// segment `a b` (a ball when `a == b`): the space a body grown by a clearance keeps
    /// clear where it is known to be valid with that clearance (the chain's start,
    /// docs/model.md "Sensors and the seen map"). Log-odds as in
    /// [`Self::mark_free_sphere`]; returns the changes of state, sorted by index.
    pub fn mark_free_near(
        &mut self,
        a: impl Into<Point3<f64>>,
        b: impl Into<Point3<f64>>,
        radius: f64,
    ) -> Result<Vec<VoxelChange>, FusionError> {
        let (a, b) = (a.into(), b.into());
        if !a.iter().chain(b.iter()).all(|v| v.is_finite()) {
            return Err(refuse("segment", a.coords.as_slice(), "must be finite"));
        }
        check_radius(radius)?;
        let r = self.resolution;
        let lo = [0, 1, 2].map(|k| ((a[k].min(b[k]) - radius) / r).floor());
        let hi = [0, 1, 2].map(|k| ((a[k].max(b[k]) + radius) / r).floor());
        self.mark_free_in(lo, hi, radius, |m, i| {
            m.segment_cube_distance(i, &a, &b) <= radius
        })
    }

    /// Marks free the voxels of the box of lattice indices `lo..=hi` that `inside`
    /// keeps (log-odds at the lower clamping bound); refuses, naming `radius`, a box
    /// of more than [`MAX_SPHERE_VOXELS`] or one that leaves OctoMap's key range.
    fn mark_free_in(
        &mut self,
        lo: [f64; 3],
        hi: [f64; 3],
        radius: f64,
        inside: impl Fn(&Self, [i32; 3]) -> bool,
    ) -> Result<Vec<VoxelChange>, FusionError> {
        let span: f64 = (0..3).map(|k| hi[k] - lo[k] + 1.0).product();
        if span > MAX_SPHERE_VOXELS as f64 || lo.iter().chain(hi.iter()).any(|v| v.abs() > 32768.0)
        {
            return Err(refuse(
                "radius",
                radius,
                "covers too many voxels or leaves OctoMap's key range",
            ));
        }
        let mut changes = Vec::new();
        for z in lo[2] as i32..=hi[2] as i32 {
            for y in lo[1] as i32..=hi[1] as i32 {
                for x in lo[0] as i32..=hi[0] as i32 {
                    let i = [x, y, z];
                    if inside(self, i) {
                        let old = self.voxels.insert(i, self.params.min);
                        changes.extend(self.change(i, old, self.params.min));
                    }
                }
            }
        }
        changes.sort_unstable_by_key(|c| c.voxel);
        Ok(changes)
    }

    /// Distance from the segment `a b` to voxel `i`'s closed cube. The distance from a
    /// point moving along the segment to a convex set is convex in the parameter, so a
    /// golden-section search finds its minimum (to far below a micrometre).
    fn segment_cube_distance(&self, i: [i32; 3], a: &Point3<f64>, b: &Point3<f64>) -> f64 {
        let res = self.resolution;
        let to_cube = |t: f64| -> f64 {
            let p = a + (b - a) * t;
            (0..3)
                .map(|k| {
                    let lo = f64::from(i[k]) * res;
                    let d = (lo - p[k]).max(p[k] - (lo + res)).max(0.0);
                    d * d
                })
                .sum::<f64>()
                .sqrt()
        };
        let g = (5f64.sqrt() - 1.0) / 2.0;
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..60 {
            let (m1, m2) = (hi - g * (hi - lo), lo + g * (hi - lo));
            if to_cube(m1) <= to_cube(m2) {
                hi = m2;
            } else {
                lo = m1;
            }
        }
        to_cube(0.0).min(to_cube(1.0)).min(to_cube((lo + hi) / 2.0))
    }

    /// The squared distance from `c` to the farthest corner of voxel `i`'s cube.
    fn farthest_corner_sq(&self, i: [i32; 3], c: &Point3<f64>) -> f64 {
        (0..3)
            .map(|a| {
                let lo = f64::from(i[a]) * self.resolution;
                let hi = (f64::from(i[a]) + 1.0) * self.resolution;
                let d = (c[a] - lo).abs().max((hi - c[a]).abs());
                d * d
            })
            .sum()
    }

    /// The seen map as a dense grid over the box of its known voxels (unknown inside
    /// the box where never seen), for planning; `unknown_is_occupied` as the planner
    /// assumes. An empty map has no box: [`GridError::Empty`].
    pub fn to_grid(&self, unknown_is_occupied: bool) -> Result<Grid, GridError> {
        let mut lo = [i32::MAX; 3];
        let mut hi = [i32::MIN; 3];
        for i in self.voxels.keys() {
            for a in 0..3 {
                lo[a] = lo[a].min(i[a]);
                hi[a] = hi[a].max(i[a]);
            }
        }
        if self.voxels.is_empty() {
            return Err(GridError::Empty);
        }
        let dims = [0, 1, 2].map(|a| (i64::from(hi[a]) - i64::from(lo[a]) + 1) as usize);
        let mut g = Grid::new(
            self.resolution,
            lo,
            dims,
            Cell::Unknown,
            unknown_is_occupied,
        )?;
        for (i, state) in self.voxels() {
            g.set(i, state);
        }
        Ok(g)
    }

    /// The seen map as an OctoMap tree (max-likelihood, pruned), for writing a `.bt`.
    pub fn to_octree(&self) -> Result<OcTree, MapFileError> {
        OcTree::from_voxels(
            self.resolution,
            self.voxels().map(|(i, s)| (i, s == Cell::Occupied)),
        )
    }

    /// Writes the seen map as a `.bt` file OctoMap reads.
    pub fn write_bt(&self, path: &Path) -> Result<(), MapFileError> {
        self.to_octree()?.write_bt(path)
    }
}

/// A radius of a marked ball or capsule: finite and `>= 0` metres.
fn check_radius(radius: f64) -> Result<(), FusionError> {
    if radius.is_finite() && radius >= 0.0 {
        Ok(())
    } else {
        Err(refuse(
            "radius",
            radius,
            "must be a finite number of metres >= 0",
        ))
    }
}

/// A key (lattice index in OctoMap's range, `-32768..32768` per axis) as one number
/// whose order is the indices' order (x, then y, then z).
fn pack(i: [i32; 3]) -> u64 {
    let k = i.map(|v| u64::from((v + 32768) as u16));
    (k[0] << 32) | (k[1] << 16) | k[2]
}

/// The key [`pack`] packed.
fn unpack(k: u64) -> [i32; 3] {
    [32, 16, 0].map(|shift| i32::from(((k >> shift) & 0xffff) as u16) - 32768)
}

#[cfg(test)]
#[path = "occupancy_tests.rs"]
mod tests;
