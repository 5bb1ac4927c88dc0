//! Built-in environments: the paper's rooms and more, as occupancy grids that can be
//! exported as OctoMap `.bt` files.
//!
//! Every scenario is a closed box at 0.1 m whose every voxel is known: walls, floors
//! and obstacles are OCCUPIED (at least two voxels thick), everything else is explicitly
//! FREE, so treating unknown space as occupied changes nothing inside the box. The
//! default chain is docs/model.md's (`l = 0.5 m`, `r_u = 0.15 m`) with
//! [`Scenario::default_units`] units, and the planner's default clearance 0.05 m.
//!
//! Openings are sized for the planner's CONSERVATIVE checks, not only for the exact
//! test: the distance field's bound can lose up to about `r_v sqrt(3)` (0.17 m) next to
//! obstacles, so a narrow opening leaves about 0.2 m of exact slack around a unit sphere
//! grown by the clearance (0.2 m radius).
//!
//! Each scenario is built so that the straight chain LI at the start yaw CANNOT fly from
//! start to goal (it has to change shape), and so that the chain CAN: the tests build a
//! follow-the-leader plan along [`Scenario::route`] and verify it with the exact checker,
//! and check a "cut" of configurations that every LI path would have to cross.
//!
//! | name | box (m) | default N | the narrow part |
//! |---|---|---|---|
//! | `window` | 8 x 6 x 3 | 5 | a 0.8 m x 0.8 m window in a dividing wall |
//! | `maze` | 10.4 x 6.4 x 2.8 | 5 | three zig-zag walls, 1.2 m gaps, 2.3 m bays |
//! | `silos` | 14 x 10.4 x 5 | 5 | a 0.8 m gap between two silos of radius 2.5 m |
//! | `corridor[:L]` | L x 2.4 x 2.4 | 5 | doors 0.8 m wide every 2 m, alternating sides |

use std::f64::consts::{FRAC_PI_2, PI};

use aerial_chain_core::{ChainParams, Shape};
use nalgebra::Point3;

use super::spec::Family;
use super::ProblemError;
use crate::map::grid::{Cell, Grid};
use crate::map::octomap::{MapFileError, OcTree};

/// Resolution of every built-in scenario (m).
pub const RESOLUTION: f64 = 0.1;
/// Thickness of walls, floors and ceilings (m): two voxels.
pub const WALL: f64 = 0.2;
/// Default corridor length (m).
pub const DEFAULT_CORRIDOR_LENGTH: f64 = 20.0;
/// Allowed corridor lengths (m).
pub const CORRIDOR_LENGTHS: std::ops::RangeInclusive<f64> = 10.0..=100.0;

/// Names of the built-in scenarios, for command-line help.
pub const NAMES: &[&str] = &["window", "maze", "silos", "corridor"];

/// One environment: the map, where the chain starts and where it must go.
#[derive(Clone, Debug)]
pub struct Scenario {
    /// Short name (`window`, `maze`, `silos`, `corridor:L`).
    pub name: String,
    /// What it is and why it is hard, in a sentence or two.
    pub description: String,
    /// The map (unknown space counts as occupied; there is none inside the box).
    pub grid: Grid,
    /// Start position of the head (m).
    pub start: Point3<f64>,
    /// Start yaw (rad): the chain starts as the straight line LI at this yaw, trailing
    /// behind the head along `-(cos yaw, sin yaw, 0)`.
    pub start_yaw: f64,
    /// Goal position of the head (m).
    pub goal: Point3<f64>,
    /// Number of units the scenario is made for.
    pub default_units: u8,
    /// A collision-free route for the head from `start` to `goal` (polyline), with room
    /// for the default chain to follow it; for tests and pictures, not for the planner.
    pub route: Vec<Point3<f64>>,
}

/// `v` as points: the scenarios' data is written as arrays.
pub(crate) fn points(v: &[[f64; 3]]) -> Vec<Point3<f64>> {
    v.iter().map(|&p| p.into()).collect()
}

