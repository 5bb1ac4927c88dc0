//! Exact verification of a plan against a map (docs/model.md "Motion between two
//! configurations"), independent of the distance field.
//!
//! Each edge is classified by which part of `zeta` changed (within 1e-9, angles compared
//! after wrapping): a translation, a shape change, nothing (allowed), or both (invalid).
//! It is then sampled so that no unit centre and no point of any link moves more than
//! `r_v / 4` between consecutive samples: on a translation every point moves as far as
//! the head; on a shape change a link direction moves on the unit sphere at most
//! `sqrt(dtheta^2 + dpsi^2)` per unit of the edge parameter (the partial derivatives of
//! the direction are orthogonal, of lengths 1 and `cos theta`), so the last unit, the
//! fastest point, moves at most `l * sum_k sqrt(dtheta_k^2 + dpsi_k^2)` over the edge.
//! Every sample must pass [`check_config_exact`].

use std::f64::consts::{PI, TAU};

use aerial_chain_core::validity::Body;

use super::exact::{check_config_exact, ExactViolation};
use crate::map::grid::Grid;
use aerial_chain_core::ChainParams;

/// Tolerance for "stays" when classifying an edge (docs/model.md).
pub const STAY_TOLERANCE: f64 = 1e-9;

/// The model's sampling rule (docs/model.md): no point of the chain moves more than
/// `r_v / SAMPLES_PER_VOXEL` between two samples of an edge. A contract, not tuning.
pub const SAMPLES_PER_VOXEL: f64 = 4.0;

/// Most sample intervals one edge may need (a 2.5 km translation at 0.1 m).
pub const MAX_INTERVALS: usize = 100_000;

/// Default search horizon for the clearance report (m).
pub const DEFAULT_HORIZON: f64 = 0.5;

/// Wraps an angle to `(-pi, pi]`.
pub fn wrap(a: f64) -> f64 {
    let w = a.rem_euclid(TAU);
    if w > PI {
        w - TAU
    } else {
        w
    }
}

/// The change from configuration `a` to `b` (`zeta`, equal lengths): the head's
/// displacement, then every angle's shortest signed difference ([`wrap`]).
pub fn zeta_delta(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter()
        .zip(b)
        .enumerate()
        .map(|(j, (x, y))| if j < 3 { y - x } else { wrap(y - x) })
        .collect()
}

/// Which kind of edge joins two configurations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeKind {
    /// Nothing changes (allowed).
    Stay,
    /// Only the head position changes.
    Translation,
    /// Only the shape changes.
    ShapeChange,
    /// Both change: not an admissible edge.
    Both,
}

impl std::fmt::Display for EdgeKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            EdgeKind::Stay => "stay",
            EdgeKind::Translation => "translation",
            EdgeKind::ShapeChange => "shape change",
            EdgeKind::Both => "both head and shape change",
        })
    }
}

/// Classifies the edge between configurations `a` and `b` (`zeta`, equal lengths).
pub fn classify_edge(a: &[f64], b: &[f64]) -> EdgeKind {
    let xi_stays = (0..3).all(|i| (b[i] - a[i]).abs() <= STAY_TOLERANCE);
    let eta_stays = a
        .iter()
        .zip(b)
        .skip(3)
        .all(|(x, y)| wrap(y - x).abs() <= STAY_TOLERANCE);
    match (xi_stays, eta_stays) {
        (true, true) => EdgeKind::Stay,
        (false, true) => EdgeKind::Translation,
        (true, false) => EdgeKind::ShapeChange,
        (false, false) => EdgeKind::Both,
    }
}

