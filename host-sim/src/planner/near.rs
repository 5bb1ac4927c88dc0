//! Each point's `k` nearest within a radius, among points binned in cubes.
//!
//! The roadmap joins every vertex to its `k` nearest within `r_T`. Points are binned
//! in cubes and each point reads the cubes about its own ring by ring (the cubes at
//! Chebyshev distance 0, 1, 2, ... in cube steps), stopping as soon as `k` of the
//! points read lie nearer than any point not yet read can, or every cube within `r_T`
//! is read. The cubes' edge is half the radius of the ball that holds `k` points at
//! the points' mean density, so two or three rings hold a point's `k` nearest, whatever
//! the density: where the points are sparse the cubes are `r_T` wide and one ring (the
//! 27 cubes about a point's own) holds every point within `r_T`; where they are dense
//! (a roadmap sampled in the few cubic metres an online piece has seen free, hundreds
//! of vertices within `r_T` of each) the cubes shrink, where reading the 27 cubes of
//! edge `r_T` about each point would read nearly every point.
//! `cargo bench --bench planner -- roadmap_build`: the whole roadmap's build took 4.1
//! ms where reading the 27 `r_T` cubes took 6.7 ms on `window`, and 6.5 ms against
//! 15.5 ms on a seen room of it. (Reading cubes in order is cheaper than a k-d tree's
//! search with a bounded heap: 0.4-0.8 ms against 1.5 ms on a forest's 1500.)

use rayon::prelude::*;

/// Points sorted into cubes of edge `edge`, by a counting sort: the points of cube `c`
/// are `items[start[c]..start[c + 1]]`.
struct Bins {
    lo: [f64; 3],
    edge: f64,
    dims: [usize; 3],
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Bins {
    /// The cubes over the points' bounding box. Their edge is half the radius of a
    /// ball that holds `k` points at the points' mean density over the box, so that
    /// two or three rings hold a point's `k` nearest; never more than `r` (one ring then
    /// holds every point within `r`) unless that would give more cubes than points (a
    /// large box and a small radius), so that they never take more memory than the
    /// points.
    fn new(points: &[[f64; 3]], r: f64, k: usize) -> Self {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in points {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let span = [0, 1, 2].map(|a| (hi[a] - lo[a]).max(0.0));
        let volume: f64 = span.iter().map(|s| s.max(r)).product();
        let per_point = volume / points.len().max(1) as f64;
        let holds_k = (k.max(1) as f64 * per_point * 3.0 / (4.0 * std::f64::consts::PI)).cbrt();
        let edge = (holds_k / 2.0).min(r).max(per_point.cbrt());
        let dims = span.map(|s| (s / edge) as usize + 1);
        let mut bins = Bins {
            lo,
            edge,
            dims,
            start: Vec::new(),
            items: vec![0; points.len()],
        };
        let cell: Vec<usize> = points.iter().map(|p| bins.cell(p)).collect();
        let mut start = vec![0u32; dims.iter().product::<usize>() + 1];
        for &c in &cell {
            start[c + 1] += 1;
        }
        for c in 1..start.len() {
            start[c] += start[c - 1];
        }
        let mut next = start.clone();
        for (i, &c) in cell.iter().enumerate() {
            bins.items[next[c] as usize] = i as u32;
            next[c] += 1;
        }
        bins.start = start;
        bins
    }

    /// The cube index of `p` along each axis, clamped into the box.
    fn coords(&self, p: &[f64; 3]) -> [usize; 3] {
        [0, 1, 2].map(|a| (((p[a] - self.lo[a]) / self.edge) as usize).min(self.dims[a] - 1))
    }

    /// The cube holding `p`.
    fn cell(&self, p: &[f64; 3]) -> usize {
        let c = self.coords(p);
        c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])
    }

    /// The points of the cube `x` of row `(y, z)` through `x_end` (inclusive).
    fn run(&self, y: usize, z: usize, x: usize, x_end: usize) -> &[u32] {
        let row = self.dims[0] * (y + self.dims[1] * z);
        &self.items[self.start[row + x] as usize..self.start[row + x_end + 1] as usize]
    }

    /// The points of the cubes at Chebyshev distance `m` (in cubes) from cube `c`, as
    /// runs of `items` (the cubes along x are adjacent in it): passed to `f`.
    fn ring(&self, c: [usize; 3], m: usize, mut f: impl FnMut(&[u32])) {
        let span = |a: usize| c[a].saturating_sub(m)..=(c[a] + m).min(self.dims[a] - 1);
        let (x0, x1) = span(0).into_inner();
        for z in span(2) {
            for y in span(1) {
                if z.abs_diff(c[2]) == m || y.abs_diff(c[1]) == m {
                    f(self.run(y, z, x0, x1));
                    continue;
                }
                // Inside the ring's faces in y and z: only its two ends along x.
                if c[0] >= m {
                    f(self.run(y, z, c[0] - m, c[0] - m));
                }
                if c[0] + m < self.dims[0] {
                    f(self.run(y, z, c[0] + m, c[0] + m));
                }
            }
        }
    }