/// A scenario for the default chain (5 units) whose head starts at the first point of
/// `route` at `start_yaw` and ends at its last; the route runs at the height `z`, so its
/// points are given as `[x, y]`.
pub(super) fn along(
    name: impl Into<String>,
    description: impl Into<String>,
    grid: Grid,
    start_yaw: f64,
    z: f64,
    route: &[[f64; 2]],
) -> Scenario {
    let route: Vec<Point3<f64>> = route.iter().map(|&[x, y]| Point3::new(x, y, z)).collect();
    Scenario {
        name: name.into(),
        description: description.into(),
        grid,
        start: route[0],
        start_yaw,
        goal: route[route.len() - 1],
        default_units: 5,
        route,
    }
}

/// A scenario by name: `window`, `maze`, `silos`, `corridor` (20 m) or `corridor:L`
/// (`L` metres, 10 to 100).
pub fn build(name: &str) -> Result<Scenario, ProblemError> {
    match name {
        "window" => Ok(window()),
        "maze" => Ok(maze()),
        "silos" => Ok(silos()),
        "corridor" => corridor(DEFAULT_CORRIDOR_LENGTH),
        _ => {
            if let Some(large) = super::large::build(name) {
                large
            } else if let Some(spec) = name.strip_prefix("passage:") {
                super::passages::PassageSpec::parse(spec)?.build()
            } else if let Some(spec) = name.strip_prefix("forest:") {
                super::families::ForestSpec::parse(spec)?.build()
            } else if let Some(spec) = name.strip_prefix("slot:") {
                super::families::SlotSpec::parse(spec)?.build()
            } else if let Some(spec) = name.strip_prefix("pipe:") {
                super::pipes::PipeSpec::parse(spec)?.build()
            } else if let Some(spec) = name.strip_prefix("shaft:") {
                super::shafts::ShaftSpec::parse(spec)?.build()
            } else if let Some(len) = name.strip_prefix("corridor:") {
                let l: f64 = len
                    .parse()
                    .map_err(|_| ProblemError::CorridorLengthNotANumber(len.into()))?;
                corridor(l)
            } else {
                Err(ProblemError::UnknownScenario(name.into()))
            }
        }
    }
}

/// A free box `0..size` (snapped to the lattice) with occupied outer shell of [`WALL`].
fn closed_box(size: [f64; 3]) -> Grid {
    shell_box(size, RESOLUTION, WALL)
}

/// A free box `0..size` at resolution `res` (snapped to the lattice) inside an occupied
/// shell `shell` thick.
pub(super) fn shell_box(size: [f64; 3], res: f64, shell: f64) -> Grid {
    let dims = size.map(|s| (s / res).round() as usize);
    let mut g = Grid::new(res, [0; 3], dims, Cell::Occupied, true)
        .expect("scenario sizes are positive and within the grid's limits");
    let eps = 1e-6;
    g.fill_box([shell + eps; 3], size.map(|s| s - shell - eps), Cell::Free);
    g
}

/// Sets the voxels whose centres lie in the box `lo..hi` to `cell` (the box shrunk by a
/// hair so that a box given by its faces on the lattice takes exactly the voxels inside
/// it).
pub(super) fn fill(g: &mut Grid, lo: [f64; 3], hi: [f64; 3], cell: Cell) {
    let e = 1e-6;
    g.fill_box(lo.map(|v| v + e), hi.map(|v| v - e), cell);
}

/// Occupies the voxels whose centres lie in the box `lo..hi` (see [`fill`]).
fn solid(g: &mut Grid, lo: [f64; 3], hi: [f64; 3]) {
    fill(g, lo, hi, Cell::Occupied);
}

/// Frees the voxels whose centres lie in the box `lo..hi` (see [`fill`]).
fn open(g: &mut Grid, lo: [f64; 3], hi: [f64; 3]) {
    fill(g, lo, hi, Cell::Free);
}

