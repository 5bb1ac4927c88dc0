//! How far a plan's units keep from the map along an edge, as widening measures it:
//! exactly (sphere against voxel cube) at twice the verifier's sample spacing, where
//! the distance field's proven bound allows the narrowest; and the distance to the
//! map and its gradient at a point (also read by `crate::planner::thread`).

use nalgebra::{Point3, Vector3};

use super::CAP;
use crate::collision::exact::positions_f64;
use crate::collision::point_clearance::{exact_clearance_above, exact_distance};
use crate::collision::verify::{classify_edge, edge_intervals, edge_sample};
use crate::collision::CollisionContext;
use crate::planner::numeric::{TIE, TINY};
use crate::planner::Step;

/// Samples of an edge are measured at the verifier's spacing times this: no unit
/// moves more than `SAMPLE_SPACING r_v / 4` between two, so a narrowest missed in
/// between is at most that much narrower (the clearance changes no faster than the
/// unit moves); `arc verify` reports the exact figure.
///
/// Tuning left a constant: every measuring function of widening and threading
/// samples edges at this spacing, and their callers (tests included) hold no
/// settings; 2 halves the measurements for at most `r_v / 2` of missed narrowing.
const SAMPLE_SPACING: f64 = 2.0;

/// The gradient of [`distance`] is taken by central differences this many steps per
/// voxel: derived from the resolution, an eighth of a voxel, well inside the voxel
/// whose cube is nearest, so that both differences see the same obstacle.
const GRADIENT_STEPS_PER_VOXEL: f64 = 8.0;

/// The narrowest sample of an edge: its clearance and where (unit centre, and which
/// unit at which sample).
#[derive(Clone, Copy, Debug)]
pub(super) struct Narrowest {
    pub(super) clearance: f64,
    pub(super) at: Point3<f64>,
    pub(super) spot: Spot,
}

/// A unit at one of an edge's samples: the sample's parameter along the edge (0 at
/// its start, 1 at its end) and the unit's index.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Spot {
    pub(super) t: f64,
    pub(super) unit: usize,
}

/// The unit positions at an edge's samples, with the distance field's lower bound on
/// their distance to the map, lowest first (those within `CAP + r_u`).
pub(super) struct Samples {
    bounds: Vec<(f64, Point3<f64>, Spot)>,
    /// The largest bound that may still hold the narrowest: the lowest plus what the
    /// bound can lose, `r_v sqrt(3)`.
    within: f64,
    /// The edge's first head position, where an edge wider than the cap is placed.
    start: Point3<f64>,
}

/// The narrowest unit clearance of edge `e` of `steps`, exactly, at the verifier's
/// samples (capped at [`CAP`]): [`measure`] over every sample.
pub(super) fn measure_whole(ctx: &CollisionContext, e: usize, steps: &[Step]) -> Narrowest {
    measure(ctx, e, steps, f64::NEG_INFINITY, |_| true)
        .expect("no clearance is at or below minus infinity")
}

/// The narrowest unit clearance of edge `e` of `steps` over the unit positions `keep`
/// keeps, exactly, at the verifier's samples (capped at [`CAP`]); `None` at the first
/// sample at or below `floor`. The distance field's proven lower bound picks the
/// samples that can hold the minimum (the exact distance exceeds the bound by at most
/// `r_v sqrt(3)`); only those are measured exactly, lowest bound first. One
/// measurement of widening's budget; the caller counts it.
pub(super) fn measure(
    ctx: &CollisionContext,
    e: usize,
    steps: &[Step],
    floor: f64,
    keep: impl Fn(&Point3<f64>) -> bool,
) -> Option<Narrowest> {
    narrowest_of(ctx, &samples(ctx, e, steps, keep), floor)
}

