//! Exact distances from the chain's bodies to the map's obstacle cubes, in `f64`, for
//! verification. Independent of the distance field: the obstacle voxels near a body are
//! enumerated from the [`Grid`] and measured one by one.

use aerial_chain_core::kinematics::positions_into;
use aerial_chain_core::validity::{check_shape, Body, Violation};
use aerial_chain_core::{ChainParams, Shape};

use nalgebra::{Point3, Vector3};

use super::OutOfBounds;
use crate::map::blocks::BLOCK;
use crate::map::distance::DistanceField;
use crate::map::grid::{floor, Grid};
use crate::map::row_gaps::FAR;

/// Distance from point `p` to the closed box `lo..hi`.
pub fn point_box_distance(p: Point3<f64>, lo: Point3<f64>, hi: Point3<f64>) -> f64 {
    let mut s = 0.0;
    for a in 0..3 {
        let d = (lo[a] - p[a]).max(p[a] - hi[a]).max(0.0);
        s += d * d;
    }
    s.sqrt()
}

/// Exact distance from the segment `a b` to the closed box `lo..hi`.
///
/// The squared distance along the segment, `f(t) = sum_axis dist(a + t (b - a), slab)^2`,
/// is convex and piecewise quadratic in `t`; its pieces change only where a coordinate
/// crosses a slab face (at most six parameters). On each piece the minimiser of the
/// quadratic is found in closed form and clamped to the piece, so the global minimum is
/// the smallest of these candidates and the piece ends.
pub fn segment_box_distance(
    a: Point3<f64>,
    b: Point3<f64>,
    lo: Point3<f64>,
    hi: Point3<f64>,
) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let mut ts = [0.0f64; 8];
    let mut n = 0;
    ts[n] = 0.0;
    n += 1;
    ts[n] = 1.0;
    n += 1;
    for ax in 0..3 {
        if d[ax] != 0.0 {
            for bound in [lo[ax], hi[ax]] {
                let t = (bound - a[ax]) / d[ax];
                if t > 0.0 && t < 1.0 {
                    ts[n] = t;
                    n += 1;
                }
            }
        }
    }
    let ts = &mut ts[..n];
    ts.sort_by(|x, y| x.total_cmp(y));
    let f = |t: f64| -> f64 {
        let mut s = 0.0;
        for ax in 0..3 {
            let x = a[ax] + t * d[ax];
            let e = (lo[ax] - x).max(x - hi[ax]).max(0.0);
            s += e * e;
        }
        s
    };
    let mut best = f(0.0).min(f(1.0));
    for w in ts.windows(2) {
        let (t0, t1) = (w[0], w[1]);
        if t1 <= t0 {
            continue;
        }
        // Which face is active on this piece: decided at its midpoint.
        let tm = 0.5 * (t0 + t1);
        let (mut num, mut den) = (0.0, 0.0);
        for ax in 0..3 {
            let x = a[ax] + tm * d[ax];
            let c = if x < lo[ax] {
                a[ax] - lo[ax]
            } else if x > hi[ax] {
                a[ax] - hi[ax]
            } else {
                continue;
            };
            num += c * d[ax];
            den += d[ax] * d[ax];
        }
        let t = if den > 0.0 {
            (-num / den).clamp(t0, t1)
        } else {
            t0
        };
        best = best.min(f(t)).min(f(t0)).min(f(t1));
    }
    best.sqrt()
}

