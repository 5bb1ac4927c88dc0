//! Which of a plan's edges fly together: the plan cut into *motions*, each one straight
//! move in `zeta`, and what to try when a merged motion fails the check.
//!
//! A motion runs between two *places* along the plan, a place being a real number
//! `k + f`: a share `f` of the way through edge `k`. A motion is either the plan's own
//! (one edge, or a part of a translation), a *run* (whole edges that lie nearly on one
//! line in `zeta`, `super::merge`), or a *pair*: a shape change with (a part of) the
//! translation beside it. Flown apart, a shape change keeps the chain standing for as
//! long as its largest angle needs; flown in a pair, the head moves meanwhile.
//!
//! When a merged motion fails the exact check, it gives way a step at a time: a run is
//! halved; a pair first flies the half of its translation nearer the shape change, then
//! a quarter (the motion keeps nearer the plan's corner, where the plan changes the
//! shape, and the check mostly fails there by millimetres of clearance), and where even
//! that fails, the shape change tries the translation on its other side in the same
//! steps, then flies alone. Every step leaves the merged motions shorter or fewer, so
//! the search ends.

use super::merge::{head_length, straight, Demand};
use super::Settings;
use crate::trajectory::reference::{Segment, SegmentKind};
use crate::trajectory::ReferenceLimits;

/// Which side of its shape change a pair's translation lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    /// The translation ends where the shape change starts.
    Before,
    /// The translation starts where the shape change ends.
    After,
}

impl Side {
    /// The side across the shape change.
    fn other(self) -> Self {
        match self {
            Side::Before => Side::After,
            Side::After => Side::Before,
        }
    }
}

/// What a motion is.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    /// One edge, or part of a translation, as the plan has it.
    Own,
    /// Whole edges, at least two, as one straight move.
    Run,
    /// The shape change `shape` with part of the translation on `side` of it.
    Pair {
        /// The shape change's edge.
        shape: usize,
        /// Where its translation lies.
        side: Side,
        /// How often the translation's part was halved on this side.
        shrunk: u8,
        /// Whether the other side was tried (or this is it).
        other_tried: bool,
    },
}

/// One motion: from place `start` to place `end`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Motion {
    start: f64,
    end: f64,
    kind: Kind,
}

impl Motion {
    /// Whether this is (part of) translation `t` flown as the plan has it.
    fn own_part_of(&self, t: usize) -> bool {
        self.kind == Kind::Own && self.start >= t as f64 && self.end <= (t + 1) as f64
    }
}

/// The plan's edges cut into motions, which together cover every edge once, in order.
#[derive(Clone, Debug)]
pub(super) struct Grouping {
    motions: Vec<Motion>,
    /// The tuning of runs and pairs.
    s: Settings,
}

/// The demands of motions already measured, by their places: the generator assembles
/// the motions again after every failed check, and most of them are the same.
pub(super) type Demands = std::collections::HashMap<(u64, u64), Demand>;

/// The motions assembled: each one's segment, whether it is merged (not the plan's
/// own), and its largest rate of progress.
pub(super) struct Assembled {
    pub segments: Vec<Segment>,
    pub merged: Vec<bool>,
    pub rates: Vec<f64>,
}