/// Number of sample intervals docs/model.md's rule needs for the edge `a -> b` of `kind`
/// at resolution `r_v` (at least 1; 0 for [`EdgeKind::Stay`] and [`EdgeKind::Both`]).
pub fn edge_intervals(
    kind: EdgeKind,
    link_length: f64,
    a: &[f64],
    b: &[f64],
    resolution: f64,
) -> usize {
    let step = resolution / SAMPLES_PER_VOXEL;
    let travel = match kind {
        EdgeKind::Translation => {
            ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt()
        }
        EdgeKind::ShapeChange => {
            let links = (a.len() - 4) / 2;
            (0..links)
                .map(|k| {
                    let dt = wrap(b[4 + 2 * k] - a[4 + 2 * k]);
                    let dp = wrap(b[5 + 2 * k] - a[5 + 2 * k]);
                    (dt * dt + dp * dp).sqrt()
                })
                .sum::<f64>()
                * link_length
        }
        EdgeKind::Stay | EdgeKind::Both => return 0,
    };
    ((travel / step).ceil() as usize).max(1)
}

/// The configuration at fraction `t` of the edge `a -> b` of `kind`.
pub fn edge_sample(kind: EdgeKind, a: &[f64], b: &[f64], t: f64) -> Vec<f64> {
    if t >= 1.0 {
        return b.to_vec();
    }
    let mut z = a.to_vec();
    match kind {
        EdgeKind::Translation => {
            for i in 0..3 {
                z[i] = a[i] + t * (b[i] - a[i]);
            }
        }
        EdgeKind::ShapeChange => {
            for i in 3..a.len() {
                z[i] = wrap(a[i] + t * wrap(b[i] - a[i]));
            }
        }
        EdgeKind::Stay | EdgeKind::Both => {}
    }
    z
}

/// Where along a plan something was found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Site {
    /// The waypoint (for `edge = None`) or the edge's first waypoint.
    pub waypoint: usize,
    /// `Some(i)`: on the edge from waypoint `i` to `i + 1`.
    pub edge: Option<usize>,
    /// Sample number along the edge (0 at its start).
    pub sample: usize,
    /// Fraction of the edge.
    pub t: f64,
}

impl std::fmt::Display for Site {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.edge {
            None => write!(f, "waypoint {}", self.waypoint),
            Some(e) => write!(
                f,
                "edge {} -> {} at t = {:.4} (sample {})",
                e,
                e + 1,
                self.t,
                self.sample
            ),
        }
    }
}

/// What is wrong with a plan.
#[derive(Clone, Debug, PartialEq)]
pub enum PlanProblem {
    /// The plan breaks the file format's rules (see `Plan::check`).
    Format(String),
    /// An edge changes both the head position and the shape.
    BothChange,
    /// A configuration fails the exact test.
    Invalid(ExactViolation),
}

impl std::fmt::Display for PlanProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlanProblem::Format(s) => write!(f, "{s}"),
            PlanProblem::BothChange => {
                f.write_str("the edge changes both the head position and the shape")
            }
            PlanProblem::Invalid(v) => write!(f, "{v}"),
        }
    }
}

/// The first problem of a plan, and where.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanViolation {
    /// Where.
    pub site: Site,
    /// What.
    pub problem: PlanProblem,
}

impl std::fmt::Display for PlanViolation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.site, self.problem)
    }
}

/// Options of [`verify_plan_with`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VerifyOptions {
    /// How far beyond a body's radius obstacles are searched for the clearance report
    /// (m); clearances above it are reported as this value.
    pub horizon: f64,
}

impl Default for VerifyOptions {
    fn default() -> Self {
        Self {
            horizon: DEFAULT_HORIZON,
        }
    }
}

/// The result of verifying a plan.
#[derive(Clone, Debug, PartialEq)]
pub struct VerifyReport {
    /// True when every waypoint and every sample of every edge is valid.
    pub ok: bool,
    /// The kind of each edge (`waypoints - 1` entries).
    pub edges: Vec<EdgeKind>,
    /// Configurations tested.
    pub samples: usize,
    /// Smallest (distance to an obstacle cube - radius) over every body of every valid
    /// sample (m), capped at the horizon.
    pub min_clearance: f64,
    /// Where that clearance was found, and the body.
    pub min_clearance_at: Option<(Site, Body)>,
    /// The first problem found, if any.
    pub violation: Option<PlanViolation>,
    /// Remarks that do not make the plan invalid (a resolution that differs from the
    /// map's, a different unknown-space assumption).
    pub notes: Vec<String>,
}

