//! What the page of `arc view` draws, computed here so that its script only places
//! points: the obstacle boxes near the chain's path, the chain's unit centres at every
//! waypoint (forward kinematics from the core), their times, and the flown units.

use std::collections::{BTreeMap, HashSet};

use aerial_chain::flying::{self, FlyOptions};
use aerial_chain::map::{Cell, Grid, FACE_NEIGHBOURS};
use aerial_chain::online::SeenOccupied;
use aerial_chain::plan_file::Plan;
use aerial_chain_core::kinematics::positions_into;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The page's data, inlined as JSON (format `arc-view/1`).
#[derive(Serialize)]
pub struct Scene {
    /// Always `arc-view/1`.
    pub format: &'static str,
    /// Title shown on the page.
    pub title: String,
    /// Number of units N.
    pub units: usize,
    /// Unit sphere radius r_u (m).
    pub unit_radius: f64,
    /// Link radius r_l (m).
    pub link_radius: f64,
    /// The obstacles drawn.
    pub boxes: Boxes,
    /// The plan's waypoints.
    pub waypoints: Waypoints,
    /// The goal region, when known.
    pub goal: Option<Goal>,
    /// The flown chain, when a flight was given.
    pub flight: Option<Flown>,
    /// The map as the sensors drew it, when the flight is an exploration's.
    pub seen: Option<Seen>,
}

/// The lattice of boxes of `scale` voxels a side: box index `(i, j, k)` has its centre
/// at `origin + size * (i, j, k)`. Written flat into the box sets below.
#[derive(Serialize)]
pub struct BoxLattice {
    /// Edge of one box (m): the voxel edge times `scale`.
    pub size: f64,
    /// Voxels per box edge (1 unless the map was thinned to stay light).
    pub scale: i32,
    /// Centre of box index `(0, 0, 0)` (m).
    pub origin: [f64; 3],
}

impl BoxLattice {
    /// Boxes of `scale` voxels a side on `grid`'s lattice.
    fn of(grid: &Grid, scale: i32) -> Self {
        let half = (f64::from(scale) - 1.0) * grid.resolution() / 2.0;
        Self {
            size: grid.resolution() * f64::from(scale),
            scale,
            origin: grid.voxel_center([0, 0, 0]).map(|c| c + half).into(),
        }
    }
}

/// The occupied voxels an exploration's sensors saw, in the order they were seen: box
/// `k` (indices `boxes[3k..3k+3]` on the lattice) appears at time `t[k]`.
#[derive(Serialize)]
pub struct Seen {
    /// Where the boxes lie.
    #[serde(flatten)]
    pub lattice: BoxLattice,
    /// Box indices `[i, j, k, ...]`, ordered by `t`.
    pub boxes: Vec<i32>,
    /// When each box was first seen holding an occupied voxel (s).
    pub t: Vec<f64>,
}

/// Obstacle boxes on a lattice.
#[derive(Serialize)]
pub struct Boxes {
    /// Where the boxes lie.
    #[serde(flatten)]
    pub lattice: BoxLattice,
    /// Box indices `[i, j, k, ...]` of boxes holding an occupied voxel.
    pub occupied: Vec<i32>,
    /// Box indices of boxes holding only unknown voxels counted as obstacles.
    pub unknown: Vec<i32>,
}

/// The plan's waypoints, on the time axis of `arc sim` (its default settings).
#[derive(Serialize)]
pub struct Waypoints {
    /// Time each waypoint is reached (s).
    pub t: Vec<f64>,
    /// Time the chain leaves each waypoint for the next (s); the last one's arrival.
    pub leave: Vec<f64>,
    /// The planner's label for each waypoint (`stats.waypoint_sources`), or `""`.
    pub source: Vec<String>,
    /// The colour class of each label (see [`kind_of`]).
    pub kind: Vec<&'static str>,
    /// Unit centres, `[x, y, z]` for every unit of every waypoint, head first.
    pub units: Vec<f64>,
}

/// The goal region: a ball around the goal head position.
#[derive(Serialize)]
pub struct Goal {
    /// Goal head position (m).
    pub center: [f64; 3],
    /// Goal tolerance (m).
    pub radius: f64,
}

/// The flown unit centres.
#[derive(Serialize)]
pub struct Flown {
    /// Sample times (s).
    pub t: Vec<f64>,
    /// Unit centres, `[x, y, z]` for every unit of every sample, head first.
    pub units: Vec<f64>,
}

