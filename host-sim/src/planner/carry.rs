//! Carrying: a stretch of the plan flown in one library shape, where that moves the
//! angles less than the plan does there.
//!
//! The search gives every head edge the cheapest shape that passes it, and the later
//! stages only shorten the changes between those shapes along the search's own head
//! route. In a maze of bays and U-turns that route hugs wall ends, and the chain
//! bends and unbends around every one. A compact library shape (the serpentine folded
//! in the vertical plane, SV, is 1.25 m long and 0.3 m wide at N = 6) may instead fly
//! the stretch rigidly, on a head route of its own that keeps its body clear of the
//! bays' walls and the gaps' ends: one change into it, one back (none at the goal).
//!
//! The numbers below are the defaults of `CarrySettings` (docs/settings.md).
//!
//! Every library shape at eight headings, the start's head yaw held
//! (`super::shorten`), is a candidate. For each:
//! 1. **Span.** The first waypoint `i` where the chain can change into it, and the
//!    last `j` after `i` where it can change back to the plan's shape (or the goal),
//!    such that flying it from `i` to `j` would move the angles less than the plan
//!    does there.
//! 2. **Fit.** Along the plan's head route from `i` to `j` (every 0.3 m, tightest
//!    first), the chain in that shape must fit with some unit within a map resolution
//!    of the route: a carried body passes every passage the head passed. Where it
//!    does not fit along an edge, the plan is split there and each side gets its own
//!    span (1 and 2 again, within that side). Most candidates are turned away here,
//!    before any search.
//!
//! Then, largest saving first, within fixed budgets of placements:
//!
//! 3. **Search.** An A* over head positions on a lattice (spacing: twice the map's
//!    resolution) from `i`'s head to `j`'s, through positions where the chain in that
//!    shape is clear, and the step to them passes the translation check (a step past a
//!    corner can clip it between two clear positions, and the taut path below is made
//!    of the search's own checks). It is guided by the plan's route,
//!    shifted so that the shape's middle follows it, and keeps within 1 m of it.
//!    Candidates whose search found no way at all on that lattice are searched again
//!    at the map's resolution, after every candidate has been tried on the coarse one.
//! 4. **Taut.** The lattice path is pulled taut by the planner's translation checks,
//!    which are what makes the result admissible (the lattice only guides). A path
//!    more than 25 % (plus 1 m) longer than the route it replaces is refused: a long
//!    detour costs more flight than the changes it saves.
//!
//! Every candidate that passes is taken, unless its span overlaps one taken before: a
//! long route is carried stretch by stretch. Every check counts towards fixed budgets,
//! not time, so the result is deterministic.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};
use std::hash::BuildHasherDefault;
use std::ops::Range;

use aerial_chain_core::kinematics::offsets;
use aerial_chain_core::lsc::{LscEntry, LscKind};
use aerial_chain_core::Shape;
use nalgebra::{Point3, Vector3};

use super::candidates::{headings, Source};
use super::lattice::{offsets26, KeyHasher};
use super::numeric::{SAME_HEADING, TIE};
use super::plan_ops::{differs, farthest, head_route, shape_motion, Quality};
use super::{CarrySettings, Checker, Step};
use crate::collision::CollisionContext;

/// Costs of the search are kept in micrometres, so that its heap orders integers: an
/// encoding, not tuning (a micrometre is far below any step of the lattice).
const PER_MICROMETRE: f64 = 1e6;

/// The search tries the goal once it is within this many lattice spacings: derived,
/// one diagonal step of the lattice (`sqrt 2` spacings, rounded up to a half), so that
/// a search that reaches the goal's cell by any in-plane step tries it.
const GOAL_REACH: f64 = 1.5;

/// A stretch of a plan flown in one library shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Carried {
    /// The library shape.
    pub kind: LscKind,
    /// Length of the head's path flown in it (m).
    pub head_path_m: f64,
}

/// A candidate: flying shape `x` (library kind `kind`) from waypoint `i` to `j` would
/// save `saving` rad of shape motion.
#[derive(Clone, Copy)]
struct Takeover {
    saving: f64,
    i: usize,
    j: usize,
    x: Shape,
    kind: LscKind,
}