/// What the verifier reads of a plan: its chain (or why it breaks its format's rules),
/// its waypoints' configurations and the map assumptions it was made with. A plan file
/// (`crate::plan_file::Plan`) is one; the verifier itself reads no file format.
pub trait Verifiable {
    /// The chain, or, where the plan breaks its format's rules, why.
    fn chain(&self) -> Result<ChainParams, String>;
    /// Every waypoint's configuration `zeta`, the start first (at least one where
    /// [`Self::chain`] is `Ok`).
    fn configurations(&self) -> Vec<&[f64]>;
    /// The voxel edge (m) the plan was made for, and whether it took unknown space
    /// as occupied.
    fn map_assumptions(&self) -> (f64, bool);
}

/// Verifies `plan` on `grid` with the default options (see [`verify_plan_with`]).
pub fn verify_plan(grid: &Grid, plan: &impl Verifiable) -> VerifyReport {
    verify_plan_with(grid, plan, &VerifyOptions::default())
}

/// Verifies every waypoint and edge of `plan` on `grid` by the exact test, with the
/// grid's choice of whether unknown space is occupied. Goes through the whole plan: the
/// report names the FIRST violation and the smallest clearance over the valid samples.
pub fn verify_plan_with(grid: &Grid, plan: &impl Verifiable, opts: &VerifyOptions) -> VerifyReport {
    let mut rep = VerifyReport {
        ok: false,
        edges: Vec::new(),
        samples: 0,
        min_clearance: opts.horizon.max(0.0),
        min_clearance_at: None,
        violation: None,
        notes: Vec::new(),
    };
    let first = Site {
        waypoint: 0,
        edge: None,
        sample: 0,
        t: 0.0,
    };
    let params = match plan.chain() {
        Ok(p) => p,
        Err(e) => {
            rep.violation = Some(PlanViolation {
                site: first,
                problem: PlanProblem::Format(e),
            });
            return rep;
        }
    };
    rep.notes = assumption_notes(grid, plan);
    let mut v = Verifier {
        grid,
        params,
        horizon: opts.horizon,
        rep,
    };
    let zetas = plan.configurations();
    v.check(zetas[0], first);
    for (e, w) in zetas.windows(2).enumerate() {
        v.check_edge(e, w[0], w[1]);
    }
    let mut rep = v.rep;
    rep.ok = rep.violation.is_none();
    rep
}

/// Notes where the plan's own map assumptions differ from the map it is checked on
/// (the check uses the caller's map; the notes only say so).
fn assumption_notes(grid: &Grid, plan: &impl Verifiable) -> Vec<String> {
    let mut notes = Vec::new();
    let (resolution, unknown_is_occupied) = plan.map_assumptions();
    if (resolution - grid.resolution()).abs() > 1e-9 {
        notes.push(format!(
            "the plan was made for resolution {} m, the map has {} m",
            resolution,
            grid.resolution()
        ));
    }
    if unknown_is_occupied != grid.unknown_is_occupied() {
        let word = |occupied: bool| if occupied { "occupied" } else { "free" };
        notes.push(format!(
            "the plan assumed unknown space {}, this check treats it as {}",
            word(unknown_is_occupied),
            word(grid.unknown_is_occupied())
        ));
    }
    notes
}

/// The exact check of one plan, sample by sample, filling its report.
struct Verifier<'a> {
    grid: &'a Grid,
    params: ChainParams,
    horizon: f64,
    rep: VerifyReport,
}