/// Env 1 of the paper: two rooms joined by a small window.
pub fn window() -> Scenario {
    let (sx, sy, sz) = (8.0, 6.0, 3.0);
    let mut g = closed_box([sx, sy, sz]);
    // Dividing wall x in [4.0, 4.2], full width and height, with a 0.8 m x 0.8 m window
    // centred at y = 3.0, z = 1.5 (faces on the voxel lattice).
    solid(&mut g, [4.0, 0.0, 0.0], [4.2, sy, sz]);
    open(&mut g, [4.0, 2.6, 1.1], [4.2, 3.4, 1.9]);
    along(
        "window",
        "Env 1: two rooms (3.8 m and 3.6 m deep, 5.6 m wide, 2.6 m high) joined by a \
         0.8 m x 0.8 m window in the 0.2 m dividing wall. The chain starts across the \
         room, perpendicular to the window, and must turn to pass it end first.",
        g,
        FRAC_PI_2,
        1.5,
        &[
            [2.0, 4.5],
            [2.0, 5.0],
            [2.4, 5.3],
            [3.0, 5.2],
            [3.3, 4.6],
            [3.4, 3.6],
            [3.55, 3.1],
            [3.8, 3.0],
            [6.6, 3.0],
        ],
    )
}

/// Env 2 of the paper: a zig-zag room.
pub fn maze() -> Scenario {
    let (sx, sy, sz) = (10.4, 6.4, 2.8);
    let mut g = closed_box([sx, sy, sz]);
    // Three walls across x, alternating gaps (1.2 m) at the top and the bottom of y.
    solid(&mut g, [2.7, 0.0, 0.0], [2.9, 5.0, sz]);
    solid(&mut g, [5.2, 1.4, 0.0], [5.4, sy, sz]);
    solid(&mut g, [7.7, 0.0, 0.0], [7.9, 5.0, sz]);
    let z = 1.4;
    along(
        "maze",
        "Env 2: a 10 m x 6 m room split by three walls into four bays (2.3-2.5 m wide) \
                      joined by 1.2 m gaps at alternating ends, so the way zig-zags. A straight chain \
                      of 5 units (2 m plus its spheres) fits in no bay across and through no gap \
                      sideways: it must bend around every wall end.",
        g,
        FRAC_PI_2,
        z,
        &[
            [1.45, 4.0],
            [1.45, 5.0],
            [1.75, 5.45],
            [2.3, 5.6],
            [3.3, 5.6],
            [3.85, 5.45],
            [4.05, 5.0],
            [4.05, 1.4],
            [4.25, 0.95],
            [4.8, 0.8],
            [5.8, 0.8],
            [6.35, 0.95],
            [6.55, 1.4],
            [6.55, 5.0],
            [6.75, 5.45],
            [7.3, 5.6],
            [8.3, 5.6],
            [8.85, 5.45],
            [9.05, 5.0],
            [9.05, 3.5],
        ],
    )
}

/// The application demo: two silos with a narrow gap between them.
pub fn silos() -> Scenario {
    let (sx, sy, sz) = (14.0, 10.4, 5.0);
    let dims = [sx, sy, sz].map(|v: f64| (v / RESOLUTION).round() as usize);
    let mut g = Grid::new(RESOLUTION, [0; 3], dims, Cell::Free, true).expect("small and positive");
    // Ground.
    solid(&mut g, [0.0, 0.0, 0.0], [sx, sy, WALL]);
    // Two silos of radius 2.5 m reaching the top of the box and past its sides, with a
    // 0.8 m gap between them at y = 5.2.
    let (r, xc, ya, yb) = (2.5, 7.0, 2.3, 8.1);
    g.fill_where(Cell::Occupied, |c| {
        let da = (c[0] - xc).hypot(c[1] - ya);
        let db = (c[0] - xc).hypot(c[1] - yb);
        da <= r || db <= r
    });
    along(
        "silos",
        "The application demo: two silos (radius 2.5 m, 5 m high) stand side by side \
                      across a 14 m x 10.4 m yard, touching its sides, with a 0.8 m gap between \
                      them. There is room to inspect around each silo on both sides; the only way \
                      from west to east is end first through the gap.",
        g,
        FRAC_PI_2,
        2.0,
        &[
            [3.0, 5.2],
            [3.0, 6.0],
            [3.4, 6.6],
            [4.0, 6.7],
            [4.5, 6.3],
            [4.6, 5.6],
            [4.8, 5.25],
            [5.3, 5.2],
            [11.0, 5.2],
        ],
    )
}