/// [`measure`] of an edge's `samples`.
pub(super) fn narrowest_of(
    ctx: &CollisionContext,
    samples: &Samples,
    floor: f64,
) -> Option<Narrowest> {
    let r_u = ctx.params().unit_radius as f64;
    let r_v = ctx.field().grid().resolution();
    let mut best = Narrowest {
        clearance: CAP,
        at: samples.start,
        spot: Spot::default(),
    };
    for &(lb, p, spot) in &samples.bounds {
        // A bound within a micrometre of the best is as good as equal: the samples
        // along a flat face all share it.
        if lb - r_u + TINY >= best.clearance || lb > samples.within {
            break;
        }
        // Near the cap the bound is close enough: the exact measure there costs
        // the most (the farthest rings) and matters the least.
        let c = if lb - r_u >= CAP - r_v {
            lb - r_u
        } else {
            // Only a distance below the best so far can matter (most samples of
            // an edge are wider).
            let below = best.clearance + r_u;
            let d = distance_below(ctx, p, below);
            if d >= below {
                continue;
            }
            d - r_u
        };
        if c <= floor {
            return None;
        }
        if c < best.clearance {
            best = Narrowest {
                clearance: c,
                at: p,
                spot,
            };
        }
    }
    Some(best)
}

/// Whether [`narrowest_of`] finds an edge's `samples` above `floor`, without finding
/// its narrowest: only the samples whose bound allows `floor` are measured, each only
/// as far as `floor`. Moves are judged by this, and most fail, so the narrowest is
/// measured only for the moves taken. (It can differ from `narrowest_of` only where a
/// sample is within a micrometre of the narrowest, which that counts as equal.)
pub(super) fn keeps_above(ctx: &CollisionContext, samples: &Samples, floor: f64) -> bool {
    let reach = floor + ctx.params().unit_radius as f64;
    for &(lb, p, _) in &samples.bounds {
        // The bound is a lower bound: from here on every sample keeps more.
        if lb > reach || lb > samples.within {
            break;
        }
        if at_or_below(ctx, lb, p, floor) {
            return false;
        }
    }
    true
}

/// Whether the unit at `p`, whose distance to the map the field bounds below by `lb`
/// (at most `floor + r_u`), keeps `floor` or less, as [`narrowest_of`] would measure
/// it: exactly, as far as the floor; near the cap, by the bound.
fn at_or_below(ctx: &CollisionContext, lb: f64, p: Point3<f64>, floor: f64) -> bool {
    let r_u = ctx.params().unit_radius as f64;
    let field = ctx.field();
    let reach = floor + r_u;
    lb - r_u >= CAP - field.grid().resolution()
        || exact_clearance_above(field, p, reach, reach + TIE).is_none()
}

/// Whether edge `e` of `steps` surely fails [`keeps_above`] at `floor`, by a look at
/// the unit of `near` alone, at the samples nearest its parameter (a pinch moves
/// little with a move, and most moves fail there). `false` decides nothing. A sample
/// found at or below the floor here is one of the edge's [`samples`], measured as
/// `keeps_above` measures it; and where `keeps_above` would stop before reaching it
/// (its bound far above the lowest), the lowest is at or below the floor too.
pub(super) fn fails_near(
    ctx: &CollisionContext,
    e: usize,
    steps: &[Step],
    near: Spot,
    floor: f64,
) -> bool {
    let edge = EdgeSamples::of(ctx, e, steps);
    let reach = floor + ctx.params().unit_radius as f64;
    let j = (near.t * edge.n as f64).round() as usize;
    (j.saturating_sub(1)..=(j + 1).min(edge.n)).any(|j| {
        let Some(&p) = edge.positions(j).get(near.unit) else {
            return false;
        };
        let lb = ctx.field().clearance_above(p, edge.cap);
        lb < edge.cap && lb <= reach && at_or_below(ctx, lb, p, floor)
    })
}