/// Distance from point `p` to the segment `a b` (f64).
pub fn point_segment_distance(p: Point3<f64>, a: Point3<f64>, b: Point3<f64>) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let ap = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
    let t = if len2 > 0.0 {
        ((ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q = [
        a[0] + t * ab[0] - p[0],
        a[1] + t * ab[1] - p[1],
        a[2] + t * ab[2] - p[2],
    ];
    (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt()
}

/// The nearest obstacle cube to a body found within a search radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    /// Exact distance from the body's core (centre point or segment) to the cube (m).
    pub distance: f64,
    /// Centre of that obstacle voxel (m).
    pub voxel: Point3<f64>,
}

/// Nearest obstacle cube to the segment `a b` (a point when `a == b`) among those at
/// distance `<= reach`; `None` when every obstacle cube is farther than `reach`.
/// Exact: every voxel intersecting the segment's bounding box grown by `reach` is
/// examined (a voxel outside it is more than `reach` away along some axis), including
/// voxels outside the grid (unknown, obstacles when unknown space counts as occupied),
/// except those in blocks the grid proves free of obstacles
/// ([`Grid::block_may_hold_obstacle`]) and, for a point, those of rows or stretches of
/// rows that lie beyond the limit (`Search::row_span`). Of several cubes at the same
/// distance, the one first in z, then y, then x.
pub fn nearest_obstacle(
    grid: &Grid,
    a: impl Into<Point3<f64>>,
    b: impl Into<Point3<f64>>,
    reach: f64,
) -> Option<Nearest> {
    let (a, b) = (a.into(), b.into());
    if !(reach.is_finite() && reach >= 0.0) || a.iter().chain(b.iter()).any(|v| !v.is_finite()) {
        return None;
    }
    let (lo, hi) = search_box(grid, a, b, reach);
    let origin = grid.origin().map(i64::from);
    let edge = BLOCK as i64;
    // The blocks (grid-local) the box touches, and the voxels of each inside the box.
    let block = |ax: usize, i: i64| (i - origin[ax]).div_euclid(edge);
    let span = |ax: usize, b: i64| {
        let first = origin[ax] + b * edge;
        (first.max(lo[ax]), (first + edge - 1).min(hi[ax]))
    };
    let mut search = Search::new(a, b, reach, grid.resolution());
    for bz in block(2, lo[2])..=block(2, hi[2]) {
        for by in block(1, lo[1])..=block(1, hi[1]) {
            for bx in block(0, lo[0])..=block(0, hi[0]) {
                if !grid.block_may_hold_obstacle([bx, by, bz]) {
                    continue;
                }
                let (zs, ys, xs) = (span(2, bz), span(1, by), span(0, bx));
                for z in zs.0..=zs.1 {
                    for y in ys.0..=ys.1 {
                        let Some((first, last)) = search.row_span(y, z, xs) else {
                            continue;
                        };
                        for x in first..=last {
                            search.visit(grid, [x, y, z]);
                        }
                    }
                }
            }
        }
    }
    search.best.map(|(n, _)| n)
}

/// The lattice indices (inclusive) of the voxels that can lie within `reach` of the
/// segment `a b`, with a voxel to spare on every side.
fn search_box(grid: &Grid, a: Point3<f64>, b: Point3<f64>, reach: f64) -> ([i64; 3], [i64; 3]) {
    let r = grid.resolution();
    let mut lo = [0i64; 3];
    let mut hi = [0i64; 3];
    for ax in 0..3 {
        let (mn, mx) = (a[ax].min(b[ax]) - reach, a[ax].max(b[ax]) + reach);
        // Voxel i spans [i r, (i + 1) r]: it touches [mn, mx] when i r <= mx and (i+1) r >= mn.
        lo[ax] = floor(mn / r) as i64 - 1;
        hi[ax] = floor(mx / r) as i64 + 1;
    }
    (lo, hi)
}

/// The nearest obstacle cube to a point or segment found so far.
struct Search {
    a: Point3<f64>,
    b: Point3<f64>,
    reach: f64,
    half: f64,
    half_diag: f64,
    /// The nearest cube and its index `[z, y, x]`, which breaks ties.
    best: Option<(Nearest, [i64; 3])>,
}

impl Search {
    fn new(a: Point3<f64>, b: Point3<f64>, reach: f64, resolution: f64) -> Self {
        Self {
            a,
            b,
            reach,
            half: 0.5 * resolution,
            half_diag: 0.5 * resolution * 3f64.sqrt(),
            best: None,
        }
    }

    /// The voxels of row `(y, z)` among `xs` that may hold a cube within the search's
    /// limit; `None` when none can. For a point, a row is left out when the point is
    /// farther from the whole row (across it, in y and z) than the limit, and of the
    /// others only the voxels whose own gap along x leaves room are kept; both
    /// compare squares with a relative allowance, so that rounding never leaves out a
    /// cube the voxel-by-voxel test would take. A segment's rows are read whole (a
    /// bound for them costs more than the few voxels a block's row holds).
    fn row_span(&self, y: i64, z: i64, xs: (i64, i64)) -> Option<(i64, i64)> {
        if self.a != self.b {
            return Some(xs);
        }
        let p = self.a;
        let limit = self
            .best
            .map_or(self.reach, |(n, _)| n.distance.min(self.reach));
        let r = 2.0 * self.half;
        let (gy, gz) = (slab_gap(r, p[1], y), slab_gap(r, p[2], z));
        let room = limit * limit * SQUARE_ALLOWANCE - (gy * gy + gz * gz);
        if room < 0.0 {
            return None;
        }
        // Voxels more than `room.sqrt()` from p along x hold no cube within the limit
        // (with a voxel to spare).
        let along = floor(room.sqrt() / r) as i64 + 2;
        let x = floor(p[0] / r) as i64;
        let (first, last) = (xs.0.max(x - along), xs.1.min(x + along));
        (first <= last).then_some((first, last))
    }

    /// Measures lattice voxel `i` when it is an obstacle.
    fn visit(&mut self, grid: &Grid, i: [i64; 3]) {
        let i32s = i.map(|v| v as i32);
        if !grid.is_obstacle(i32s) {
            return;
        }
        let (a, b) = (self.a, self.b);
        let c = grid.voxel_center(i32s);
        // Cheap rejection by the centre's distance.
        let dc = if a == b {
            let e = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt()
        } else {
            point_segment_distance(c, a, b)
        };
        let limit = self
            .best
            .map_or(self.reach, |(n, _)| n.distance.min(self.reach));
        if dc - self.half_diag > limit {
            return;
        }
        let half = Vector3::repeat(self.half);
        let (vlo, vhi) = (c - half, c + half);
        let d = if a == b {
            point_box_distance(a, vlo, vhi)
        } else {
            segment_box_distance(a, b, vlo, vhi)
        };
        let key = [i[2], i[1], i[0]];
        let better = self
            .best
            .is_none_or(|(n, k)| d < n.distance || (d == n.distance && key < k));
        if d <= limit && better {
            self.best = Some((
                Nearest {
                    distance: d,
                    voxel: c,
                },
                key,
            ));
        }
    }
}

/// Unit centres of a chain in `f64` (paper Eq. 2), from a head position and the shape
/// angles `eta` (`2N - 1` numbers; only the link pitches and yaws matter).
pub fn positions_f64(
    link_length: f64,
    head: impl Into<Point3<f64>>,
    eta: &[f64],
) -> Vec<Point3<f64>> {
    let mut p = vec![nalgebra::Vector3::zeros(); eta.len().saturating_sub(1) / 2 + 1];
    positions_into(link_length, head.into().coords, eta, &mut p);
    p.into_iter().map(Point3::from).collect()
}

/// Why a configuration is invalid by the exact test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ExactViolation {
    /// Limits or self-collision (docs/model.md items 1-2), by the core's checks.
    Shape(Violation),
    /// A unit centre lies outside the map's bounding box (item 4).
    OutOfBounds(OutOfBounds),
    /// A body is within its radius of an obstacle cube (item 3).
    Map {
        /// The body.
        body: Body,
        /// Its distance to the cube minus its radius (m, <= 0).
        clearance: f64,
        /// Centre of the obstacle voxel (m).
        voxel: Point3<f64>,
    },
    /// The shape angles are not a valid `eta` for the chain.
    BadShape,
}

impl std::fmt::Display for ExactViolation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ExactViolation::Shape(v) => write!(f, "{v}"),
            ExactViolation::OutOfBounds(o) => write!(f, "{o}"),
            ExactViolation::Map {
                body,
                clearance,
                voxel,
            } => write!(
                f,
                "{body} touches the obstacle voxel at ({:.3}, {:.3}, {:.3}) (clearance {:.4} m)",
                voxel[0], voxel[1], voxel[2], clearance
            ),
            ExactViolation::BadShape => {
                f.write_str("the shape angles are not finite or have the wrong count")
            }
        }
    }
}

