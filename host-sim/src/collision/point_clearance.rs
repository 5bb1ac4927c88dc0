//! The exact clearance of a point: the distance to the nearest obstacle voxel cube,
//! read row by row from the grid's rows along x and their gaps
//! ([`crate::map::row_gaps`]). The conservative checks fall back on it where the
//! distance field's bound falls just short; widening and threading measure with it.

use nalgebra::Point3;

use super::exact::{slab_gap, SQUARE_ALLOWANCE};
use crate::map::distance::DistanceField;
use crate::map::grid::Grid;
use crate::map::row_gaps::FAR;

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

/// [`exact_clearance`] with `stop` 0, to the bit: the exact distance from `p` to the
/// nearest obstacle cube, capped at `cap`, 0 in one. Read as [`exact_clearance_above`]
/// reads (the rows straight across `p` first, a row's state only where it could lower
/// the minimum); a point within a cube is measured by `exact_clearance` itself. The
/// widening's and the threading's measures of a passage read it often.
pub(crate) fn exact_distance(field: &DistanceField, p: Point3<f64>, cap: f64) -> f64 {
    exact_clearance_above(field, p, 0.0, cap).unwrap_or_else(|| exact_clearance(field, p, 0.0, cap))
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
}