/// The plan `steps` with stretches of it flown in one library shape each, where that
/// moves the angles less (see the module docs), and those stretches in the order they
/// were found; checks by `checker`. The placements its searches make are added to
/// `spent` (at most `CarrySettings::total_points`).
pub(super) fn carried(
    checker: &mut Checker,
    library: &[LscEntry],
    steps: &[Step],
    s: &CarrySettings,
    spent: &mut usize,
) -> Option<(Vec<Step>, Vec<Carried>)> {
    if Quality::of(steps).shape_changes < s.min_changes {
        return None;
    }
    let mut tried = takeovers(checker, library, steps, s);
    // Stretches taken: their spans, paths and what they carried.
    let mut taken: Vec<(Takeover, Vec<Point3<f64>>, Carried)> = Vec::new();
    // The coarse lattice first; where it found no way at all (rather than running out
    // of placements), the fine one may pass a spot the coarse one steps over.
    let r_v = checker.ctx.field().grid().resolution();
    let start = *spent;
    for spacing in s.spacings {
        let mut closed = Vec::new();
        for t in tried {
            // A span that overlaps a stretch taken would undo part of it.
            if taken.iter().any(|(o, ..)| t.i <= o.j && o.i <= t.j) {
                continue;
            }
            if *spent - start >= s.total_points {
                break;
            }
            let route = head_route(&steps[t.i..=t.j]);
            let guide = Guide::new(&route, middle(checker, &t.x), s.tube);
            let budget = s.search_points.min(s.total_points - (*spent - start));
            let (found, used) = search(checker, &guide, &t.x, spacing * r_v, budget, s.greed);
            *spent += used;
            let path = match found {
                Found::Path(path) => path,
                Found::Closed => {
                    closed.push(t);
                    continue;
                }
                Found::OutOfBudget => continue,
            };
            let Some(path) = taut(checker, &path, &t.x) else {
                continue;
            };
            let length =
                |p: &[Point3<f64>]| p.windows(2).map(|w| (w[1] - w[0]).norm()).sum::<f64>();
            let head_path_m = length(&path);
            if head_path_m > s.detour_m + s.detour_share * length(&route) {
                continue;
            }
            let carried = Carried {
                kind: t.kind,
                head_path_m,
            };
            taken.push((t, path, carried));
        }
        tried = closed;
    }
    if taken.is_empty() {
        return None;
    }
    let stretches = taken.iter().map(|(.., c)| *c).collect();
    // Spliced from the plan's end, so that the spans still to splice keep their
    // indices (they are disjoint).
    taken.sort_by_key(|(t, ..)| Reverse(t.i));
    let mut plan = steps.to_vec();
    for (t, path, _) in &taken {
        plan = splice(&plan, t.i, t.j, path, t.x, Source::Lsc(t.kind));
    }
    Some((plan, stretches))
}

/// Every library shape that could take over somewhere in the plan and fits along the
/// route there, the largest saving first. Where a shape does not fit along some edge
/// of its span (a passage only other shapes pass), the plan is split at that edge and
/// each side gets a span of its own: on a long route a shape may carry every stretch
/// between the passages it cannot take.
fn takeovers(
    checker: &mut Checker,
    library: &[LscEntry],
    steps: &[Step],
    s: &CarrySettings,
) -> Vec<Takeover> {
    // Shape motion of the plan up to each waypoint.
    let mut upto = vec![0.0; steps.len()];
    for k in 1..steps.len() {
        upto[k] = upto[k - 1] + shape_motion(&steps[k - 1].shape, &steps[k].shape);
    }
    let samples = RouteSamples::along(&checker.ctx, steps);
    let mut out = Vec::new();
    for (x, kind) in shapes(library, &steps[0].shape, s.headings) {
        // Ranges of waypoints still to look at, the plan's start first.
        let mut ranges = vec![(0, steps.len() - 1)];
        while let Some((from, to)) = ranges.pop() {
            let Some((i, j, saving)) = span(checker, steps, &upto, &x, s.saving, from, to) else {
                continue;
            };
            match misfit(checker, &samples, i..j, &x, s.fit_spacing) {
                None => out.push(Takeover {
                    saving,
                    i,
                    j,
                    x,
                    kind,
                }),
                // Edge `k` of the span is where it does not fit: what lies after it,
                // then what lies before it (popped first).
                Some(k) => {
                    ranges.push((k + 1, j));
                    ranges.push((i, k));
                }
            }
        }
    }
    // Stable: equal savings keep the order of `shapes`.
    out.sort_by(|a, b| b.saving.total_cmp(&a.saving));
    out
}