    /// How near `p` (in cube `c`) a point outside the cubes within `m` rings of `c`
    /// can be: the distance to the nearest face of that block that has cubes beyond
    /// it (infinite when there is none), less a slack for the rounding of the cubes'
    /// faces.
    fn beyond(&self, p: &[f64; 3], c: [usize; 3], m: usize) -> f64 {
        let mut near = f64::INFINITY;
        for a in 0..3 {
            if c[a] > m {
                near = near.min(p[a] - (self.lo[a] + (c[a] - m) as f64 * self.edge));
            }
            if c[a] + m + 1 < self.dims[a] {
                near = near.min(self.lo[a] + (c[a] + m + 1) as f64 * self.edge - p[a]);
            }
        }
        near - 1e-9 * (1.0 + self.edge)
    }
}

/// Squared distance, summed over x, y, z in that order.
fn squared(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]) * (a[i] - b[i])).sum()
}

/// For every point, the indices of the `k` other points nearest it among those within
/// `r` (a squared distance at most `r^2`), in no particular order; on every thread.
/// `keep(i)` is read before point `i`'s search: `false` gives it no neighbours (a
/// deadline passed).
pub(super) fn nearest_within(
    points: &[[f64; 3]],
    r: f64,
    k: usize,
    keep: impl Fn(usize) -> bool + Sync,
) -> Vec<Vec<usize>> {
    if points.is_empty() {
        return Vec::new();
    }
    let bins = Bins::new(points, r, k);
    let r2 = r * r;
    // Every point within `r` lies within this many rings of a point's cube.
    let rings = (r / bins.edge).ceil() as usize;
    points
        .par_iter()
        .enumerate()
        // One buffer of candidates per task: allocating one per point cost more than
        // the search.
        .map_init(Vec::new, |near: &mut Vec<(f64, usize)>, (i, p)| {
            if k == 0 || !keep(i) {
                return Vec::new();
            }
            near.clear();
            let c = bins.coords(p);
            for m in 0..=rings {
                bins.ring(c, m, |run| {
                    for &j in run {
                        let j = j as usize;
                        let d = squared(p, &points[j]);
                        if d <= r2 && j != i {
                            near.push((d, j));
                        }
                    }
                });
                // Done when nothing unread can be within `r`, or `k` read are nearer
                // than anything unread.
                let g = bins.beyond(p, c, m);
                if g >= r || (g > 0.0 && near.iter().filter(|x| x.0 < g * g).count() >= k) {
                    break;
                }
            }
            if near.len() > k {
                near.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0));
                near.truncate(k);
            }
            near.iter().map(|&(_, j)| j).collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The `k` nearest within `r` by reading every point.
    fn brute(points: &[[f64; 3]], i: usize, r: f64, k: usize) -> Vec<usize> {
        let mut near: Vec<(f64, usize)> = (0..points.len())
            .filter(|&j| j != i)
            .map(|j| (squared(&points[i], &points[j]), j))
            .filter(|&(d, _)| d <= r * r)
            .collect();
        near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut ids: Vec<usize> = near.into_iter().take(k).map(|(_, j)| j).collect();
        ids.sort_unstable();
        ids
    }

    /// The binned search's answer for every point is what reading every point finds.
    fn matches_brute_force(points: &[[f64; 3]], r: f64, k: usize) -> Result<(), TestCaseError> {
        let got = nearest_within(points, r, k, |_| true);
        prop_assert_eq!(got.len(), points.len());
        for (i, mut near) in got.into_iter().enumerate() {
            near.sort_unstable();
            prop_assert_eq!(near, brute(points, i, r, k), "point {}", i);
        }
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        /// The binned search finds what reading every point finds, in flat and in
        /// long boxes (where the cubes grow past `r`), for any `k`.
        #[test]
        fn binned_matches_brute_force(
            points in proptest::collection::vec(
                proptest::array::uniform3(-5.0f64..5.0), 0..300),
            stretch in proptest::array::uniform3(0.01f64..40.0),
            r in 0.05f64..3.0,
            k in 0usize..40,
        ) {
            let points: Vec<[f64; 3]> = points
                .iter()
                .map(|p| [p[0] * stretch[0], p[1] * stretch[1], p[2] * stretch[2]])
                .collect();
            matches_brute_force(&points, r, k)?;
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(40))]

        /// Where hundreds of points lie within `r` of each (a roadmap sampled in a
        /// small seen space), the cubes are smaller than `r` and the search stops after
        /// a few rings: it still finds what reading every point finds.
        #[test]
        fn dense_points_match_brute_force(
            points in proptest::collection::vec(
                proptest::array::uniform3(-1.0f64..1.0), 100..800),
            r in 0.5f64..3.0,
            k in 1usize..40,
        ) {
            matches_brute_force(&points, r, k)?;
        }
    }

    #[test]
    fn dense_points_use_cubes_smaller_than_the_radius() {
        let points: Vec<[f64; 3]> = (0..1000)
            .map(|i| {
                [
                    (i % 10) as f64 * 0.1,
                    (i / 10 % 10) as f64 * 0.1,
                    (i / 100) as f64 * 0.1,
                ]
            })
            .collect();
        let bins = Bins::new(&points, 1.5, 30);
        assert!(bins.edge < 0.5, "edge {}", bins.edge);
    }

    #[test]
    fn a_point_left_out_gets_no_neighbours() {
        let points = [[0.0; 3], [0.5, 0.0, 0.0], [0.0, 0.5, 0.0]];
        let got = nearest_within(&points, 1.0, 5, |i| i != 1);
        assert_eq!(got[1], Vec::<usize>::new());
        let mut first = got[0].clone();
        first.sort_unstable();
        assert_eq!(first, vec![1, 2]);
    }
}
