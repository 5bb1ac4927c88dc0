//! Shape connection for one head edge of the online construction: the legs that
//! fly the chain from `v` to `u`, tried in order: keep the shape, turn it, a library
//! shape, follow-the-leader steps, SRSConnect; on the head route, and out of a start
//! that keeps less than the clearance, at a smaller clearance where the preferred one
//! fails.

use aerial_chain_core::lsc::LscKind;
use aerial_chain_core::Shape;
use nalgebra::Point3;

use super::candidates::{self, Candidate, Source};
use super::construction::{Construction, Leg};
use super::numeric::{DISTINCT_SHAPE, PER_MILLIMETRE, TINY, TINY_F32};
use super::roadmap::VertexId;
use super::{follow, srs_connect, Mode, Preference};
use crate::collision::CollisionContext;

impl Construction<'_> {
    /// The legs that take the chain from `v` to `u`, or None. On the head route (both
    /// ends query vertices), and from a start that keeps less than the clearance, the
    /// planner gives way to the smallest clearance when the preferred one fails.
    pub(super) fn connect(&mut self, v: VertexId, u: VertexId) -> Option<Vec<Leg>> {
        if let Some(legs) = self.connect_at(v, u) {
            return Some(legs);
        }
        let p = self.planner;
        let (c_min, c_pref) = (p.ctx_min.clearance_margin(), p.ctx.clearance_margin());
        let on_route = self.roadmap.is_query(v) && self.roadmap.is_query(u);
        // A start within the clearance cannot be left at it: an edge from there keeps
        // what the start keeps.
        let from_start = self.start_margin_at(v);
        if !(c_min < c_pref && (self.may_give_way && on_route || from_start.is_some())) {
            return None;
        }
        // Give way step by step: first to `give_way_share` of the head's own margin along the
        // edge (what the passage leaves on its narrowest side), or to what the start keeps,
        // then to the floor.
        let (a, b) = (self.roadmap.point(v), self.roadmap.point(u));
        let mid = match from_start {
            Some(m) => m,
            None => {
                let head = head_margin(&p.ctx, a, b);
                (p.settings.give_way_share * head * PER_MILLIMETRE).floor() / PER_MILLIMETRE
            }
        }
        .clamp(c_min, c_pref);
        let mut levels = vec![(mid, None)];
        if mid > c_min {
            levels.push((c_min, Some(p.ctx_min.clone())));
        }
        let mut legs = None;
        for (c, ctx) in levels {
            let ctx = match ctx {
                Some(x) => x,
                None => {
                    match CollisionContext::new(p.ctx.field_arc().clone(), *p.ctx.params(), c) {
                        Ok(mut x) => {
                            x.set_min_step(p.ctx.min_step());
                            x
                        }
                        Err(_) => continue,
                    }
                }
            };
            self.checker.ctx = ctx;
            legs = self.connect_at(v, u);
            if legs.is_some() {
                self.relaxed.push((self.steps.len(), c, a));
                break;
            }
        }
        self.checker.ctx = p.ctx.clone();
        legs
    }

    /// [`Self::connect`] at the checker's clearance.
    fn connect_at(&mut self, v: VertexId, u: VertexId) -> Option<Vec<Leg>> {
        let (a, b) = (self.roadmap.point(v), self.roadmap.point(u));
        if let Some(changes) = self.connect_rigid(a, b) {
            return Some(vec![Leg { changes, to: b }]);
        }
        if self.planner.settings.follow_step > 0.0 {
            if let Some(legs) = self.follow(a, b) {
                return Some(legs);
            }
        }
        if !self.random_shapes {
            return None;
        }
        self.connect_srs(a, b)
            .map(|changes| vec![Leg { changes, to: b }])
    }

    /// The shape change at `a` to a kept, turned or library shape that flies `a -> b`.
    fn connect_rigid(&mut self, a: [f64; 3], b: [f64; 3]) -> Option<Vec<Candidate>> {
        let s = &self.planner.settings;
        let cur = self.current;
        let edge_yaw = edge_yaw(a, b, &cur.shape);
        let lsc = &self.planner.tables.lsc;
        let use_lsc = s.mode != Mode::Srs;
        let is_pn = matches!(cur.source, Source::Lsc(LscKind::Pn));
        // Coverage: move into the polygon wherever it fits.
        if s.prefer == Preference::Coverage && use_lsc && !is_pn {
            let pn = candidates::library(&cur.shape, lsc, edge_yaw, s.n_psi, Some(LscKind::Pn));
            if let Some(c) = self.first_direct(a, b, &pn) {
                return Some(vec![c]);
            }
        }
        // (a) keep the shape.
        if self.checker.translation(a, b, &cur.shape) {
            return Some(Vec::new());
        }
        // (b) yaw rotations.
        let rot = candidates::rotations(&cur.shape, edge_yaw, s.n_psi);
        if let Some(c) = self.first_direct(a, b, &rot) {
            return Some(vec![c]);
        }
        // (c) library shapes, cheapest first.
        let lib = if use_lsc {
            candidates::library(&cur.shape, lsc, edge_yaw, s.n_psi, None)
        } else {
            Vec::new()
        };
        self.first_direct(a, b, &lib).map(|c| vec![c])
    }

    /// Follow-the-leader from `a` to `b` in steps of `follow_step`: before each step
    /// the body is laid back along the head's track ([`follow::lay_along_newest_last`]).
    fn follow(&mut self, a: [f64; 3], b: [f64; 3]) -> Option<Vec<Leg>> {
        let params = *self.planner.ctx.params();
        let len = super::dist(a, b);
        let n = ((len / self.planner.settings.follow_step).ceil() as usize).max(1);
        // Newest point last: each step appends (inserting at the front made long
        // edges quadratic).
        let mut track = self.track(a);
        track.reverse();
        let mut shape = self.current.shape;
        let mut legs = Vec::with_capacity(n.min(1024));
        let mut p = a;
        for j in 1..=n {
            let t = j as f64 / n as f64;
            let q = [0, 1, 2].map(|i| a[i] + t * (b[i] - a[i]));
            let laid = follow::lay_along_newest_last(&params, &track);
            let mut changes = Vec::new();
            if laid.max_angle_diff(&shape) > DISTINCT_SHAPE {
                let ok =
                    self.checker.config(p, &laid) && self.checker.shape_change(p, &shape, &laid);
                if !ok {
                    return None;
                }
                shape = laid;
                changes.push(Candidate {
                    shape,
                    source: Source::Follow,
                });
            }
            if !self.checker.translation(p, q, &shape) {
                return None;
            }
            legs.push(Leg { changes, to: q });
            track.push(nalgebra::Vector3::new(
                q[0] as f32,
                q[1] as f32,
                q[2] as f32,
            ));
            p = q;
        }
        Some(legs)
    }

    /// The head's track behind `a`: the head positions of the follow-the-leader steps
    /// that led here (newest first), then the body of the chain where that run of
    /// steps began. A rigid body's corners sharper than 90 degrees are cut first: a
    /// zig-zag at the bend limit (the serpentines) cannot be slid along.
    fn track(&self, a: [f64; 3]) -> Vec<nalgebra::Vector3<f32>> {
        let v = |p: Point3<f64>| nalgebra::Vector3::new(p[0] as f32, p[1] as f32, p[2] as f32);
        let params = self.planner.ctx.params();
        let mut track = vec![v(a.into())];
        let mut length = 0.0;
        // Twice the chain's reach: a winding track takes more than one reach of chords.
        let need = 2.0 * (params.reach() as f64 + 1.0);
        for st in self.steps.iter().rev() {
            if st.source == Source::Follow && length < need {
                let last = track.last().expect("track starts at a");
                let d = (v(st.xi) - last).norm();
                if d > TINY_F32 {
                    length += d as f64;
                    track.push(v(st.xi));
                }
                continue;
            }
            let body = aerial_chain_core::kinematics::offsets(params, &st.shape);
            let body: Vec<_> = body.iter().take(params.n()).map(|o| v(st.xi) + o).collect();
            if st.source == Source::Follow {
                track.extend(body);
            } else {
                track.extend(follow::cut_sharp_corners(
                    &body,
                    std::f32::consts::FRAC_PI_2,
                ));
            }
            break;
        }
        track
    }

    /// SRSConnect (d): a path through `G_Val` to a random shape that flies `a -> b`.
    fn connect_srs(&mut self, a: [f64; 3], b: [f64; 3]) -> Option<Vec<Candidate>> {
        let s = &self.planner.settings;
        if s.mode == Mode::Lsc {
            return None;
        }
        let cur = self.current;
        let edge_yaw = edge_yaw(a, b, &cur.shape);
        self.stats.srs_connects += 1;
        let srs = &self.planner.tables.srs;
        let mut pool: Vec<Candidate> = Vec::with_capacity(2 * srs.len());
        for (k, &shape) in srs.iter().enumerate() {
            pool.push(Candidate {
                shape,
                source: Source::Srs(k as u16),
            });
            // The same shape turned so that its body trails straight behind the edge.
            let turn = aerial_chain_core::angle::diff(
                self.planner.trail_yaw[k],
                edge_yaw + std::f32::consts::PI,
            );
            pool.push(Candidate {
                shape: shape.rotated(turn),
                source: Source::SrsTurned(k as u16),
            });
        }
        // G_Val holds the random shapes only, as in the paper: the library was tried in (c).
        srs_connect::connect(
            &mut self.checker,
            &mut self.srs_memo,
            a,
            b,
            &cur,
            &pool,
            &self.planner.tables.adjacency,
            s.d_c.unwrap_or_else(|| {
                aerial_chain_core::srs::default_r_s(self.planner.tables.params.units, srs.len())
            }),
        )
    }

    /// The first candidate that fits at `a`, flies `a -> b`, and is reachable from the
    /// current shape by one shape change at `a`. The change is checked before the
    /// flight: where the chain is boxed in (unknown space all round at the start of an
    /// online piece) the changes fail for most candidates, and edge after edge would
    /// sweep every one of them along the edge first (same answer either way).
    fn first_direct(&mut self, a: [f64; 3], b: [f64; 3], cands: &[Candidate]) -> Option<Candidate> {
        let cur = self.current.shape;
        cands.iter().copied().find(|c| {
            self.checker.placement(a, &c.shape)
                && self.checker.shape_change(a, &cur, &c.shape)
                && self.checker.translation(a, b, &c.shape)
        })
    }
}

/// A lower bound on the head unit's margin (distance to the map minus `r_u`) along
/// the segment `a b`, sampled every quarter voxel (m, at least 0).
fn head_margin(ctx: &CollisionContext, a: [f64; 3], b: [f64; 3]) -> f64 {
    let step = ctx.field().grid().resolution() / crate::collision::SAMPLES_PER_VOXEL;
    let n = (super::dist(a, b) / step).ceil().max(1.0) as usize;
    let r_u = ctx.params().unit_radius as f64;
    (0..=n)
        .map(|i| {
            let t = i as f64 / n as f64;
            let p = [0, 1, 2].map(|k| a[k] + t * (b[k] - a[k]));
            ctx.clearance(p) - r_u
        })
        .fold(f64::INFINITY, f64::min)
        .max(0.0)
}

/// The yaw of the edge `a -> b`; for a vertical edge, the shape's own heading.
fn edge_yaw(a: [f64; 3], b: [f64; 3], shape: &Shape) -> f32 {
    if (b[0] - a[0]).hypot(b[1] - a[1]) > TINY {
        (b[1] - a[1]).atan2(b[0] - a[0]) as f32
    } else {
        shape.head_yaw()
    }
}