impl Grouping {
    /// The merges worth trying, left to right: the longest run from each edge on (a run
    /// of one edge is none; a shape change and one translation make a pair instead),
    /// else a translation and the shape change after it, or a shape change and the
    /// translation after it, as a pair; each edge in at most one motion. `on == false`:
    /// every edge alone. Tuned by `s` (runs, pieces, shrinks).
    pub(super) fn new(edges: &[Segment], l: f64, on: bool, s: &Settings) -> Self {
        let own = |k: usize| Motion {
            start: k as f64,
            end: (k + 1) as f64,
            kind: Kind::Own,
        };
        let mut g = Self {
            motions: Vec::with_capacity(edges.len()),
            s: *s,
        };
        let mut k = 0;
        while k < edges.len() {
            if !on {
                g.motions.push(own(k));
                k += 1;
                continue;
            }
            // Runs grow by whole follow-the-leader steps (a shape change and a
            // translation) where a single edge more would end half way through one.
            let mut end = k;
            while let Some(next) = [end + 2, end + 1]
                .into_iter()
                .find(|&e| e < edges.len() && e - k < s.max_run && straight(&edges[k..=e], l, s))
            {
                end = next;
            }
            // A shape change and one translation are a pair, which gives way in finer
            // steps than a run.
            let kinds = (edges[k].kind, edges.get(k + 1).map(|e| e.kind));
            let side = match kinds {
                (SegmentKind::Translation, Some(SegmentKind::ShapeChange)) => Some(Side::Before),
                (SegmentKind::ShapeChange, Some(SegmentKind::Translation)) => Some(Side::After),
                _ => None,
            };
            if end > k && (end > k + 1 || side.is_none()) {
                g.motions.push(Motion {
                    start: k as f64,
                    end: (end + 1) as f64,
                    kind: Kind::Run,
                });
                k = end + 1;
                continue;
            }
            g.motions.push(own(k));
            if let Some(side) = side {
                g.motions.push(own(k + 1));
                let shape = g.motions.len() - if side == Side::Before { 1 } else { 2 };
                g.pair(shape, side, edges);
                k += 1;
            }
            k += 1;
        }
        g
    }

    /// Pairs the shape change flown alone as motion `m` with the translation on `side`
    /// of it, where motion `m`'s neighbour there flies that translation (or what other
    /// pairs left of it) as the plan has it: with all of that part, unless it is a
    /// sliver of under `Settings::min_piece`. Whether it made the pair.
    fn pair(&mut self, m: usize, side: Side, edges: &[Segment]) -> bool {
        let shape = self.motions[m].start as usize;
        let (t, neighbour) = match side {
            Side::Before if shape > 0 && m > 0 => (shape - 1, m - 1),
            Side::After if shape + 1 < edges.len() => (shape + 1, m + 1),
            _ => return false,
        };
        let Some(&next) = self.motions.get(neighbour) else {
            return false;
        };
        if edges[t].kind != SegmentKind::Translation || !next.own_part_of(t) {
            return false;
        }
        // A whole translation however short, else no sliver.
        let share = next.end - next.start;
        if share * head_length(&edges[t].delta) < self.s.min_piece && share < 1.0 {
            return false;
        }
        let kind = Kind::Pair {
            shape,
            side,
            shrunk: 0,
            other_tried: false,
        };
        match side {
            Side::Before => {
                self.motions[m].start = next.end - share;
                self.motions[m].kind = kind;
                self.cut_neighbour(neighbour, next.start, next.end - share);
            }
            Side::After => {
                self.motions[m].end = next.start + share;
                self.motions[m].kind = kind;
                self.cut_neighbour(neighbour, next.start + share, next.end);
            }
        }
        true
    }

    /// Motion `n` (the plan's own) now runs from `start` to `end`; gone if empty.
    fn cut_neighbour(&mut self, n: usize, start: f64, end: f64) {
        if end - start > 0.0 {
            self.motions[n].start = start;
            self.motions[n].end = end;
        } else {
            self.motions.remove(n);
        }
    }