impl Verifier<'_> {
    /// Checks one configuration; records the smallest clearance and the first violation.
    fn check(&mut self, zeta: &[f64], site: Site) {
        let rep = &mut self.rep;
        rep.samples += 1;
        let head = [zeta[0], zeta[1], zeta[2]];
        match check_config_exact(self.grid, &self.params, head, &zeta[3..], self.horizon) {
            Ok(c) => {
                if rep.min_clearance_at.is_none() || c.clearance < rep.min_clearance {
                    rep.min_clearance = c.clearance;
                    rep.min_clearance_at = Some((site, c.body));
                }
            }
            Err(v) => {
                if let ExactViolation::Map {
                    body, clearance, ..
                } = v
                {
                    if clearance < rep.min_clearance {
                        rep.min_clearance = clearance;
                        rep.min_clearance_at = Some((site, body));
                    }
                }
                self.flag(site, PlanProblem::Invalid(v));
            }
        }
    }

    /// Records `problem` at `site` unless an earlier violation is already recorded.
    fn flag(&mut self, site: Site, problem: PlanProblem) {
        if self.rep.violation.is_none() {
            self.rep.violation = Some(PlanViolation { site, problem });
        }
    }

    /// Checks edge `e` from `a` to `b` by docs/model.md's sampling rule (its start was
    /// checked as the previous edge's end).
    fn check_edge(&mut self, e: usize, a: &[f64], b: &[f64]) {
        let kind = classify_edge(a, b);
        self.rep.edges.push(kind);
        let end = Site {
            waypoint: e + 1,
            edge: None,
            sample: 0,
            t: 1.0,
        };
        let on_edge = |sample: usize, t: f64| Site {
            waypoint: e,
            edge: Some(e),
            sample,
            t,
        };
        match kind {
            EdgeKind::Stay => self.check(b, end),
            EdgeKind::Both => {
                self.flag(on_edge(0, 0.0), PlanProblem::BothChange);
                self.check(b, end);
            }
            EdgeKind::Translation | EdgeKind::ShapeChange => {
                let l = self.params.link_length as f64;
                let n = edge_intervals(kind, l, a, b, self.grid.resolution());
                if n > MAX_INTERVALS {
                    // Only a translation that leaves any real map gets here (a shape
                    // change moves no point more than 15 * l * 4.5 m): check its end,
                    // which is outside the bounds, instead of sampling for ever.
                    self.check(b, end);
                    let what = format!("the edge needs {n} samples, more than {MAX_INTERVALS}");
                    self.flag(on_edge(0, 0.0), PlanProblem::Format(what));
                    return;
                }
                for j in 1..=n {
                    let t = j as f64 / n as f64;
                    let z = edge_sample(kind, a, b, t);
                    let site = if j == n { end } else { on_edge(j, t) };
                    self.check(&z, site);
                }
            }
        }
    }
}