/// The parts of an `arc sim --out` or `arc explore --out` file (arc-sim/1) the view
/// reads.
#[derive(Deserialize)]
pub struct FlightFile {
    format: String,
    samples: Vec<FlightSample>,
    #[serde(default)]
    explore: Option<ExplorePart>,
}

/// The part of an exploration's record the view reads.
#[derive(Deserialize)]
struct ExplorePart {
    #[serde(default)]
    seen_occupied: Option<SeenOccupied>,
}

#[derive(Deserialize)]
struct FlightSample {
    t: f64,
    units: Vec<FlightBody>,
}

#[derive(Deserialize)]
struct FlightBody {
    p: [f32; 3],
}

/// Most flight samples kept in the page; longer flights keep every k-th.
const MAX_FLIGHT_SAMPLES: usize = 4000;

/// Most pieces one unit's step between waypoints is cut into by [`along`].
const MAX_PIECES: f64 = 1000.0;

/// A length rounded to a millimetre, which keeps the page small.
fn mm(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

/// The colour class of a waypoint label: `library` (LSC:...), `srs` (SRS:...),
/// `rotation`, `follow`, `shrunk`, `sampled`, `translate`, `start` or `other`.
pub fn kind_of(label: &str) -> &'static str {
    match label.split(':').next().unwrap_or("") {
        "start" => "start",
        "translate" => "translate",
        "LSC" => "library",
        "SRS" => "srs",
        "rotation" => "rotation",
        "follow" => "follow",
        "shrunk" => "shrunk",
        "sampled" => "sampled",
        _ => "other",
    }
}

/// The unit centres of every waypoint, and the time each is reached when flown on
/// `grid` as `arc sim` flies it with its default settings (`flying::time`: along the
/// plan's trajectory, the start hold included), times to the millisecond.
pub fn waypoints(plan: &Plan, grid: &Grid) -> Result<Waypoints, String> {
    let n = plan.chain.units as usize;
    let l = plan.chain.link_length;
    let timed = flying::time(plan, grid, &FlyOptions::default())
        .map_err(|e| format!("cannot time the plan: {e}"))?;
    let (t, leave) = timed.waypoint_times(plan);
    let (t, leave) = (
        t.into_iter().map(mm).collect(),
        leave.into_iter().map(mm).collect(),
    );
    let count = plan.waypoints.len();
    let labels = plan.stats.get("waypoint_sources");
    let label = |i: usize| labels.and_then(|l| l.get(i)).and_then(|v| v.as_str());
    let source: Vec<String> = (0..count)
        .map(|i| label(i).unwrap_or("").to_string())
        .collect();
    let kind = source.iter().map(|s| kind_of(s)).collect();
    let mut units = Vec::with_capacity(count * n * 3);
    let mut out = vec![Vector3::<f64>::zeros(); n];
    for w in &plan.waypoints {
        let xi = w.xi();
        positions_into(l, Vector3::from(xi), w.eta(), &mut out);
        units.extend(out.iter().flat_map(|p| [mm(p.x), mm(p.y), mm(p.z)]));
    }
    Ok(Waypoints {
        t,
        leave,
        source,
        kind,
        units,
    })
}

/// The unit centres `units` (`n` units a configuration, `[x, y, z]` each) and points
/// on the straight line between each unit's consecutive centres at most `step` m
/// apart: what the obstacles are drawn near.
pub fn along(units: &[f64], n: usize, step: f64) -> Vec<[f64; 3]> {
    let points: Vec<[f64; 3]> = units.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let mut out = points.clone();
    for (a, b) in points.iter().zip(points.iter().skip(n)) {
        let d = (0..3).map(|k| (b[k] - a[k]).powi(2)).sum::<f64>().sqrt();
        // Capped, so that a plan with absurdly long edges cannot exhaust memory here.
        let pieces = (d / step).ceil().min(MAX_PIECES) as usize;
        for i in 1..pieces {
            let f = i as f64 / pieces as f64;
            out.push([0, 1, 2].map(|k| a[k] + f * (b[k] - a[k])));
        }
    }
    out
}

