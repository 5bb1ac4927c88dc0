//! The full-state PRM's roadmap: sampled configurations (goal samples first), their
//! embeddings in the zeta metric, and the lazy graph of their nearest neighbours.

use std::time::{Duration, Instant};

use aerial_chain_core::{ChainParams, Shape};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::metric::{embed, embedding_dim, Neighbours};
use super::{prm_star_k, PrmSettings, PrmStats};
use crate::collision::CollisionContext;
use crate::plan_file::Timings;
use crate::planner::graph::{Edge, EdgeState, LazyGraph};

/// The roadmap: vertices, their embeddings and neighbour lists.
pub(super) struct Roadmap {
    /// Head position of each vertex (m).
    pub(super) xi: Vec<[f64; 3]>,
    /// Shape of each vertex.
    pub(super) shapes: Vec<Shape>,
    /// The vertices' embeddings, for nearest neighbours.
    pub(super) index: Neighbours,
    /// Directed: an edge's validity depends on its direction.
    pub(super) graph: LazyGraph,
    goal_samples: usize,
    tries: u64,
    capped: bool,
    /// Neighbours asked per vertex.
    pub(super) k: usize,
}

/// Sampled configurations.
struct Samples {
    xi: Vec<[f64; 3]>,
    shapes: Vec<Shape>,
    /// Of them, the first ones are goal samples.
    goal_samples: usize,
    /// Configurations drawn.
    tries: u64,
    /// Whether the time limit stopped sampling.
    capped: bool,
}

/// A uniformly random shape: head yaw and link yaws on the circle, pitches in the limits.
fn random_shape(params: &ChainParams, rng: &mut Pcg64) -> Shape {
    let pi = std::f32::consts::PI;
    let mut s = Shape::line(params.units, 0.0);
    s.set_head_yaw(aerial_chain_core::angle::wrap(rng.gen_range(-pi..pi)));
    let t = params.theta_max;
    for k in 0..s.links() {
        let pitch = rng.gen_range(-t..=t);
        let yaw = aerial_chain_core::angle::wrap(rng.gen_range(-pi..pi));
        s.set_link(k, pitch, yaw);
    }
    s
}

/// Whether `tol` is a goal tolerance (finite, `>= 0`).
pub(super) fn valid_tolerance(tol: f64) -> bool {
    tol.is_finite() && tol >= 0.0
}

impl Roadmap {
    /// Samples the vertex budget (goal samples first, in the ball of radius `tol`
    /// about `goal`), then joins each vertex to its `k` nearest. Past `limit` it stops
    /// and keeps what it has.
    pub(super) fn build(
        ctx: &CollisionContext,
        s: &PrmSettings,
        (goal, tol): ([f64; 3], f64),
        limit: Option<Duration>,
    ) -> Self {
        let began = Instant::now();
        let out_of_time =
            |tries: u64| tries.is_multiple_of(256) && limit.is_some_and(|l| began.elapsed() > l);
        let Samples {
            xi,
            shapes,
            goal_samples,
            tries,
            mut capped,
        } = sample(ctx, s, (goal, tol), &out_of_time);
        let params = ctx.params();
        let n = xi.len();
        let dim = embedding_dim(params.n());
        let mut emb = Vec::with_capacity(n * dim);
        for (p, sh) in xi.iter().zip(&shapes) {
            embed(params, *p, sh, &mut emb);
        }
        let index = Neighbours::new(dim, emb);
        let k = s.k.unwrap_or_else(|| prm_star_k(n, params.shape_dim() + 3));
        let graph = nearest_neighbours(&index, n, k, &out_of_time, &mut capped);
        Self {
            xi,
            shapes,
            index,
            graph,
            goal_samples,
            tries,
            capped,
            k,
        }
    }

