//! The weighted zeta metric of the full-state PRM, and its neighbour search.
//!
//! # The metric
//! The distance between two configurations `a`, `b` approximates the root-mean-square
//! displacement of the chain's unit centres between them. A head translation `d xi`
//! moves every unit by `|d xi|`. Turning link `i` (1-based) by a small angle `d`
//! moves the `N - i` units behind it by about `l d` each, so its share of the mean
//! squared displacement is `(N - i) / N * l^2 d^2`: these are the paper's `C_T` weights
//! (Eq. 3), and the head's own yaw gets `C_T`'s weight `N`, i.e. `l^2 d^2`. Hence
//!
//! ```text
//! d(a, b)^2 = |xi_a - xi_b|^2 + (l^2 / N) * C_T(eta_a, eta_b)^2
//! ```
//!
//! with one change that makes it an exact Euclidean distance: every yaw (the head's and
//! each link's) enters through its chord `2 sin(d / 2)` instead of the wrapped angle
//! `d` (equal to first order, never larger, and at most `pi / 2` times smaller at a half
//! turn). Pitches are not wrapped (`|theta| < 90 deg`) and enter linearly. So the
//! metric is the Euclidean distance between the embeddings
//!
//! ```text
//! e(zeta) = [x, y, z,  l cos psi1_r, l sin psi1_r,
//!            for each link i: w_i theta_i, w_i cos psi_i, w_i sin psi_i ],  w_i = l sqrt((N - i) / N)
//! ```
//!
//! in `R^(3N + 2)`, and a k-d tree over the embeddings finds exact nearest neighbours
//! (kiddo, one tree per dimension, instantiated for every `N` in `2..=16`).

use std::num::NonZero;

use aerial_chain_core::{ChainParams, Shape};
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;

/// Dimension of the embedding for `n` units: `3 n + 2`.
pub fn embedding_dim(n: usize) -> usize {
    3 * n + 2
}

/// Appends the embedding of `(xi, shape)` (see the module docs) to `out`.
pub fn embed(params: &ChainParams, xi: [f64; 3], shape: &Shape, out: &mut Vec<f64>) {
    let n = shape.units();
    let l = params.link_length as f64;
    out.extend_from_slice(&xi);
    let h = shape.head_yaw() as f64;
    out.push(l * h.cos());
    out.push(l * h.sin());
    for k in 0..shape.links() {
        let i = k + 1;
        let w = l * (((n - i) as f64) / n as f64).sqrt();
        let (p, y) = (shape.pitch(k) as f64, shape.yaw(k) as f64);
        out.push(w * p);
        out.push(w * y.cos());
        out.push(w * y.sin());
    }
}

/// The metric between two embeddings of equal length.
pub fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Nearest-neighbour index over a fixed set of embedded points (row-major, `dim` each).
pub struct Neighbours {
    dim: usize,
    points: Vec<f64>,
    tree: Tree,
}

enum Tree {
    /// No tree: too few points, or a dimension without an instantiated tree.
    Brute,
    D8(ImmutableKdTree<f64, u32, 8, 32>),
    D11(ImmutableKdTree<f64, u32, 11, 32>),
    D14(ImmutableKdTree<f64, u32, 14, 32>),
    D17(ImmutableKdTree<f64, u32, 17, 32>),
    D20(ImmutableKdTree<f64, u32, 20, 32>),
    D23(ImmutableKdTree<f64, u32, 23, 32>),
    D26(ImmutableKdTree<f64, u32, 26, 32>),
    D29(ImmutableKdTree<f64, u32, 29, 32>),
    D32(ImmutableKdTree<f64, u32, 32, 32>),
    D35(ImmutableKdTree<f64, u32, 35, 32>),
    D38(ImmutableKdTree<f64, u32, 38, 32>),
    D41(ImmutableKdTree<f64, u32, 41, 32>),
    D44(ImmutableKdTree<f64, u32, 44, 32>),
    D47(ImmutableKdTree<f64, u32, 47, 32>),
    D50(ImmutableKdTree<f64, u32, 50, 32>),
}

fn rows<const K: usize>(points: &[f64]) -> Vec<[f64; K]> {
    points
        .chunks_exact(K)
        .map(|c| {
            let mut r = [0.0; K];
            r.copy_from_slice(c);
            r
        })
        .collect()
}

fn query<const K: usize>(
    t: &ImmutableKdTree<f64, u32, K, 32>,
    q: &[f64],
    k: NonZero<usize>,
) -> Vec<(u32, f64)> {
    let mut a = [0.0; K];
    a.copy_from_slice(&q[..K]);
    t.nearest_n::<SquaredEuclidean>(&a, k)
        .into_iter()
        .map(|n| (n.item, n.distance.sqrt()))
        .collect()
}