/// The exact test's findings for one valid configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExactClearance {
    /// Smallest (distance to an obstacle cube - radius) over all bodies (m), capped at
    /// the search horizon.
    pub clearance: f64,
    /// The body with that clearance.
    pub body: Body,
}

/// Contact within rounding (m): computed distances carry floating-point error of
/// about 1e-15 m near the map, so a body whose computed distance to an obstacle is
/// within this of its radius touches it (docs/model.md, Interpretations). It is far
/// below any clearance a planner keeps, and far above rounding.
pub const CONTACT_TOLERANCE: f64 = 1e-9;

/// The exact validity test of one configuration (docs/model.md "Validity of one
/// configuration"), in `f64` for positions; limits and self-collision use the core's
/// `f32` checks on the shape rounded to `f32`. `horizon` (m) caps how far beyond a
/// body's radius obstacles are searched: the clearance reported is `min(true, horizon)`.
pub fn check_config_exact(
    grid: &Grid,
    params: &ChainParams,
    head: impl Into<Point3<f64>>,
    eta: &[f64],
    horizon: f64,
) -> Result<ExactClearance, ExactViolation> {
    let head = head.into();
    let n = params.n();
    if eta.len() != 2 * n - 1 || eta.iter().chain(head.iter()).any(|v| !v.is_finite()) {
        return Err(ExactViolation::BadShape);
    }
    let mut e32 = [0f32; aerial_chain_core::MAX_SHAPE_DIM];
    for (d, s) in e32.iter_mut().zip(eta) {
        *d = *s as f32;
    }
    let shape =
        Shape::from_slice(params.units, &e32[..eta.len()]).map_err(|_| ExactViolation::BadShape)?;
    check_shape(params, &shape).map_err(ExactViolation::Shape)?;
    let p = positions_f64(params.link_length as f64, head, eta);
    for (i, q) in p.iter().enumerate() {
        if !grid.in_bounds(*q) {
            return Err(ExactViolation::OutOfBounds(OutOfBounds::unit(i, *q)));
        }
    }
    let horizon = horizon.max(0.0);
    let mut best = ExactClearance {
        clearance: horizon,
        body: Body::Unit(0),
    };
    let bodies = (0..n)
        .map(|i| (Body::Unit(i as u8), p[i], p[i], params.unit_radius as f64))
        .chain((0..n - 1).map(|k| {
            (
                Body::Link(k as u8),
                p[k],
                p[k + 1],
                params.link_radius as f64,
            )
        }));
    for (body, a, b, radius) in bodies {
        if let Some(near) = nearest_obstacle(grid, a, b, radius + horizon) {
            let c = near.distance - radius;
            if near.distance <= radius + CONTACT_TOLERANCE {
                return Err(ExactViolation::Map {
                    body,
                    clearance: c,
                    voxel: near.voxel,
                });
            }
            if c < best.clearance {
                best = ExactClearance { clearance: c, body };
            }
        }
    }
    Ok(best)
}