/// A long corridor with doors at alternating sides, `length` metres (10 to 100).
pub fn corridor(length: f64) -> Result<Scenario, ProblemError> {
    if !CORRIDOR_LENGTHS.contains(&length) {
        return Err(ProblemError::CorridorLength(length));
    }
    // Whole voxels.
    let sx = (length / RESOLUTION).round() * RESOLUTION;
    let (sy, sz) = (2.4, 2.4);
    let mut g = closed_box([sx, sy, sz]);
    let yc = 0.5 * sy;
    let amp = 0.45;
    let z = 1.2;
    // Doors: 0.2 m walls across the corridor at x0 = FIRST + 2 j, each with an opening
    // 0.8 m wide and 1.8 m high (z 0.2 .. 2.0) centred at yc + amp (j even) or yc - amp.
    // The start leaves room behind the head for a straight chain of 6 units.
    const FIRST: f64 = 4.5;
    let mut doors = Vec::new();
    let mut x0 = FIRST;
    while x0 <= sx - 3.5 + 1e-9 {
        doors.push(x0);
        x0 += 2.0;
    }
    for (j, &x0) in doors.iter().enumerate() {
        let y = if j % 2 == 0 { yc + amp } else { yc - amp };
        solid(&mut g, [x0, 0.0, 0.0], [x0 + 0.2, sy, sz]);
        open(&mut g, [x0, y - 0.4, WALL], [x0 + 0.2, y + 0.4, 2.0]);
    }
    // Route: straight from the start, then a sine through every door's centre
    // (y = yc + amp sin(pi (x - s0) / 2), extreme at each door), then straight on.
    let s0 = FIRST - 0.9;
    let last = doors.last().copied().unwrap_or(s0) + 0.1;
    let end_s = last + 1.0;
    let mut route = vec![[s0 - 0.1, yc], [s0, yc]];
    let mut x = s0 + 0.1;
    while x < end_s - 1e-9 {
        route.push([x, yc + amp * (PI * (x - s0) / 2.0).sin()]);
        x += 0.1;
    }
    route.push([end_s, yc]);
    route.push([sx - 1.0, yc]);
    let name = if length == DEFAULT_CORRIDOR_LENGTH {
        "corridor".into()
    } else {
        format!("corridor:{length}")
    };
    let description = format!(
        "A {sx:.1} m corridor (2 m x 2 m inside) with {} doors 2 m apart, each 0.8 m wide, \
         alternately 0.45 m left and right of the axis. A straight chain of 5 units is longer \
         than the space between two doors, so it cannot shift sideways: it must snake.",
        doors.len()
    );
    Ok(along(name, description, g, 0.0, z, &route))
}

/// The poses of a witness plan ([`Scenario::route_poses`]) and the chain they are for.
#[derive(Clone, Debug, PartialEq)]
pub struct RoutePoses {
    /// The chain's parameters, checked.
    pub params: ChainParams,
    /// Head position and shape of every waypoint, the start first.
    pub poses: Vec<([f64; 3], Shape)>,
}

impl Scenario {
    /// The scenario's map as an OctoMap tree (every voxel in the box known; pruned).
    pub fn octree(&self) -> Result<OcTree, MapFileError> {
        OcTree::from_voxels(self.grid.resolution(), self.grid.known_voxels())
    }

    /// The start shape: the straight line LI at the start yaw.
    pub fn start_shape(&self, units: u8) -> Result<Shape, ProblemError> {
        if !(2..=aerial_chain_core::MAX_UNITS as u8).contains(&units) {
            return Err(ProblemError::OutOfRange {
                name: "units",
                value: units.into(),
                lo: 2.0,
                hi: aerial_chain_core::MAX_UNITS as f64,
            });
        }
        Ok(Shape::line(units, self.start_yaw as f32))
    }

