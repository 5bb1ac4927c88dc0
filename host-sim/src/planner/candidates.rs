//! Candidate shapes for one head edge: yaw rotations of the current shape and the
//! library's shapes at `n_psi` headings, ordered by the cost to transition `C_T`.

use std::f32::consts::TAU;

use aerial_chain_core::cost::transition_cost_sq;
use aerial_chain_core::lsc::{LscEntry, LscKind};
use aerial_chain_core::Shape;

/// Where a shape of the plan came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// The start shape.
    Start,
    /// A yaw rotation of the shape before it.
    Rotation,
    /// A library shape (rotated about the head).
    Lsc(LscKind),
    /// A random shape, by index in the SRS.
    Srs(u16),
    /// A random shape turned about the head so that it trails behind the edge.
    SrsTurned(u16),
    /// The chain laid back along the head's track (follow-the-leader).
    Follow,
    /// Part of the way to a shape the search chose, where refinement found that
    /// enough (`super::refine`).
    Shrunk,
    /// A configuration of the full-state PRM's roadmap ([`crate::baseline`]).
    Sampled,
    /// The yaw and shape a goal asks for ([`crate::goal::GoalPose`]).
    Goal,
}

/// A shape with its origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// The shape.
    pub shape: Shape,
    /// Where it came from.
    pub source: Source,
}

/// The headings tried for an edge: the edge's own direction (so the chain trails
/// straight behind the head) and `n_psi` evenly spaced turns from it.
pub fn headings(edge_yaw: f32, n_psi: usize) -> impl Iterator<Item = f32> {
    let n = n_psi.max(1);
    (0..n).map(move |k| aerial_chain_core::angle::wrap(edge_yaw + TAU * k as f32 / n as f32))
}

/// Yaw rotations of `current` that point it at each heading (except itself),
/// cheapest first.
pub fn rotations(current: &Shape, edge_yaw: f32, n_psi: usize) -> Vec<Candidate> {
    let mut out: Vec<Candidate> = headings(edge_yaw, n_psi)
        .map(|h| current.rotated(aerial_chain_core::angle::diff(current.head_yaw(), h)))
        .filter(|s| s.max_angle_diff(current) > super::numeric::DISTINCT_SHAPE)
        .map(|shape| Candidate {
            shape,
            source: Source::Rotation,
        })
        .collect();
    sort_by_cost(current, &mut out);
    out
}

/// Library shapes at every heading, cheapest to reach first (`only`: one kind).
pub fn library(
    current: &Shape,
    lsc: &[LscEntry],
    edge_yaw: f32,
    n_psi: usize,
    only: Option<LscKind>,
) -> Vec<Candidate> {
    let mut out = Vec::new();
    for e in lsc.iter().filter(|e| only.is_none_or(|k| k == e.kind)) {
        for h in headings(edge_yaw, n_psi) {
            // Library shapes look along +x: rotate their head to the heading.
            let shape = e
                .shape
                .rotated(aerial_chain_core::angle::diff(e.shape.head_yaw(), h));
            out.push(Candidate {
                shape,
                source: Source::Lsc(e.kind),
            });
        }
    }
    sort_by_cost(current, &mut out);
    out
}

/// Stable sort by `C_T` from `from` (ties keep generation order: deterministic).
pub fn sort_by_cost(from: &Shape, c: &mut [Candidate]) {
    c.sort_by(|a, b| {
        transition_cost_sq(from, &a.shape).total_cmp(&transition_cost_sq(from, &b.shape))
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use aerial_chain_core::cost::transition_cost;
    use aerial_chain_core::lsc::library as lib;
    use aerial_chain_core::ChainParams;

    #[test]
    fn rotations_are_sorted_and_skip_the_identity() {
        let s = Shape::line(4, 0.0);
        let r = rotations(&s, 0.0, 8);
        assert_eq!(r.len(), 7);
        let costs: Vec<f32> = r.iter().map(|c| transition_cost(&s, &c.shape)).collect();
        assert!(costs.windows(2).all(|w| w[0] <= w[1] + 1e-6));
        assert!((r[0].shape.head_yaw().abs() - std::f32::consts::FRAC_PI_4).abs() < 1e-5);
    }

    #[test]
    fn library_candidates_face_the_edge_first_for_a_line() {
        let p = ChainParams::new(5);
        let l = lib(&p);
        let cur = Shape::line(5, 1.0);
        let c = library(&cur, &l.entries, 1.0, 8, None);
        assert_eq!(c.len(), 6 * 8);
        assert_eq!(c[0].source, Source::Lsc(LscKind::Li));
        assert!(c[0].shape.max_angle_diff(&cur) < 1e-5);
        assert!(library(&cur, &l.entries, 1.0, 8, Some(LscKind::Pn))
            .iter()
            .all(|x| x.source == Source::Lsc(LscKind::Pn)));
    }
}