/// The exact distance from `p` to the nearest obstacle voxel cube of the field's grid,
/// when it is above `stop` and below `cap`; otherwise some value `<= stop` (the first
/// cube found within `stop`) or `>= cap`. The grid's rows along x are visited in rings
/// around the one holding `p`, nearest first, so a blocked point is settled after a
/// few; of each row only the obstacle voxels nearest `p` on either side are measured
/// (`crate::map::row_gaps`), one lookup finding them.
pub fn exact_clearance(
    field: &DistanceField,
    p: impl Into<Point3<f64>>,
    stop: f64,
    cap: f64,
) -> f64 {
    let p = p.into();
    let g = field.grid();
    let r = g.resolution();
    let c0 = g.lattice_index(p);
    let rings = (cap / r).ceil() as i32 + 1;
    // Lattice x of every row's first voxel.
    let x0 = g.origin()[0];
    let mut best = cap;
    let slab = |a: usize, i: i32| slab_gap(r, p[a], i.into());
    // The slabs of every row offset in y, then in z: on the stack unless the cap
    // is far beyond what the planner asks for.
    let span = (2 * rings + 1) as usize;
    let mut stack = [0.0f64; 2 * STACK_SPAN];
    let mut heap = Vec::new();
    let slabs: &mut [f64] = if span <= STACK_SPAN {
        &mut stack[..2 * span]
    } else {
        heap.resize(2 * span, 0.0);
        &mut heap
    };
    for d in 0..span {
        let o = d as i32 - rings;
        slabs[d] = slab(1, c0[1] + o);
        slabs[span + d] = slab(2, c0[2] + o);
    }
    let (gy, gz) = slabs.split_at(span);
    for k in 0..=rings {
        // Every cube of a row in ring k is at least (k - 1) r away.
        if (k - 1) as f64 * r >= best {
            break;
        }
        for dz in -k..=k {
            let gz = gz[(dz + rings) as usize];
            // Rows whose square distance exceeds this are as far as `best` or farther
            // by `sqrt` too (the factor covers rounding): no plane or row beyond it
            // holds a cube nearer than `best`. The few within it are read.
            let skip = best * best * SQUARE_ALLOWANCE;
            if gz * gz > skip {
                continue;
            }
            // On the ring's faces in z every y belongs to the ring; inside them only
            // its two y faces do.
            let step = if dz.abs() == k { 1 } else { (2 * k).max(1) };
            for dy in (-k..=k).step_by(step as usize) {
                let gy = gy[(dy + rings) as usize];
                let yz = gy * gy + gz * gz;
                if yz > skip {
                    continue;
                }
                let (y, z) = (c0[1] + dy, c0[2] + dz);
                // The row's raw states and gaps; `None` outside the grid.
                let row = g
                    .row_start(y, z)
                    .map(|start| (g.raw_row_at(start), field.row_gaps_at(start)));
                let candidates = row_candidates(g, c0[0], row);
                if let Candidates::Beyond(gap) = candidates {
                    if gap as f64 * r >= best {
                        continue;
                    }
                }
                let mut measure = |x: i32| {
                    let raw = row.and_then(|(cells, _)| {
                        usize::try_from(x - x0)
                            .ok()
                            .and_then(|i| cells.get(i).copied())
                    });
                    if g.is_obstacle_raw(raw) {
                        let gx = slab(0, x);
                        // As `point_box_distance` sums the squares; a square beyond
                        // `skip` is no nearer by `sqrt` either.
                        let s = gx * gx + gy * gy + gz * gz;
                        if s <= skip {
                            best = best.min(s.sqrt());
                        }
                    }
                    best <= stop
                };
                let found = match candidates {
                    Candidates::Two(a, b) => measure(a) || measure(b),
                    Candidates::Beyond(_) => (-rings..=rings).any(|dx| measure(c0[0] + dx)),
                };
                if found {
                    return best;
                }
            }
        }
    }
    best
}