    /// The poses (head position, shape) of a witness plan: the chain follows
    /// [`Self::route`] like a snake (every unit on the route, `l` apart), alternating
    /// translations of the head by at most `step` metres and shape changes that put
    /// the units back on the route; with the chain's parameters, checked. Not optimal
    /// in any way; it shows that the scenario can be flown (`crate::witness` makes it
    /// a plan file).
    pub fn route_poses(&self, params: &ChainParams, step: f64) -> Result<RoutePoses, ProblemError> {
        let params = params.validate().map_err(ProblemError::Chain)?;
        if !(step.is_finite() && step > 0.0) {
            return Err(ProblemError::Step(step));
        }
        let n = params.n();
        let l = params.link_length as f64;
        let (c, s) = (self.start_yaw.cos(), self.start_yaw.sin());
        // The plan file's arrays (docs/model.md "Files").
        let (start, goal): ([f64; 3], [f64; 3]) = (self.start.into(), self.goal.into());
        let given: Vec<[f64; 3]> = self.route.iter().map(|&p| p.into()).collect();
        // The path: the start chain's line (extended by one more link), then the route.
        let mut path: Vec<[f64; 3]> = (1..=n)
            .rev()
            .map(|k| {
                let d = k as f64 * l;
                [start[0] - c * d, start[1] - s * d, start[2]]
            })
            .collect();
        for p in &given {
            if dist(*p, path[path.len() - 1]) > 1e-12 {
                path.push(*p);
            }
        }
        if dist(given[0], start) > 1e-9 || dist(*given.last().unwrap_or(&start), goal) > 1e-9 {
            return Err(ProblemError::RouteEnds);
        }
        let route = Polyline::new(path);
        let s_start = n as f64 * l;
        let s_end = route.length();
        let mut shape = self.start_shape(params.units)?;
        let mut poses = vec![(start, shape)];
        let mut at = s_start;
        loop {
            let head = if at == s_start {
                start
            } else {
                route.point(at)
            };
            let next = route.follow_shape(at, n, l)?;
            if next.max_angle_diff(&shape) > 0.0 {
                shape = next;
                poses.push((head, shape));
            }
            if at >= s_end {
                break;
            }
            at = (at + step).min(s_end);
            let head = if at >= s_end { goal } else { route.point(at) };
            poses.push((head, shape));
        }
        Ok(RoutePoses { params, poses })
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// A polyline parametrised by arc length.
struct Polyline {
    pts: Vec<[f64; 3]>,
    cum: Vec<f64>,
}

impl Polyline {
    fn new(pts: Vec<[f64; 3]>) -> Self {
        let mut cum = vec![0.0];
        for w in pts.windows(2) {
            let last = cum[cum.len() - 1];
            cum.push(last + dist(w[0], w[1]));
        }
        Self { pts, cum }
    }

    fn length(&self) -> f64 {
        self.cum[self.cum.len() - 1]
    }

    fn point(&self, s: f64) -> [f64; 3] {
        let s = s.clamp(0.0, self.length());
        let i = self
            .cum
            .partition_point(|&c| c <= s)
            .clamp(1, self.pts.len() - 1);
        let (a, b) = (self.pts[i - 1], self.pts[i]);
        let seg = self.cum[i] - self.cum[i - 1];
        let t = if seg > 0.0 {
            (s - self.cum[i - 1]) / seg
        } else {
            0.0
        };
        [
            a[0] + t * (b[0] - a[0]),
            a[1] + t * (b[1] - a[1]),
            a[2] + t * (b[2] - a[2]),
        ]
    }

    /// The shape whose units sit on the polyline, `l` apart (chord), head at `s`.
    fn follow_shape(&self, s: f64, n: usize, l: f64) -> Result<Shape, ProblemError> {
        let mut eta = vec![0f32; 2 * n - 1];
        let mut sk = s;
        let mut prev = self.point(s);
        for k in 0..n - 1 {
            // March back until the chord reaches l, then bisect.
            let mut lo = sk;
            let mut hi = sk;
            loop {
                hi -= 0.01;
                if hi < 0.0 {
                    return Err(ProblemError::RouteTooShort);
                }
                if dist(self.point(hi), prev) >= l {
                    break;
                }
                lo = hi;
            }
            // dist(point(lo)) < l <= dist(point(hi)), hi < lo.
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if dist(self.point(mid), prev) < l {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let q = self.point(hi);
            let d = [
                (prev[0] - q[0]) / l,
                (prev[1] - q[1]) / l,
                (prev[2] - q[2]) / l,
            ];
            let theta = (-d[2]).clamp(-1.0, 1.0).asin();
            let psi = d[1].atan2(d[0]);
            eta[1 + 2 * k] = theta as f32;
            eta[2 + 2 * k] = psi as f32;
            if k == 0 {
                eta[0] = psi as f32;
            }
            prev = q;
            sk = hi;
        }
        Shape::from_slice(n as u8, &eta).map_err(ProblemError::Shape)
    }
}

#[cfg(test)]
mod tests;