/// Where shape `x` can take over from the plan: the first waypoint `i` at which the
/// chain can change into it, and the last `j` after it at which it can change back
/// to the plan's shape (or the goal), if flying `x` from `i` to `j` would save motion;
/// both within waypoints `from..=to`.
fn span(
    checker: &mut Checker,
    steps: &[Step],
    upto: &[f64],
    x: &Shape,
    saving: f64,
    from: usize,
    to: usize,
) -> Option<(usize, usize, f64)> {
    let last = steps.len() - 1;
    let into = |k: usize| shape_motion(&steps[k].shape, x);
    let back = |k: usize| {
        if k == last {
            0.0
        } else {
            shape_motion(x, &steps[k].shape)
        }
    };
    // A change at `i` can only pay where the rest of the plan moves more than it.
    let i = (from..to).find(|&i| {
        into(i) + saving < upto[last] - upto[i]
            && checker.placement(steps[i].xi, x)
            && checker.shape_change(steps[i].xi, &steps[i].shape, x)
    })?;
    let j = (i + 1..=to).rev().find(|&j| {
        into(i) + back(j) + saving < upto[j] - upto[i]
            && checker.placement(steps[j].xi, x)
            && (j == last || checker.shape_change(steps[j].xi, x, &steps[j].shape))
    })?;
    Some((i, j, upto[j] - upto[i] - into(i) - back(j)))
}

/// The plan with waypoints `i..=j` replaced by: the change into `x` at `i`, the
/// translations of `path` (from `i`'s head position to `j`'s), and the change back to
/// the plan's shape at `j` (none at the goal).
fn splice(
    steps: &[Step],
    i: usize,
    j: usize,
    path: &[Point3<f64>],
    x: Shape,
    source: Source,
) -> Vec<Step> {
    let mut out = steps[..=i].to_vec();
    let step = |xi, shape_change| Step {
        xi,
        shape: x,
        source,
        shape_change,
    };
    if differs(&steps[i].shape, &x) {
        out.push(step(path[0], true));
    }
    out.extend(path[1..].iter().map(|&xi| step(xi, false)));
    if j + 1 < steps.len() {
        if differs(&x, &steps[j].shape) {
            out.push(Step {
                shape_change: true,
                ..steps[j]
            });
        }
        out.extend_from_slice(&steps[j + 1..]);
    }
    out
}