/// [`exact_clearance`] as the conservative checks use it: `Some(v)` with `v` the value
/// it returns (to the bit: the exact distance from `p` to the nearest obstacle cube,
/// capped at `cap`) when that value is above `stop`, `None` when it is not (some cube
/// lies within `stop`).
///
/// It reads the same rows with the same row gaps and measures a cube as that does, so
/// the minimum is the same to the bit; only the order and the work differ. The rows
/// straight across `p` in y and in z come first, nearest out: beside a flat wall they
/// hold the nearest cube, which settles a blocked point at once and keeps the rows
/// read after them (those left within the nearest distance found) few. Inside the
/// grid a row is one gap read from the whole arrays, and a candidate cube's state is
/// read only when its distance could lower the minimum. What this path does not cover
/// (a point beyond the grid's x extent, a row whose gap saturates within reach, a
/// large cap) goes to [`exact_clearance`] itself.
pub(crate) fn exact_clearance_above(
    field: &DistanceField,
    p: Point3<f64>,
    stop: f64,
    cap: f64,
) -> Option<f64> {
    let slow = || {
        let e = exact_clearance(field, p, stop, cap);
        (e > stop).then_some(e)
    };
    let g = field.grid();
    let r = g.resolution();
    // The rings `exact_clearance` reads: no row beyond them holds a cube within `cap`.
    let rings = (cap / r).ceil();
    // (A point this far out would overflow the lattice's indices: that one reads it.)
    let near = p.iter().all(|v| v.abs() < 1e9);
    if !(cap >= 0.0 && rings < (STACK_SPAN / 2) as f64 && near) {
        return slow();
    }
    let rings = rings as i32 + 1;
    let span = (2 * rings + 1) as usize;
    if span > STACK_SPAN {
        return slow();
    }
    let c0 = g.lattice_index(p);
    let o = g.origin();
    let [nx, ny, nz] = g.dims().map(|d| d as i64);
    let lx = c0[0] as i64 - o[0] as i64;
    if lx < 0 || lx >= nx {
        return slow();
    }
    let mut gy = [0.0f64; STACK_SPAN];
    let mut gz = [0.0f64; STACK_SPAN];
    for d in 0..span {
        let off = d as i64 - rings as i64;
        gy[d] = slab_gap(r, p[1], c0[1] as i64 + off);
        gz[d] = slab_gap(r, p[2], c0[2] as i64 + off);
    }
    let mut rows = Rows {
        cells: g.raw_cells(),
        gaps: field.row_gaps(),
        grid: g,
        dims: [nx, ny, nz],
        lx,
        ly: c0[1] as i64 - o[1] as i64,
        lz: c0[2] as i64 - o[2] as i64,
        x0: o[0] as i64,
        r,
        px: p[0],
        unknown: g.unknown_is_occupied(),
        best: cap,
        skip: cap * cap * SQUARE_ALLOWANCE,
        stop,
    };
    let at = |a: &[f64; STACK_SPAN], d: i32| a[(d + rings) as usize];
    // The rows straight across p, nearest out (`exact_clearance`'s ring bound: every
    // cube of a row `j` away is at least `(j - 1) r` away).
    for j in 0..=rings {
        if (j - 1) as f64 * r >= rows.best {
            break;
        }
        let cross: &[(i32, i32)] = if j == 0 {
            &[(0, 0)]
        } else {
            &[(0, -j), (0, j), (-j, 0), (j, 0)]
        };
        for &(dy, dz) in cross {
            match rows.read(dy, dz, at(&gy, dy), at(&gz, dz)) {
                Row::Go => {}
                Row::Found => return None,
                Row::Slow => return slow(),
            }
        }
    }
    // The others, planes nearest out and rows nearest out in each: the slab gaps grow
    // away from p, so the first row beyond the minimum found ends its side.
    for dz in (1..=rings).flat_map(|k| [-k, k]) {
        let gz = at(&gz, dz);
        if gz * gz > rows.skip {
            continue;
        }
        for side in [-1, 1] {
            for k in 1..=rings {
                let gy = at(&gy, side * k);
                if gy * gy + gz * gz > rows.skip {
                    break;
                }
                match rows.read(side * k, dz, gy, gz) {
                    Row::Go => {}
                    Row::Found => return None,
                    Row::Slow => return slow(),
                }
            }
        }
    }
    (rows.best > stop).then_some(rows.best)
}