macro_rules! trees {
    ($($v:ident $k:literal),*) => {
        fn build_tree(dim: usize, points: &[f64]) -> Tree {
            match dim {
                $($k => Tree::$v(ImmutableKdTree::new_from_slice(&rows::<$k>(points))),)*
                _ => Tree::Brute,
            }
        }
        fn query_tree(t: &Tree, q: &[f64], k: NonZero<usize>) -> Option<Vec<(u32, f64)>> {
            match t {
                $(Tree::$v(t) => Some(query(t, q, k)),)*
                Tree::Brute => None,
            }
        }
    };
}

trees!(D8 8, D11 11, D14 14, D17 17, D20 20, D23 23, D26 26, D29 29, D32 32, D35 35, D38 38, D41 41, D44 44, D47 47, D50 50);

impl Neighbours {
    /// An index over `points` (row-major, `dim` numbers each; a trailing partial row is
    /// ignored).
    pub fn new(dim: usize, mut points: Vec<f64>) -> Self {
        let dim = dim.max(1);
        points.truncate(points.len() / dim * dim);
        // The k-d tree pays off from a few hundred points; below, scan.
        let tree = if points.len() / dim >= 64 {
            build_tree(dim, &points)
        } else {
            Tree::Brute
        };
        Self { dim, points, tree }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len() / self.dim
    }

    /// Point `i`'s embedding.
    pub fn point(&self, i: usize) -> &[f64] {
        &self.points[i * self.dim..(i + 1) * self.dim]
    }

    /// The `k` points nearest to `q` (of length `dim`), nearest first, ties by index,
    /// as `(index, distance)`.
    pub fn nearest(&self, q: &[f64], k: usize) -> Vec<(u32, f64)> {
        let Some(kk) = NonZero::new(k.min(self.len())) else {
            return Vec::new();
        };
        if q.len() != self.dim {
            return Vec::new();
        }
        let mut out = match query_tree(&self.tree, q, kk) {
            Some(v) => v,
            None => {
                let mut all: Vec<(u32, f64)> = (0..self.len())
                    .map(|i| (i as u32, distance(self.point(i), q)))
                    .collect();
                all.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
                all.truncate(kk.get());
                all
            }
        };
        out.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tree_and_scan_agree() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let dim = embedding_dim(5);
        let pts: Vec<f64> = (0..500 * dim).map(|_| rng.gen_range(-1.0..1.0)).collect();
        let idx = Neighbours::new(dim, pts.clone());
        for q in 0..20 {
            let qp = &pts[q * dim..(q + 1) * dim];
            let got = idx.nearest(qp, 7);
            let mut all: Vec<(u32, f64)> = (0..500)
                .map(|i| (i as u32, distance(&pts[i * dim..(i + 1) * dim], qp)))
                .collect();
            all.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
            let want: Vec<u32> = all[..7].iter().map(|x| x.0).collect();
            assert_eq!(got.iter().map(|x| x.0).collect::<Vec<_>>(), want);
        }
    }

    #[test]
    fn metric_is_rms_displacement_to_first_order() {
        let p = ChainParams::new(5);
        let a = Shape::line(5, 0.0);
        let mut b = a;
        b.set_link(0, 0.01, 0.0); // first link pitches by 0.01: 4 units move ~0.005 m
        let (mut ea, mut eb) = (Vec::new(), Vec::new());
        embed(&p, [0.0; 3], &a, &mut ea);
        embed(&p, [0.0; 3], &b, &mut eb);
        let want = (4.0 / 5.0 * (0.5f64 * 0.01).powi(2)).sqrt();
        assert!((distance(&ea, &eb) - want).abs() < 1e-6);
        // Yaw wraps: -pi + e and pi - e are close.
        let mut c = a;
        c.set_link(3, 0.0, std::f32::consts::PI - 1e-3);
        let mut d = a;
        d.set_link(3, 0.0, -std::f32::consts::PI + 1e-3);
        let (mut ec, mut ed) = (Vec::new(), Vec::new());
        embed(&p, [0.0; 3], &c, &mut ec);
        embed(&p, [0.0; 3], &d, &mut ed);
        assert!(distance(&ec, &ed) < 1e-3);
    }

    #[test]
    fn bad_queries_give_nothing() {
        let idx = Neighbours::new(3, vec![0.0, 0.0, 0.0]);
        assert!(idx.nearest(&[0.0, 0.0], 1).is_empty());
        assert!(idx.nearest(&[0.0, 0.0, 0.0], 0).is_empty());
        assert_eq!(idx.nearest(&[0.0, 0.0, 0.0], 5).len(), 1);
        assert_eq!(Neighbours::new(3, Vec::new()).len(), 0);
    }
}
