//! How far a body moving in a straight line stays clear of the map, read from the
//! obstacle cubes near its path. The translation check walks each body by its proven
//! margin (the ball one bound proves free); beside a wall that margin is thin, and a body
//! sliding along the wall would be measured again every few millimetres. Moving the body
//! against the cubes it could meet settles such a run at once.
//!
//! Each cube is grown by the body's radius into a box, which holds every point within that
//! radius of the cube; the body (a unit's centre, or a link's segment, by its bounding
//! box) moves against those boxes axis by axis. A box only over-approximates the rounded
//! cube, so a run may end early by a corner (never late): the check then walks on from
//! there as before.

use nalgebra::{Point3, Vector3};

use crate::map::distance::DistanceField;
use crate::map::grid::floor;

/// Added to every grown radius (m): covers the rounding of the times computed below
/// (relative errors near 1e-16 of coordinates far below a kilometre), so that a time
/// found is never later than the true one.
const ROUND: f64 = 1e-9;

/// The most rows of voxels a run reads before it gives up (and proves nothing): a body
/// with a long way left in a fine map would otherwise read more than the walk it saves.
const MAX_ROWS: f64 = 4096.0;

/// How far (m, in `[0, reach]`) the segment `a b` (a point when `a == b`) can move along
/// the unit vector `dir` while every point of it stays more than `radius` from every
/// obstacle cube of the field's grid (space beyond the grid counts as the grid says
/// unknown space does). A proven lower bound: 0 where the segment's box already meets a
/// grown cube, or where the path crosses more rows than a run reads.
pub(super) fn free_run(
    field: &DistanceField,
    a: Point3<f64>,
    b: Point3<f64>,
    dir: Vector3<f64>,
    radius: f64,
    reach: f64,
) -> f64 {
    let grid = field.grid();
    let r = grid.resolution();
    let grown = radius + ROUND;
    let (lo, hi) = (a.coords.inf(&b.coords), a.coords.sup(&b.coords));
    let way = dir * reach;
    // Every cube the body can meet within `reach` lies in the swept box, grown.
    let first = ((lo + way.inf(&Vector3::zeros())).add_scalar(-grown) / r).map(floor);
    let last = ((hi + way.sup(&Vector3::zeros())).add_scalar(grown) / r).map(floor);
    let ny = last.y - first.y + 1.0;
    if !(ny <= MAX_SPAN as f64 && ny * (last.z - first.z + 1.0) <= MAX_ROWS) {
        return 0.0;
    }
    let body = Body {
        lo,
        hi,
        dir,
        grown,
        r,
    };
    let (y0, ny) = (first.y as i64, ny as usize);
    let mut across_y = [(0.0, 0.0); MAX_SPAN];
    for (j, o) in across_y.iter_mut().enumerate().take(ny) {
        *o = body.overlap(1, y0 + j as i64);
    }
    let mut run = reach;
    for z in first.z as i64..=last.z as i64 {
        let (z_in, z_out) = body.overlap(2, z);
        for (j, &(y_in, y_out)) in across_y[..ny].iter().enumerate() {
            // While the body's box is across this row's grown slabs in y and z.
            let from = z_in.max(y_in).max(0.0);
            let to = z_out.min(y_out).min(run);
            if from <= to {
                run = run.min(body.first_in_row(field, y0 + j as i64, z, from, to));
                if run <= 0.0 {
                    return 0.0;
                }
            }
        }
    }
    run
}

/// The most rows in y a run reads (they are kept on the stack).
const MAX_SPAN: usize = 64;

/// The moving body: its box at the start, its direction, and the cubes' grown radius.
struct Body {
    lo: Vector3<f64>,
    hi: Vector3<f64>,
    dir: Vector3<f64>,
    grown: f64,
    r: f64,
}

impl Body {
    /// The times `(in, out)` at which the body's box overlaps, along axis `a`, the grown
    /// slab of the cubes with lattice index `k` there; `in > out` when it never does.
    fn overlap(&self, a: usize, k: i64) -> (f64, f64) {
        let (c_lo, c_hi) = (
            k as f64 * self.r - self.grown,
            (k as f64 + 1.0) * self.r + self.grown,
        );
        let (lo, hi, d) = (self.lo[a], self.hi[a], self.dir[a]);
        if d > 0.0 {
            ((c_lo - hi) / d, (c_hi - lo) / d)
        } else if d < 0.0 {
            ((c_hi - lo) / d, (c_lo - hi) / d)
        } else if lo <= c_hi && hi >= c_lo {
            (f64::NEG_INFINITY, f64::INFINITY)
        } else {
            (f64::INFINITY, f64::NEG_INFINITY)
        }
    }

    /// The first time in `[from, to]` at which the body's box meets a grown obstacle
    /// cube of row `(y, z)`, while it is across the row's slabs; infinity when it does
    /// not. The row's cubes are read in the direction of motion (the first obstacle the
    /// box reaches is met first), skipping along the row's gaps.
    fn first_in_row(&self, field: &DistanceField, y: i64, z: i64, from: f64, to: f64) -> f64 {
        let grid = field.grid();
        let (d, r, g) = (self.dir.x, self.r, self.grown);
        let reach_lo = self.lo.x + (from * d).min(to * d) - g;
        let reach_hi = self.hi.x + (from * d).max(to * d) + g;
        let (k_lo, k_hi) = (floor(reach_lo / r) as i64, floor(reach_hi / r) as i64);
        let row = i32::try_from(y).ok().zip(i32::try_from(z).ok());
        let Some(start) = row.and_then(|(y, z)| grid.row_start(y, z)) else {
            // A row beyond the grid is all unknown: an obstacle, it is met as soon as
            // the body is across it (its cubes span the body's whole reach in x).
            return if grid.unknown_is_occupied() {
                from
            } else {
                f64::INFINITY
            };
        };
        let gaps = field.row_gaps_at(start);
        let x0 = grid.origin()[0] as i64;
        // Beyond the row's ends every voxel is unknown.
        let beyond = if grid.unknown_is_occupied() { 0 } else { 1 };
        let step = if d >= 0.0 { 1 } else { -1 };
        let mut k = if d >= 0.0 { k_lo } else { k_hi };
        while (k_lo..=k_hi).contains(&k) {
            // Free voxels ahead, by the row's gaps (beyond the row: one at a time).
            let ahead = usize::try_from(k - x0)
                .ok()
                .and_then(|i| gaps.get(i))
                .map_or(beyond, |&gap| gap as i64);
            if ahead == 0 {
                let (x_in, x_out) = self.overlap(0, k);
                let at = x_in.max(from);
                if at <= x_out.min(to) {
                    return at;
                }
                k += step;
            } else {
                k += step * ahead;
            }
        }
        f64::INFINITY
    }
}