/// What reading one row decided.
enum Row {
    /// Nothing within `stop` so far.
    Go,
    /// A cube within `stop`.
    Found,
    /// The row needs [`exact_clearance`]'s own reading (its gap saturates).
    Slow,
}

/// The search of [`exact_clearance_above`]: the arrays it reads and the minimum so far.
struct Rows<'a> {
    cells: &'a [u8],
    gaps: &'a [u8],
    grid: &'a Grid,
    /// The grid's dimensions.
    dims: [i64; 3],
    /// Grid-local indices of the voxel holding p.
    lx: i64,
    ly: i64,
    lz: i64,
    /// The grid's first lattice x.
    x0: i64,
    r: f64,
    px: f64,
    unknown: bool,
    /// The nearest cube so far (at most the cap) and the squares beyond it.
    best: f64,
    skip: f64,
    stop: f64,
}

impl Rows<'_> {
    /// Reads the row `dy`, `dz` from p's, whose slab gaps are `gy`, `gz`: its nearest
    /// obstacle cubes either way along x, each measured as `exact_clearance` does.
    #[inline(always)]
    fn read(&mut self, dy: i32, dz: i32, gy: f64, gz: f64) -> Row {
        if gy * gy + gz * gz > self.skip {
            return Row::Go;
        }
        let [nx, ny, nz] = self.dims;
        let (y, z) = (self.ly + dy as i64, self.lz + dz as i64);
        if y < 0 || y >= ny || z < 0 || z >= nz {
            // Beyond the grid every voxel is unknown: the one across from p is the
            // row's nearest obstacle when unknown space is one.
            return match self.unknown {
                true => self.cube(self.lx, None, gy, gz),
                false => Row::Go,
            };
        }
        let start = ((z * ny + y) * nx) as usize;
        let n = self.gaps[start + self.lx as usize];
        if n == FAR {
            // The row holds no obstacle within `FAR - 1` voxels along x.
            return match (FAR - 1) as f64 * self.r >= self.best {
                true => Row::Go,
                false => Row::Slow,
            };
        }
        // Both of the row's candidates lie `n` voxels from p's along x, so at least
        // `(n - 1) r` away along x (less a relative allowance far above the rounding of
        // `slab_gap`); a square from that bound is no larger than either cube's (each
        // step of the sum is monotone), so a row beyond the minimum by it is left
        // without measuring its cubes or reading their states.
        let near = (n.max(1) - 1) as f64 * self.r * (1.0 - 1e-12);
        if near * near + gy * gy + gz * gz > self.skip {
            return Row::Go;
        }
        let n = n as i64;
        for x in [self.lx - n, self.lx + n] {
            let raw = (0..nx).contains(&x).then(|| self.cells[start + x as usize]);
            if let Row::Found = self.cube(x, Some(raw), gy, gz) {
                return Row::Found;
            }
        }
        Row::Go
    }

    /// Measures the voxel at grid-local `x` of a row (`raw`: `None` for a row beyond
    /// the grid, else the voxel's raw state, `None` beyond the row's ends) when its
    /// square distance could lower the minimum and it is an obstacle.
    #[inline]
    fn cube(&mut self, x: i64, raw: Option<Option<u8>>, gy: f64, gz: f64) -> Row {
        let gx = slab_gap(self.r, self.px, self.x0 + x);
        // As `exact_clearance` sums the squares.
        let s = gx * gx + gy * gy + gz * gz;
        if s <= self.skip && self.grid.is_obstacle_raw(raw.flatten()) {
            self.best = self.best.min(s.sqrt());
            self.skip = self.best * self.best * SQUARE_ALLOWANCE;
            if self.best <= self.stop {
                return Row::Found;
            }
        }
        Row::Go
    }
}