/// An edge's samples as [`samples`] takes them: `n + 1`, evenly along the edge.
struct EdgeSamples {
    kind: crate::collision::verify::EdgeKind,
    a: Vec<f64>,
    b: Vec<f64>,
    n: usize,
    link: f64,
    /// Distances at or beyond this (m) are not kept: `CAP + r_u`.
    cap: f64,
}

impl EdgeSamples {
    fn of(ctx: &CollisionContext, e: usize, steps: &[Step]) -> Self {
        let params = ctx.params();
        let link = params.link_length as f64;
        let (a, b) = (zeta(&steps[e]), zeta(&steps[e + 1]));
        let kind = classify_edge(&a, &b);
        let r_v = ctx.field().grid().resolution();
        let n = edge_intervals(kind, link, &a, &b, SAMPLE_SPACING * r_v).max(1);
        EdgeSamples {
            kind,
            a,
            b,
            n,
            link,
            cap: CAP + params.unit_radius as f64,
        }
    }

    /// The unit positions at sample `j` (of `0..=n`).
    fn positions(&self, j: usize) -> Vec<Point3<f64>> {
        let z = edge_sample(self.kind, &self.a, &self.b, j as f64 / self.n as f64);
        positions_f64(self.link, [z[0], z[1], z[2]], &z[3..])
    }
}

/// The unit positions of edge `e` of `steps` that `keep` keeps, at the samples
/// [`measure`] looks at ([`Samples`]).
pub(super) fn samples(
    ctx: &CollisionContext,
    e: usize,
    steps: &[Step],
    keep: impl Fn(&Point3<f64>) -> bool,
) -> Samples {
    let edge = EdgeSamples::of(ctx, e, steps);
    let field = ctx.field();
    let r_v = field.grid().resolution();
    let mut bounds: Vec<(f64, Point3<f64>, Spot)> = Vec::new();
    for j in 0..=edge.n {
        let t = j as f64 / edge.n as f64;
        for (unit, p) in edge.positions(j).into_iter().enumerate() {
            let lb = field.clearance_above(p, edge.cap);
            if lb < edge.cap && keep(&p) {
                bounds.push((lb, p, Spot { t, unit }));
            }
        }
    }
    bounds.sort_by(|x, y| x.0.total_cmp(&y.0));
    let within = bounds.first().map_or(0.0, |f| f.0 + r_v * 3f64.sqrt());
    Samples {
        bounds,
        within,
        start: Point3::from(steps[e].xi),
    }
}

/// Distance from `p` to the nearest obstacle cube, capped at `CAP + r_u`: as far as
/// a passage's middle matters to widening (and to `crate::planner::thread`).
pub(in crate::planner) fn distance(ctx: &CollisionContext, p: Point3<f64>) -> f64 {
    distance_below(ctx, p, CAP + ctx.params().unit_radius as f64)
}

/// Distance from `p` to the nearest obstacle cube, capped at `cap`: the distance
/// field's bound first, and the search for the nearest cube stops at `cap`.
pub(in crate::planner) fn distance_below(ctx: &CollisionContext, p: Point3<f64>, cap: f64) -> f64 {
    let f = ctx.field();
    if f.clearance_above(p, cap) >= cap {
        return cap;
    }
    exact_distance(f, p, cap).min(cap)
}

/// The gradient of [`distance`] at `p` (central differences, an eighth of a voxel).
pub(in crate::planner) fn gradient(ctx: &CollisionContext, p: Point3<f64>) -> Vector3<f64> {
    let h = ctx.field().grid().resolution() / GRADIENT_STEPS_PER_VOXEL;
    Vector3::from_fn(|i, _| {
        let mut e = Vector3::zeros();
        e[i] = h;
        (distance(ctx, p + e) - distance(ctx, p - e)) / (2.0 * h)
    })
}

/// A step's configuration `zeta` in `f64`.
pub(in crate::planner) fn zeta(s: &Step) -> Vec<f64> {
    s.xi.iter()
        .copied()
        .chain(s.shape.as_slice().iter().map(|&v| v as f64))
        .collect()
}