/// Exact check of one edge `a -> b` (`zeta`s) on `grid` for chain `params`, by
/// docs/model.md's sampling rule, including both ends. Returns the smallest clearance,
/// or the first failing sample's fraction and violation (an edge that changes both parts
/// fails at 0 with [`ExactViolation::BadShape`]).
#[cfg(test)]
pub fn check_edge_exact(
    grid: &Grid,
    params: &ChainParams,
    a: &[f64],
    b: &[f64],
    horizon: f64,
) -> Result<f64, (f64, ExactViolation)> {
    let dim = 2 * params.n() + 2;
    if a.len() != dim || b.len() != dim {
        return Err((0.0, ExactViolation::BadShape));
    }
    let kind = classify_edge(a, b);
    if kind == EdgeKind::Both {
        return Err((0.0, ExactViolation::BadShape));
    }
    let n = edge_intervals(kind, params.link_length as f64, a, b, grid.resolution());
    if n > MAX_INTERVALS {
        // Too long for any map: report its end (outside the bounds) or give up.
        check_config_exact(grid, params, [b[0], b[1], b[2]], &b[3..], horizon)
            .map_err(|v| (1.0, v))?;
        return Err((0.0, ExactViolation::BadShape));
    }
    let mut best = f64::INFINITY;
    for j in 0..=n {
        let t = if n == 0 { 0.0 } else { j as f64 / n as f64 };
        let z = edge_sample(kind, a, b, t);
        match check_config_exact(grid, params, [z[0], z[1], z[2]], &z[3..], horizon) {
            Ok(c) => best = best.min(c.clearance),
            Err(v) => return Err((t, v)),
        }
    }
    Ok(best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::grid::{Cell, Grid};
    use crate::plan_file::{ChainSection, MapSection, Plan, Waypoint, FORMAT};
    use aerial_chain_core::Shape;

    fn plan(points: &[([f64; 3], Shape)]) -> Plan {
        Plan {
            format: FORMAT.into(),
            chain: ChainSection::from_params(&ChainParams::new(3)),
            map: MapSection::new(0.1, true),
            waypoints: points.iter().map(|(h, s)| Waypoint::new(*h, s)).collect(),
            stats: Default::default(),
        }
    }

    fn room() -> Grid {
        let mut g = Grid::new(0.1, [0, 0, 0], [40, 40, 20], Cell::Free, true).unwrap();
        g.fill_box([2.05, 0.0, 0.0], [2.15, 4.0, 2.0], Cell::Occupied);
        g
    }

    #[test]
    fn wrap_and_classify() {
        assert_eq!(wrap(PI), PI);
        assert!((wrap(-PI) - PI).abs() < 1e-12);
        assert!((wrap(3.0 * PI) - PI).abs() < 1e-9);
        let a = [0.0, 0.0, 0.0, PI, 0.0, PI];
        let b = [0.0, 0.0, 0.0, -PI, 0.0, -PI];
        assert_eq!(classify_edge(&a, &b), EdgeKind::Stay);
        let c = [1.0, 0.0, 0.0, PI, 0.0, PI];
        assert_eq!(classify_edge(&a, &c), EdgeKind::Translation);
        let d = [0.0, 0.0, 0.0, PI, 0.1, PI];
        assert_eq!(classify_edge(&a, &d), EdgeKind::ShapeChange);
        let e = [1.0, 0.0, 0.0, PI, 0.1, PI];
        assert_eq!(classify_edge(&a, &e), EdgeKind::Both);
    }

    #[test]
    fn reports_first_violation_and_clearance() {
        let g = room();
        let s = Shape::line(3, 0.0);
        let ok = plan(&[
            ([1.6, 1.0, 1.0], s),
            ([1.6, 3.0, 1.0], s),
            ([1.6, 3.0, 1.0], s.rotated(1.0)),
        ]);
        let r = verify_plan(&g, &ok);
        assert!(r.ok, "{:?}", r.violation);
        assert_eq!(r.edges, vec![EdgeKind::Translation, EdgeKind::ShapeChange]);
        // The head sphere's closest approach: 2.0 - 1.6 - 0.15.
        assert!((r.min_clearance - 0.25).abs() < 1e-6, "{}", r.min_clearance);
        assert!(r.samples > 80);
        let bad = plan(&[([1.6, 1.0, 1.0], s), ([3.0, 1.0, 1.0], s)]);
        let r = verify_plan(&g, &bad);
        let v = r.violation.unwrap();
        assert_eq!(v.site.edge, Some(0));
        assert!(
            matches!(
                v.problem,
                PlanProblem::Invalid(ExactViolation::Map {
                    body: Body::Unit(0),
                    ..
                })
            ),
            "{v}"
        );
        assert!(v.site.t > 0.1 && v.site.t < 0.3, "{v}");
        assert!(r.min_clearance <= 0.0);
        let both = plan(&[([1.6, 1.0, 1.0], s), ([1.6, 2.0, 1.0], s.rotated(0.5))]);
        let r = verify_plan(&g, &both);
        assert_eq!(r.violation.unwrap().problem, PlanProblem::BothChange);
        // A plan that leaves for the far end of the world does not hang the verifier.
        let far = plan(&[([1.6, 1.0, 1.0], s), ([1e12, 1.0, 1.0], s)]);
        let r = verify_plan(&g, &far);
        assert!(matches!(
            r.violation.unwrap().problem,
            PlanProblem::Invalid(ExactViolation::OutOfBounds(_))
        ));
        let mut broken = ok.clone();
        broken.waypoints[1].zeta.pop();
        assert!(matches!(
            verify_plan(&g, &broken).violation.unwrap().problem,
            PlanProblem::Format(_)
        ));
    }
}