/// The flown unit centres of `file`, for a chain of `n` units, and the map its
/// sensors drew when it is an exploration's.
pub fn flown(file: FlightFile, n: usize) -> Result<(Flown, Option<SeenOccupied>), String> {
    if file.format != "arc-sim/1" {
        return Err(format!(
            "format = {:?}, expected \"arc-sim/1\" (the file `arc sim --out` writes)",
            file.format
        ));
    }
    if file.samples.is_empty() {
        return Err("samples is empty".into());
    }
    let mut last = f64::NEG_INFINITY;
    for (i, s) in file.samples.iter().enumerate() {
        if !s.t.is_finite() || s.t < last {
            return Err(format!("samples[{i}].t = {} is not a later time", s.t));
        }
        last = s.t;
        if s.units.len() != n {
            return Err(format!(
                "samples[{i}] has {} units, the plan has N = {n}",
                s.units.len()
            ));
        }
        if s.units.iter().any(|u| u.p.iter().any(|v| !v.is_finite())) {
            return Err(format!("samples[{i}] has a position that is not finite"));
        }
    }
    let every = file.samples.len().div_ceil(MAX_FLIGHT_SAMPLES).max(1);
    let kept: Vec<&FlightSample> = file.samples.iter().step_by(every).collect();
    let flown = Flown {
        t: kept.iter().map(|s| mm(s.t)).collect(),
        units: kept
            .iter()
            .flat_map(|s| s.units.iter())
            .flat_map(|u| u.p.map(|v| mm(f64::from(v))))
            .collect(),
    };
    let seen = file.explore.and_then(|e| e.seen_occupied);
    if let Some(s) = &seen {
        if s.voxels.len() != s.t.len() {
            return Err(format!(
                "explore.seen_occupied has {} voxels and {} times",
                s.voxels.len(),
                s.t.len()
            ));
        }
        if let Some(k) = s.t.iter().position(|t| !t.is_finite()) {
            return Err(format!("explore.seen_occupied.t[{k}] is not finite"));
        }
    }
    Ok((flown, seen))
}

/// Which obstacles to draw: those within `near` m of `points`, or all.
pub enum Region<'a> {
    /// Voxels close to these points (m).
    Near(&'a [[f64; 3]], f64),
    /// The whole map.
    Whole,
}

/// The obstacle voxels of `grid` in `region` that touch free space (the hidden inside
/// of a wall is not drawn), merged into boxes of 2, 4, 8... voxels a side until at
/// most `max_boxes` remain.
pub fn boxes(grid: &Grid, region: &Region<'_>, max_boxes: usize) -> Boxes {
    let (lo, hi) = lattice_range(grid, region);
    let near = Near::of(region);
    let mut surface: Vec<([i32; 3], bool)> = Vec::new();
    for k in lo[2]..=hi[2] {
        for j in lo[1]..=hi[1] {
            for i in lo[0]..=hi[0] {
                let v = [i, j, k];
                if grid.is_obstacle(v) && touches_free(grid, v) && near.keeps(grid, v) {
                    surface.push((v, grid.cell(v) == Cell::Occupied));
                }
            }
        }
    }
    let (scale, merged) = merge(&surface, max_boxes, false, |a, b| *a |= b);
    let (mut occupied, mut unknown) = (Vec::new(), Vec::new());
    for (b, occ) in merged {
        if occ { &mut occupied } else { &mut unknown }.extend(b);
    }
    Boxes {
        lattice: BoxLattice::of(grid, scale),
        occupied,
        unknown,
    }
}

/// The seen voxels of `seen` in `region` of `grid` (the map the view draws, of the
/// same resolution), merged as [`boxes`] merges, each box timed by the first of its
/// voxels seen, in the order they were seen.
pub fn seen_boxes(
    grid: &Grid,
    seen: &SeenOccupied,
    region: &Region<'_>,
    max_boxes: usize,
) -> Result<Seen, String> {
    if (seen.resolution - grid.resolution()).abs() > 1e-9 * grid.resolution() {
        return Err(format!(
            "explore.seen_occupied.resolution = {} m, the map's is {} m: view the \
             exploration on the map it flew",
            seen.resolution,
            grid.resolution()
        ));
    }
    let near = Near::of(region);
    let kept: Vec<([i32; 3], f64)> = seen
        .voxels
        .iter()
        .zip(&seen.t)
        .filter(|(v, _)| near.keeps(grid, **v))
        .map(|(v, t)| (*v, *t))
        .collect();
    let (scale, merged) = merge(&kept, max_boxes, f64::INFINITY, |a, b| *a = a.min(b));
    let mut timed: Vec<(f64, [i32; 3])> = merged.into_iter().map(|(b, t)| (t, b)).collect();
    timed.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    Ok(Seen {
        lattice: BoxLattice::of(grid, scale),
        boxes: timed.iter().flat_map(|(_, b)| *b).collect(),
        t: timed.iter().map(|(t, _)| mm(*t)).collect(),
    })
}

