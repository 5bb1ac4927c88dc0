//! Exact distances from the chain's bodies to the map's obstacle cubes, in `f64`, for
//! verification. Independent of the distance field: the obstacle voxels near a body are
//! enumerated from the [`Grid`] and measured one by one.

use aerial_chain_core::kinematics::positions_into;
use aerial_chain_core::validity::{check_shape, Body, Violation};
use aerial_chain_core::{ChainParams, Shape};

use nalgebra::{Point3, Vector3};

use super::OutOfBounds;
use crate::map::blocks::BLOCK;
use crate::map::grid::{floor, Grid};

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

/// How far the coordinate `v` lies from the slab of voxels `i` (lattice index,
/// resolution `r`) along its axis, as `point_box_distance` measures it from a voxel's
/// faces: a row or plane left out by it holds no cube nearer, to the bit.
#[inline]
pub(super) fn slab_gap(r: f64, v: f64, i: i64) -> f64 {
    let c = (i as f64 + 0.5) * r;
    ((c - r / 2.0) - v).max(v - (c + r / 2.0)).max(0.0)
}

/// A square distance beyond `best * best` times this is at or beyond `best` by `sqrt`
/// too: the factor covers the rounding of both, so a row, plane or cube left out by
/// squares is one `sqrt` would leave out.
pub(super) const SQUARE_ALLOWANCE: f64 = 1.0 + 1e-12;

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

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