/// How far the coordinate `v` lies from the slab of voxels `i` (lattice index,
/// resolution `r`) along its axis, as `point_box_distance` measures it from a voxel's
/// faces: a row or plane left out by it holds no cube nearer, to the bit.
#[inline]
fn slab_gap(r: f64, v: f64, i: i64) -> f64 {
    let c = (i as f64 + 0.5) * r;
    ((c - r / 2.0) - v).max(v - (c + r / 2.0)).max(0.0)
}

/// A square distance beyond `best * best` times this is at or beyond `best` by `sqrt`
/// too: the factor covers the rounding of both, so a row, plane or cube left out by
/// squares is one `sqrt` would leave out.
const SQUARE_ALLOWANCE: f64 = 1.0 + 1e-12;

/// Row offsets per axis whose slabs [`exact_clearance`] keeps on the stack: a
/// 1.5 m cap at 0.05 m.
const STACK_SPAN: usize = 65;

/// Where the obstacle cubes of a row nearest a point in lattice column `x` can be.
enum Candidates {
    /// At these lattice x (each may be free: then the row has none).
    Two(i32, i32),
    /// Farther along x than this many voxels (the row's gaps saturate): read the row.
    Beyond(u8),
}

/// The candidates of a row of grid `g`, given as its raw states and gaps
/// ([`Grid::raw_row_at`], [`DistanceField::row_gaps_at`]; `None` outside the grid),
/// for a point in lattice column `x`.
fn row_candidates(g: &Grid, x: i32, row: Option<(&[u8], &[u8])>) -> Candidates {
    let Some((cells, gaps)) = row else {
        // Outside the grid every voxel is unknown: the one across from the point is
        // the nearest obstacle, if unknown space is one.
        return Candidates::Two(x, x);
    };
    let (first, last) = (g.origin()[0], g.origin()[0] + cells.len() as i32 - 1);
    if (x < first || x > last) && g.unknown_is_occupied() {
        return Candidates::Two(x, x);
    }
    // Off the row's ends with unknown space free, the row's nearest obstacle to the
    // point is the one nearest its end.
    let x = x.clamp(first, last);
    let n = gaps[(x - first) as usize];
    if n == FAR {
        // A cube 255 voxels along or more is at least 254 voxels away along x.
        Candidates::Beyond(FAR - 1)
    } else {
        Candidates::Two(x - n as i32, x + n as i32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn exact_clearance_reads_rows_whose_gaps_saturate() {
        use crate::map::grid::Cell;
        // A row longer than the gaps' 255 voxels: the obstacle 290 voxels away is
        // found by reading the row.
        let mut g = Grid::new(0.01, [0, 0, 0], [300, 1, 1], Cell::Free, false).unwrap();
        g.set([0, 0, 0], Cell::Occupied);
        let field = DistanceField::new(g);
        let p = Point3::new(2.905, 0.005, 0.005);
        assert!((exact_clearance(&field, p, 0.0, 3.0) - 2.895).abs() < 1e-9);
        // Within a cap below the saturated gap, it is not looked for.
        assert_eq!(exact_clearance(&field, p, 0.0, 2.0), 2.0);
    }

    #[test]
    fn box_distances_by_hand() {
        let (lo, hi) = (Point3::origin(), Point3::new(1.0, 1.0, 1.0));
        let p = Point3::new;
        assert_eq!(point_box_distance(p(0.5, 0.5, 0.5), lo, hi), 0.0);
        assert!((point_box_distance(p(2.0, 0.5, 0.5), lo, hi) - 1.0).abs() < 1e-12);
        assert!((point_box_distance(p(2.0, 2.0, 0.5), lo, hi) - 2f64.sqrt()).abs() < 1e-12);
        // A segment passing diagonally above an edge.
        let d = segment_box_distance(p(-1.0, 2.0, 0.5), p(2.0, -1.0, 0.5), lo, hi);
        // The line x + y = 1 passes through the box's face diagonal: distance 0.
        assert!(d.abs() < 1e-12);
        let d = segment_box_distance(p(-1.0, 3.0, 0.5), p(3.0, -1.0, 0.5), lo, hi);
        // x + y = 2: closest to corner (1, 1): distance sqrt(2)/2... (1,1) to line = 0/ sqrt2? (1+1-2)/sqrt2 = 0.
        assert!(d.abs() < 1e-12);
        let d = segment_box_distance(p(0.0, 3.0, 0.5), p(3.0, 0.0, 0.5), lo, hi);
        // x + y = 3: corner (1,1) at distance 1/sqrt(2).
        assert!((d - 0.5f64.sqrt()).abs() < 1e-12);
        // Parallel segment, beyond the end.
        let d = segment_box_distance(p(3.0, 0.5, 2.0), p(5.0, 0.5, 2.0), lo, hi);
        assert!((d - 5f64.sqrt()).abs() < 1e-12);
    }

    proptest! {
        /// The closed form never exceeds dense sampling, and is close to it.
        #[test]
        fn segment_box_matches_sampling(
            a in proptest::array::uniform3(-2.0f64..3.0),
            b in proptest::array::uniform3(-2.0f64..3.0),
            lo in proptest::array::uniform3(-0.5f64..0.5),
            size in proptest::array::uniform3(0.05f64..1.0),
        ) {
            let hi = [lo[0] + size[0], lo[1] + size[1], lo[2] + size[2]];
            let (a, b, lo, hi) = (a.into(), b.into(), lo.into(), hi.into());
            let d = segment_box_distance(a, b, lo, hi);
            let mut best = f64::INFINITY;
            for i in 0..=2000 {
                let t = i as f64 / 2000.0;
                let p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])];
                best = best.min(point_box_distance(p.into(), lo, hi));
            }
            prop_assert!(d <= best + 1e-9, "{} > {}", d, best);
            let len = ((b[0]-a[0]).powi(2) + (b[1]-a[1]).powi(2) + (b[2]-a[2]).powi(2)).sqrt();
            prop_assert!(best - d <= len / 2000.0 + 1e-9, "{} vs {}", d, best);
        }
    }
}