/// Voxels `items` merged into boxes of 1, 2, 4... voxels a side until at most
/// `max_boxes` remain: each box's value starts at `init` and folds in its voxels'
/// values with `fold`. Returns the scale and the boxes.
fn merge<T: Copy>(
    items: &[([i32; 3], T)],
    max_boxes: usize,
    init: T,
    fold: impl Fn(&mut T, T),
) -> (i32, BTreeMap<[i32; 3], T>) {
    let mut scale = 1i32;
    loop {
        let mut m: BTreeMap<[i32; 3], T> = BTreeMap::new();
        for &(v, value) in items {
            let b = v.map(|x| x.div_euclid(scale));
            fold(m.entry(b).or_insert(init), value);
        }
        if m.len() <= max_boxes || scale >= 1 << 12 {
            return (scale, m);
        }
        scale *= 2;
    }
}

/// Which voxels a [`Region`] keeps: those whose centres lie in the cubes next to its
/// points, or all.
struct Near(Option<(HashSet<[i64; 3]>, f64)>);

impl Near {
    fn of(region: &Region<'_>) -> Self {
        Near(match region {
            Region::Near(points, d) => Some((buckets(points, *d), *d)),
            Region::Whole => None,
        })
    }

    fn keeps(&self, grid: &Grid, v: [i32; 3]) -> bool {
        match &self.0 {
            Some((set, d)) => set.contains(&bucket(grid.voxel_center(v).into(), *d)),
            None => true,
        }
    }
}

/// Whether a 6-neighbour of voxel `v` inside the grid is not an obstacle.
fn touches_free(grid: &Grid, v: [i32; 3]) -> bool {
    FACE_NEIGHBOURS.iter().any(|s| {
        let w = [v[0] + s[0], v[1] + s[1], v[2] + s[2]];
        grid.local(w).is_some() && !grid.is_obstacle(w)
    })
}

/// The lattice box to scan: the grid, cut to the points' bounding box grown by the
/// distance for [`Region::Near`].
fn lattice_range(grid: &Grid, region: &Region<'_>) -> ([i32; 3], [i32; 3]) {
    let o = grid.origin();
    let d = grid.dims();
    let mut lo = o;
    let mut hi = [0, 1, 2].map(|a| o[a] + d[a] as i32 - 1);
    if let Region::Near(points, near) = region {
        let reach = 2.0 * near;
        for a in 0..3 {
            let min = points.iter().map(|p| p[a]).fold(f64::INFINITY, f64::min);
            let max = points
                .iter()
                .map(|p| p[a])
                .fold(f64::NEG_INFINITY, f64::max);
            let (l, h) = (
                grid.lattice_index([min - reach; 3])[a],
                grid.lattice_index([max + reach; 3])[a],
            );
            lo[a] = lo[a].max(l);
            hi[a] = hi[a].min(h);
        }
    }
    (lo, hi)
}

/// The cube of edge `d` holding `p`.
fn bucket(p: [f64; 3], d: f64) -> [i64; 3] {
    p.map(|v| (v / d).floor() as i64)
}

/// The cubes of edge `d` holding or next to a point: a voxel in one of them is at
/// most about `2 d` from a point.
fn buckets(points: &[[f64; 3]], d: f64) -> HashSet<[i64; 3]> {
    let mut set = HashSet::new();
    for &p in points {
        let b = bucket(p, d);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    set.insert([
                        b[0].saturating_add(dx),
                        b[1].saturating_add(dy),
                        b[2].saturating_add(dz),
                    ]);
                }
            }
        }
    }
    set
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_fall_into_colour_classes() {
        assert_eq!(kind_of("LSC:SE"), "library");
        assert_eq!(kind_of("SRS:12:turned"), "srs");
        assert_eq!(kind_of("follow"), "follow");
        assert_eq!(kind_of("translate"), "translate");
        assert_eq!(kind_of("whatever"), "other");
    }

    #[test]
    fn long_edges_get_points_along_them() {
        // One unit, two waypoints 10 m apart: 9 points in between at 1 m.
        let p = along(&[0.0, 0.0, 0.0, 10.0, 0.0, 0.0], 1, 1.0);
        assert_eq!(p.len(), 11);
        assert!(p.contains(&[5.0, 0.0, 0.0]));
    }
}