    /// The place each motion starts at.
    pub(super) fn starts(&self) -> impl Iterator<Item = f64> + '_ {
        self.motions.iter().map(|m| m.start)
    }

    /// The edges each motion flies (whole or in part), by index.
    pub(super) fn edge_spans(&self) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        self.motions
            .iter()
            .map(|m| m.start.floor() as usize..m.end.ceil() as usize)
    }

    /// The plan's corners (places where two edges meet) inside merged motions.
    pub(super) fn merged_corners(&self) -> usize {
        self.motions
            .iter()
            .filter(|m| m.kind != Kind::Own)
            .map(|m| (m.end.ceil() - m.start.floor()) as usize - 1)
            .sum()
    }

    /// Every motion as one segment (edges summed, parts of edges in proportion), with
    /// its largest rate of progress within `lim`.
    pub(super) fn assemble(
        &self,
        edges: &[Segment],
        demands: &mut Demands,
        lim: &ReferenceLimits,
        l: f64,
    ) -> Assembled {
        let mut out = Assembled {
            segments: Vec::with_capacity(self.motions.len()),
            merged: Vec::with_capacity(self.motions.len()),
            rates: Vec::with_capacity(self.motions.len()),
        };
        for m in &self.motions {
            let e = segment(edges, m.start, m.end);
            let key = (m.start.to_bits(), m.end.to_bits());
            let demand = *demands.entry(key).or_insert_with(|| Demand::of(&e, l));
            out.segments.push(e);
            out.merged.push(m.kind != Kind::Own);
            out.rates.push(demand.max_rate(lim));
        }
        out
    }

    /// Gives way where merged motion `m` failed the check: a run is halved, a pair
    /// flies half as much of its translation, or comes apart and tries the other side.
    /// False where motion `m` is the plan's own (nothing to undo).
    pub(super) fn undo(&mut self, m: usize, edges: &[Segment]) -> bool {
        let motion = self.motions[m];
        match motion.kind {
            Kind::Own => false,
            Kind::Run => {
                let (first, last) = (motion.start as usize, motion.end as usize - 1);
                let mid = (first + (last - first).div_ceil(2)) as f64;
                let kind = |a: f64, b: f64| if b - a > 1.0 { Kind::Run } else { Kind::Own };
                self.motions[m] = Motion {
                    start: motion.start,
                    end: mid,
                    kind: kind(motion.start, mid),
                };
                let back = Motion {
                    start: mid,
                    end: motion.end,
                    kind: kind(mid, motion.end),
                };
                self.motions.insert(m + 1, back);
                true
            }
            Kind::Pair {
                shape,
                side,
                shrunk,
                other_tried,
            } => {
                let (t, piece) = match side {
                    Side::Before => (shape - 1, shape as f64 - motion.start),
                    Side::After => (shape + 1, motion.end - (shape + 1) as f64),
                };
                let half = piece / 2.0;
                if shrunk < self.s.shrinks
                    && half * head_length(&edges[t].delta) >= self.s.min_piece
                {
                    let place = match side {
                        Side::Before => motion.start + half,
                        Side::After => motion.end - half,
                    };
                    self.give_back(m, side, place);
                    let at = self.find(shape);
                    if let Kind::Pair { shrunk, .. } = &mut self.motions[at].kind {
                        *shrunk += 1;
                    }
                    return true;
                }
                let whole = match side {
                    Side::Before => shape as f64,
                    Side::After => (shape + 1) as f64,
                };
                self.give_back(m, side, whole);
                let at = self.find(shape);
                if !other_tried && self.pair(at, side.other(), edges) {
                    if let Kind::Pair { other_tried, .. } = &mut self.motions[at].kind {
                        *other_tried = true;
                    }
                }
                true
            }
        }
    }

    /// The index of the motion that holds shape change `shape`.
    fn find(&self, shape: usize) -> usize {
        let at = shape as f64;
        self.motions
            .iter()
            .position(|m| m.start <= at && at < m.end)
            .expect("the motions cover every edge")
    }

    /// Pair `m` gives its translation back to the plan up to `place` (all of it where
    /// `place` is the shape change's end: the shape change is left alone): to the
    /// neighbouring motion where that flies the rest of the same translation as the plan
    /// has it, else as a motion of its own.
    fn give_back(&mut self, m: usize, side: Side, place: f64) {
        let motion = self.motions[m];
        let Kind::Pair { shape, .. } = motion.kind else {
            return;
        };
        match side {
            Side::Before => {
                let (from, to) = (motion.start, place);
                let joins = m > 0 && self.motions[m - 1].own_part_of(shape - 1);
                self.motions[m].start = to;
                if to >= shape as f64 {
                    self.motions[m].kind = Kind::Own;
                }
                if joins {
                    self.motions[m - 1].end = to;
                } else {
                    let piece = Motion {
                        start: from,
                        end: to,
                        kind: Kind::Own,
                    };
                    self.motions.insert(m, piece);
                }
            }
            Side::After => {
                let (from, to) = (place, motion.end);
                let joins = self
                    .motions
                    .get(m + 1)
                    .is_some_and(|n| n.own_part_of(shape + 1));
                self.motions[m].end = from;
                if from <= (shape + 1) as f64 {
                    self.motions[m].kind = Kind::Own;
                }
                if joins {
                    self.motions[m + 1].start = from;
                } else {
                    let piece = Motion {
                        start: from,
                        end: to,
                        kind: Kind::Own,
                    };
                    self.motions.insert(m + 1, piece);
                }
            }
        }
    }
}