/// The library's shapes at every heading, the start's head yaw held, least motion
/// from `start` first (ties keep the library's order), each once.
/// (`headings` per shape).
fn shapes(library: &[LscEntry], start: &Shape, headings_per_shape: usize) -> Vec<(Shape, LscKind)> {
    let mut out: Vec<(f64, Shape, LscKind)> = Vec::new();
    for e in library {
        for h in headings(0.0, headings_per_shape) {
            let mut x = e
                .shape
                .rotated(aerial_chain_core::angle::diff(e.shape.head_yaw(), h));
            x.set_head_yaw(start.head_yaw());
            let same = out.iter().any(|o| o.1.max_angle_diff(&x) <= SAME_HEADING);
            if !same {
                out.push((shape_motion(start, &x), x, e.kind));
            }
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out.into_iter().map(|(_, x, s)| (x, s)).collect()
}

/// The middle of the shape's bounding box, from the head (m).
fn middle(checker: &Checker, x: &Shape) -> Vector3<f64> {
    let p = offsets(checker.ctx.params(), x);
    let (mut lo, mut hi) = (Vector3::repeat(f64::MAX), Vector3::repeat(f64::MIN));
    for q in p.iter().take(x.units()) {
        let q = q.cast::<f64>();
        lo = lo.inf(&q);
        hi = hi.sup(&q);
    }
    (lo + hi) / 2.0
}

/// The plan's head route sampled every map resolution, each sample with the head's
/// clearance there and its edge (`k`: from `steps[k]` to `steps[k + 1]`), the tightest
/// first (ties in route order). Made once per plan: every shape and every span reads
/// its own edges from it.
struct RouteSamples(Vec<(f64, Point3<f64>, usize)>);

impl RouteSamples {
    fn along(ctx: &CollisionContext, steps: &[Step]) -> Self {
        let r_v = ctx.field().grid().resolution();
        let mut samples = Vec::new();
        for (k, w) in steps.windows(2).enumerate() {
            let (a, b) = (w[0].xi, w[1].xi);
            if (b - a).norm() <= TIE {
                continue;
            }
            let n = ((b - a).norm() / r_v).ceil().max(1.0) as usize;
            for m in 0..n {
                let p = a + (b - a) * (m as f64 / n as f64);
                samples.push((ctx.clearance(p), p, k));
            }
        }
        // Stable: equal clearances keep the route's order.
        samples.sort_by(|a, b| a.0.total_cmp(&b.0));
        Self(samples)
    }
}

/// Where the chain in shape `x` cannot be along the plan's head route on `edges`,
/// tested at `samples` `fit_spacing` (m) apart (the tightest, where the head is
/// nearest the map, first): the edge of the first point at which no unit can be at
/// the point or one map resolution from it along or across the axes with the rest of
/// the body clear; `None` where it fits everywhere. A carried chain takes its body
/// through every passage the route takes its head through; this turns away, before
/// any search, a shape that is too wide for one.
fn misfit(
    checker: &mut Checker,
    samples: &RouteSamples,
    edges: Range<usize>,
    x: &Shape,
    fit_spacing: f64,
) -> Option<usize> {
    let r_v = checker.ctx.field().grid().resolution();
    let units = offsets(checker.ctx.params(), x);
    let mut tested: Vec<Point3<f64>> = Vec::new();
    for &(_, p, k) in samples.0.iter().filter(|s| edges.contains(&s.2)) {
        if tested.iter().any(|t| (t - p).norm() < fit_spacing) {
            continue;
        }
        tested.push(p);
        let fits = units.iter().take(x.units()).any(|u| {
            let head = p - u.cast::<f64>();
            std::iter::once([0; 3])
                .chain(offsets26())
                .map(|o| Vector3::new(o[0] as f64, o[1] as f64, o[2] as f64) * r_v)
                .any(|d| checker.placement(head + d, x))
        });
        if !fits {
            return Some(k);
        }
    }
    None
}

/// The plan's head route with the shape's middle on it: the start and the goal stay
/// (the head must be there), every point between is shifted by `-centre`.
struct Guide {
    points: Vec<Point3<f64>>,
    /// Length of the guide from each point to its end.
    rest: Vec<f64>,
    /// The search keeps within this distance (m) of the guide.
    tube: f64,
}

impl Guide {
    fn new(route: &[Point3<f64>], centre: Vector3<f64>, tube: f64) -> Self {
        let last = route.len() - 1;
        let points: Vec<Point3<f64>> = route
            .iter()
            .enumerate()
            .map(|(k, &p)| if k == 0 || k == last { p } else { p - centre })
            .collect();
        let mut rest = vec![0.0; points.len()];
        for k in (0..last).rev() {
            rest[k] = rest[k + 1] + (points[k + 1] - points[k]).norm();
        }
        Self { points, rest, tube }
    }

    fn goal(&self) -> Point3<f64> {
        self.points[self.points.len() - 1]
    }

    /// Estimated way left from `p`: to the nearest point of the guide, then along the
    /// guide to its end; `None` beyond its tube from the guide.
    fn estimate(&self, p: &Point3<f64>) -> Option<f64> {
        // (distance to the guide, way left from there)
        let mut best = ((self.goal() - p).norm(), 0.0);
        for (k, w) in self.points.windows(2).enumerate() {
            let d = w[1] - w[0];
            let len2 = d.norm_squared();
            let t = if len2 > 0.0 {
                ((p - w[0]).dot(&d) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let near = (w[0] + d * t - p).norm();
            if near < best.0 {
                best = (near, self.rest[k + 1] + (1.0 - t) * len2.sqrt());
            }
        }
        (best.0 <= self.tube).then_some(best.0 + best.1)
    }
}

/// How a search ended.
enum Found {
    /// A path of lattice points, from the start to the goal.
    Path(Vec<Point3<f64>>),
    /// Every lattice point the search could reach was expanded: no way on this lattice.
    Closed,
    /// The search ran out of placements.
    OutOfBudget,
}

/// What the search knows of one lattice point.
struct Point {
    /// Cost of the best way found to it (micrometres).
    g: u64,
    /// The guide's estimate from it, weighted (micrometres).
    estimate: u64,
    /// Where the best way came from.
    from: [i32; 3],
    /// Whether the chain is clear there (`None`: not checked yet).
    clear: Option<bool>,
    /// Expanded.
    done: bool,
}

/// A lattice index packed into one key (21 bits per axis).
fn pack(k: [i32; 3]) -> u64 {
    const OFF: i64 = 1 << 20;
    let f = |v: i32| ((v as i64 + OFF) as u64) & 0x1F_FFFF;
    (f(k[0]) << 42) | (f(k[1]) << 21) | f(k[2])
}

/// An A* over head positions `start + h k` (k in Z^3, 26 neighbours) at which the chain
/// in shape `x` is clear, from the start to a point from which the goal is one
/// translation away: how it ended (a path includes the start and the goal), and the
/// placements checked.
/// Points are checked when they are reached, not when they are first seen, so the
/// work follows the search's front rather than its whole frontier.
fn search(
    checker: &mut Checker,
    guide: &Guide,
    x: &Shape,
    h: f64,
    budget: usize,
    greed: f64,
) -> (Found, usize) {
    let origin = guide.points[0];
    let goal = guide.goal();
    let at = |k: [i32; 3]| origin + Vector3::new(k[0] as f64, k[1] as f64, k[2] as f64) * h;
    // Costs in micrometres, so that the heap orders integers.
    let scale = PER_MICROMETRE;
    let mut points: HashMap<u64, Point, BuildHasherDefault<KeyHasher>> = HashMap::default();
    let mut open = BinaryHeap::new();
    let start = Point {
        g: 0,
        estimate: 0,
        from: [0; 3],
        clear: Some(true),
        done: false,
    };
    points.insert(pack([0; 3]), start);
    open.push(Reverse((0u64, 0u64, [0i32; 3])));
    let mut checked = 0;
    while let Some(Reverse((_, g, k))) = open.pop() {
        let pt = points.get_mut(&pack(k)).expect("pushed points are known");
        if pt.done || pt.g < g {
            continue;
        }
        let p = at(k);
        let from = pt.from;
        if pt.clear.is_none() {
            if checked >= budget {
                return (Found::OutOfBudget, checked);
            }
            checked += 1;
            pt.clear = Some(checker.placement(p, x));
        }
        if pt.clear == Some(false) {
            continue;
        }
        if k != [0; 3] {
            // A step past an obstacle's corner can clip it between two clear points:
            // the step itself must pass (another step may reach the point).
            checked += 1;
            if !checker.translation(at(from), p, x) {
                pt.g = u64::MAX;
                continue;
            }
        }
        pt.done = true;
        if (goal - p).norm() <= GOAL_REACH * h && checker.translation(p, goal, x) {
            let mut path = vec![goal, p];
            let mut c = k;
            while c != [0; 3] {
                c = points[&pack(c)].from;
                path.push(at(c));
            }
            path.reverse();
            return (Found::Path(path), checked);
        }
        for n in neighbours(k) {
            let step = ((n[0] - k[0]).abs() + (n[1] - k[1]).abs() + (n[2] - k[2]).abs()) as f64;
            let cost = g + (step.sqrt() * h * scale) as u64;
            let pt = points.entry(pack(n)).or_insert_with(|| {
                let estimate = guide.estimate(&at(n));
                Point {
                    g: u64::MAX,
                    estimate: estimate.map_or(0, |e| (greed * e * scale) as u64),
                    from: k,
                    // Beyond the tube round the guide: left alone, as if blocked.
                    clear: estimate.is_none().then_some(false),
                    done: false,
                }
            });
            if pt.done || pt.clear == Some(false) || pt.g <= cost {
                continue;
            }
            pt.g = cost;
            pt.from = k;
            open.push(Reverse((cost + pt.estimate, cost, n)));
        }
    }
    (Found::Closed, checked)
}

/// The 26 lattice neighbours of `k`.
fn neighbours(k: [i32; 3]) -> impl Iterator<Item = [i32; 3]> {
    offsets26()
        .into_iter()
        .map(move |o| [0, 1, 2].map(|a| k[a] + o[a] as i32))
}

/// The path pulled taut: from each point, straight to the farthest later one the
/// chain in shape `x` can translate to; `None` where a step of the path itself fails.
fn taut(checker: &mut Checker, path: &[Point3<f64>], x: &Shape) -> Option<Vec<Point3<f64>>> {
    let mut out = vec![path[0]];
    let mut i = 0;
    let last = path.len() - 1;
    while i < last {
        i = farthest(i, last, |j| checker.translation(path[i], path[j], x))?;
        out.push(path[i]);
    }
    Some(out)
}

#[cfg(test)]
#[path = "carry_tests.rs"]
mod tests;