    /// The counters of the roadmap, built in `roadmap_s`.
    pub(super) fn stats(&self, roadmap_s: f64) -> PrmStats {
        let g = &self.graph;
        PrmStats {
            timings: Timings {
                roadmap_s,
                ..Default::default()
            },
            vertices: self.xi.len(),
            goal_samples: self.goal_samples,
            sample_tries: self.tries,
            build_capped: self.capped,
            k: self.k,
            // Undirected: every edge is kept both ways.
            graph_edges: (0..g.len()).map(|v| g.edges(v).len()).sum::<usize>() / 2,
            ..Default::default()
        }
    }
}

/// Rejection sampling of the vertex budget: first the goal samples (the head uniform
/// in the goal ball, any shape), then configurations uniform in the map's box. Without
/// a time limit it runs until the budget is met (or `1000 M_F` draws have been made).
fn sample(
    ctx: &CollisionContext,
    s: &PrmSettings,
    (goal, tol): ([f64; 3], f64),
    out_of_time: &impl Fn(u64) -> bool,
) -> Samples {
    let params = *ctx.params();
    let mut rng = Pcg64::seed_from_u64(s.seed);
    let (lo, hi) = ctx.field().grid().bounds();
    let want_goal = if valid_tolerance(tol) && ctx.is_head_free(goal) {
        s.goal_count()
    } else {
        0
    };
    let max_tries = (s.vertices as u64).saturating_mul(1000).max(10_000);
    let mut xi = Vec::with_capacity(s.vertices);
    let mut shapes = Vec::with_capacity(s.vertices);
    let mut tries = 0u64;
    let mut capped = false;
    while xi.len() < want_goal && tries < max_tries {
        tries += 1;
        if out_of_time(tries) {
            capped = true;
            break;
        }
        let mut d = [0.0; 3];
        for c in d.iter_mut() {
            *c = if tol > 0.0 {
                rng.gen_range(-tol..=tol)
            } else {
                0.0
            };
        }
        if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > tol * tol {
            continue;
        }
        let p = [goal[0] + d[0], goal[1] + d[1], goal[2] + d[2]];
        let shape = random_shape(&params, &mut rng);
        if ctx.check_config(p, &shape).is_ok() {
            xi.push(p);
            shapes.push(shape);
        }
    }
    let goal_samples = xi.len();
    while !capped && xi.len() < s.vertices && tries < max_tries {
        tries += 1;
        if out_of_time(tries) {
            capped = true;
            break;
        }
        let p = [
            rng.gen_range(lo[0]..hi[0]),
            rng.gen_range(lo[1]..hi[1]),
            rng.gen_range(lo[2]..hi[2]),
        ];
        let shape = random_shape(&params, &mut rng);
        if ctx.check_config(p, &shape).is_ok() {
            xi.push(p);
            shapes.push(shape);
        }
    }
    Samples {
        xi,
        shapes,
        goal_samples,
        tries,
        capped,
    }
}

/// Joins each of the `n` vertices of `index` to its `k` nearest, both ways, in vertex
/// order; sets `capped` where time runs out first (later vertices then keep only the
/// edges found so far).
fn nearest_neighbours(
    index: &Neighbours,
    n: usize,
    k: usize,
    out_of_time: &impl Fn(u64) -> bool,
    capped: &mut bool,
) -> LazyGraph {
    let mut pairs: Vec<Vec<(u32, f64)>> = vec![Vec::new(); n];
    for i in 0..n {
        if out_of_time(i as u64) {
            *capped = true;
            break;
        }
        for (j, d) in index.nearest(index.point(i), k + 1) {
            if j as usize != i {
                pairs[i].push((j, d));
                pairs[j as usize].push((i as u32, d));
            }
        }
    }
    let adj = pairs
        .into_iter()
        .map(|mut v| {
            v.sort_by_key(|x| x.0);
            v.dedup_by_key(|x| x.0);
            v.into_iter()
                .map(|(to, cost)| Edge::new(to as usize, cost, EdgeState::Unknown))
                .collect()
        })
        .collect();
    LazyGraph::new(adj, false)
}