/// The straight move from place `start` to place `end` along `edges`: the plan's
/// configuration at `start`, and the sum of the edges' changes in between (each edge in
/// the share the places cut from it).
fn segment(edges: &[Segment], start: f64, end: f64) -> Segment {
    let first = start.floor() as usize;
    let last = (end.ceil() as usize).max(first + 1) - 1;
    let mut e = edges[first].clone();
    let lead = start - first as f64;
    e.from
        .iter_mut()
        .zip(&edges[first].delta)
        .for_each(|(a, d)| *a += lead * d);
    e.delta.iter_mut().for_each(|d| *d = 0.0);
    let mut moves_shape = false;
    for (k, edge) in edges.iter().enumerate().take(last + 1).skip(first) {
        let lo = (start - k as f64).max(0.0);
        let hi = (end - k as f64).min(1.0);
        e.delta
            .iter_mut()
            .zip(&edge.delta)
            .for_each(|(a, d)| *a += (hi - lo) * d);
        moves_shape |= edge.kind == SegmentKind::ShapeChange;
        e.to_waypoint = edge.to_waypoint;
    }
    if moves_shape {
        e.kind = SegmentKind::ShapeChange;
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A step of a straight chain of 4 units: its head along x or y (m), or a turn of
    /// the chain about its head (rad).
    #[derive(Clone, Copy, Debug)]
    enum Step {
        X(f64),
        Y(f64),
        Turn(f64),
    }
    use Step::{Turn, X, Y};

    /// The edges of the waypoints `steps` reach from the head at `(0, 0, 1)`, yaw 0.
    fn walk(steps: &[Step]) -> Vec<Segment> {
        let (mut h, mut yaw) = ([0.0, 0.0, 1.0], 0.0);
        let mut w = vec![zeta(h, yaw)];
        for step in steps {
            match *step {
                X(d) => h[0] += d,
                Y(d) => h[1] += d,
                Turn(d) => yaw += d,
            }
            w.push(zeta(h, yaw));
        }
        let lim = ReferenceLimits {
            start_hold: 0.0,
            ..Default::default()
        };
        crate::trajectory::reference::Reference::new(4, 0.5, &w, &lim)
            .unwrap()
            .segments()
            .to_vec()
    }

    /// `zeta` of the straight chain of 4 units with its head at `h` and yaw `yaw`.
    fn zeta(h: [f64; 3], yaw: f64) -> Vec<f64> {
        let mut z = h.to_vec();
        z.push(yaw);
        for _ in 0..3 {
            z.extend([0.0, yaw]);
        }
        z
    }

    /// The edges of a chain of links of 0.5 m grouped, merging on.
    fn grouped(e: &[Segment]) -> Grouping {
        Grouping::new(e, 0.5, true, &Settings::default())
    }

    fn places(g: &Grouping) -> Vec<(f64, f64, bool)> {
        g.motions
            .iter()
            .map(|m| (m.start, m.end, m.kind != Kind::Own))
            .collect()
    }

    /// Motions cover the edges in order, each from where the one before ends.
    fn covers(g: &Grouping, edges: usize) {
        assert_eq!(g.motions[0].start, 0.0);
        assert_eq!(g.motions.last().unwrap().end, edges as f64);
        for w in g.motions.windows(2) {
            assert_eq!(w[0].end, w[1].start, "{:?}", g.motions);
            assert!(w[0].start < w[0].end);
        }
    }

    #[test]
    fn runs_join_what_lies_on_a_line_and_stop_at_corners() {
        // Three translations along x, then one along y: the first three are one run.
        let e = walk(&[X(0.1), X(0.1), X(0.1), Y(0.1)]);
        let g = grouped(&e);
        assert_eq!(places(&g), [(0.0, 3.0, true), (3.0, 4.0, false)]);
        let off = Grouping::new(&e, 0.5, false, &Settings::default());
        assert_eq!(off.merged_corners(), 0);
        assert_eq!(g.merged_corners(), 2);
        // Halved: the first edge alone, then the other two; then those apart.
        let mut g = g;
        assert!(g.undo(0, &e));
        assert_eq!(
            places(&g),
            [(0.0, 1.0, false), (1.0, 3.0, true), (3.0, 4.0, false)]
        );
        assert!(g.undo(1, &e));
        assert_eq!(g.merged_corners(), 0);
        assert!(!g.undo(1, &e), "nothing left to undo");
        covers(&g, 4);
        // A small turn of the chain between two translations along its axis: the
        // straight move would swing the tail 1.5 * 0.1 rad off at the waypoint between,
        // past even a short step's tolerance, so only the pair (translation, turn) is
        // merged.
        let e = walk(&[X(0.1), Turn(0.1), X(0.1)]);
        let g = grouped(&e);
        assert_eq!(places(&g), [(0.0, 2.0, true), (2.0, 3.0, false)]);
    }

    #[test]
    fn a_pair_flies_less_of_its_translation_then_the_other_one_then_comes_apart() {
        // 2 m along x, a turn of the chain by 0.4 rad, 2 m along x again.
        let e = walk(&[X(2.0), Turn(0.4), X(2.0)]);
        let mut g = grouped(&e);
        covers(&g, 3);
        assert_eq!(places(&g), [(0.0, 2.0, true), (2.0, 3.0, false)]);
        assert_eq!(g.merged_corners(), 1);
        let lim = ReferenceLimits::default();
        let segs = g.assemble(&e, &mut Demands::new(), &lim, 0.5);
        assert_eq!(segs.merged, [true, false]);
        assert_eq!(segs.segments[0].kind, SegmentKind::ShapeChange);
        assert!((segs.segments[0].delta[0] - 2.0).abs() < 1e-12);
        assert!((segs.segments[0].delta[3] - 0.4).abs() < 1e-12);
        // Fails: the last metre of the translation, then the last half metre.
        assert!(g.undo(0, &e));
        covers(&g, 3);
        assert_eq!(places(&g)[..2], [(0.0, 0.5, false), (0.5, 2.0, true)]);
        let segs = g.assemble(&e, &mut Demands::new(), &lim, 0.5);
        assert!((segs.segments[1].from[0] - 1.0).abs() < 1e-12);
        assert!((segs.segments[1].delta[0] - 1.0).abs() < 1e-12);
        assert!(g.undo(1, &e));
        assert_eq!(places(&g)[..2], [(0.0, 0.75, false), (0.75, 2.0, true)]);
        // Fails again: the translation before is whole again, and the shape change
        // takes the one after, in the same steps.
        assert!(g.undo(1, &e));
        covers(&g, 3);
        assert_eq!(places(&g), [(0.0, 1.0, false), (1.0, 3.0, true)]);
        assert!(g.undo(1, &e));
        assert_eq!(
            places(&g),
            [(0.0, 1.0, false), (1.0, 2.5, true), (2.5, 3.0, false)]
        );
        assert!(g.undo(1, &e));
        assert!(g.undo(1, &e));
        covers(&g, 3);
        assert_eq!(
            places(&g),
            [(0.0, 1.0, false), (1.0, 2.0, false), (2.0, 3.0, false)]
        );
        assert_eq!(g.merged_corners(), 0);
        assert!(!g.undo(1, &e), "nothing left to undo");
    }

    #[test]
    fn no_pair_is_shrunk_to_a_sliver() {
        // 0.3 m, then a turn: the pair flies 0.15 m, then comes apart (0.075 m would be
        // under the shortest piece); nothing after the turn to pair with.
        let e = walk(&[X(0.3), Turn(0.4)]);
        let mut g = grouped(&e);
        assert_eq!(places(&g), [(0.0, 2.0, true)]);
        assert!(g.undo(0, &e));
        assert_eq!(places(&g), [(0.0, 0.5, false), (0.5, 2.0, true)]);
        assert!(g.undo(1, &e));
        assert_eq!(places(&g), [(0.0, 1.0, false), (1.0, 2.0, false)]);
    }

    #[test]
    fn a_short_translation_is_taken_whole_and_blocks_nothing_else() {
        // 0.2 m, a turn, 0.2 m, a turn back: each turn takes the translation before it.
        let e = walk(&[X(0.2), Turn(0.4), X(0.2), Turn(-0.4)]);
        let g = grouped(&e);
        covers(&g, 4);
        assert_eq!(places(&g), [(0.0, 2.0, true), (2.0, 4.0, true)]);
        assert_eq!(g.merged_corners(), 2);
    }

    proptest::proptest! {
        /// Whatever fails, in any order: the motions keep covering every edge once,
        /// in order, none empty; no motion's part of a translation is a sliver; and
        /// the search ends, every motion at last the plan's own.
        #[test]
        fn giving_way_keeps_the_cover_and_ends(
            kinds in proptest::collection::vec((0u8..3, 0.05f64..3.0), 1..24),
            picks in proptest::collection::vec(0usize..1000, 0..400),
        ) {
            let steps: Vec<Step> = kinds
                .iter()
                .map(|&(kind, size)| match kind {
                    0 => X(size),
                    1 => Turn(size / 4.0),
                    _ => Y(size),
                })
                .collect();
            let e = walk(&steps);
            let mut g = grouped(&e);
            covers(&g, e.len());
            let corners = e.len() - 1;
            let mut undone = 0;
            for pick in picks.iter().chain(std::iter::repeat(&0)) {
                let merged: Vec<usize> = (0..g.motions.len())
                    .filter(|&m| g.motions[m].kind != Kind::Own)
                    .collect();
                if merged.is_empty() {
                    break;
                }
                proptest::prop_assert!(g.undo(merged[pick % merged.len()], &e));
                undone += 1;
                proptest::prop_assert!(undone <= 8 * e.len(), "no end in sight");
                covers(&g, e.len());
                proptest::prop_assert!(g.merged_corners() <= corners);
                for m in &g.motions {
                    let k = m.start.floor() as usize;
                    let part = m.end.min((k + 1) as f64) - m.start;
                    let piece = part * head_length(&e[k].delta);
                    let whole = part == 1.0 || m.start.fract() == 0.0 && m.end.fract() == 0.0;
                    proptest::prop_assert!(whole || piece >= Settings::default().min_piece - 1e-9,
                        "a sliver of {piece} m: {:?}", g.motions);
                }
            }
            proptest::prop_assert_eq!(g.merged_corners(), 0);
        }
    }
}
