//! The passage around a unit, as widening judges it: the clearance a unit would keep
//! in its middle, from the free chords across it with obstacles on both sides.

use nalgebra::{Point3, Vector3};

use super::measure::{distance, gradient};
use super::CAP;
use crate::collision::CollisionContext;
use crate::planner::numeric::{MILLIMETRE, TINY};
use crate::planner::WidenSettings;

/// Whether a unit keeping `clearance` at `p` keeps less than widening aims for
/// ([`aim`]) in the middle of the passage there ([`middles`] over the projected
/// gradient `grad` and the axes, the shortest chord counting); false where there is no
/// passage. Stops at the first chord whose middle the unit already keeps its aim of.
pub(super) fn below_aim(
    ctx: &CollisionContext,
    s: &WidenSettings,
    p: Point3<f64>,
    grad: Vector3<f64>,
    along: Option<Vector3<f64>>,
    clearance: f64,
) -> bool {
    let lines = across_all(&[grad, Vector3::x(), Vector3::y(), Vector3::z()], along);
    let mut middles = middles(ctx, s, p, &lines, along).peekable();
    middles.peek().is_some() && middles.all(|m| clearance < aim(s, m))
}

/// Whether `p` lies in a passage ([`middles`] over the gradient there and the axes
/// finds a chord): the axes first, the gradient only where they find none.
pub(super) fn in_passage(
    ctx: &CollisionContext,
    s: &WidenSettings,
    p: Point3<f64>,
    along: Option<Vector3<f64>>,
) -> bool {
    let finds = |lines: &[Vector3<f64>]| middles(ctx, s, p, lines, along).next().is_some();
    finds(&across_all(
        &[Vector3::x(), Vector3::y(), Vector3::z()],
        along,
    )) || finds(&across_all(&[gradient(ctx, p)], along))
}

/// The clearance a unit would keep in the middle of the passage at `p` along each of
/// the unit directions `lines` (across `along`): for each line through `p` that meets
/// obstacles on both sides within reach, the free chord halved, less the unit's
/// radius; the passage's middle is the shortest. None where no line does: open space,
/// or a passage wider than [`CAP`] allows to matter. Lazy: each chord costs two sphere
/// traces.
fn middles<'b>(
    ctx: &'b CollisionContext,
    s: &'b WidenSettings,
    p: Point3<f64>,
    lines: &'b [Vector3<f64>],
    along: Option<Vector3<f64>>,
) -> impl Iterator<Item = f64> + 'b {
    let r_u = ctx.params().unit_radius as f64;
    // A unit about to enter an opening is narrowest in front of it: the passage's
    // cross-section lies a little further along.
    // (`WidenSettings::probe_shifts`, the first of which is no shift.)
    let shifts: &[f64] = match along {
        Some(_) => &s.probe_shifts,
        None => &[0.0],
    };
    let u_along = along.unwrap_or_else(Vector3::zeros);
    shifts
        .iter()
        .map(move |&k| p + u_along * k)
        .flat_map(move |q| lines.iter().map(move |&u| (q, u)))
        .filter_map(move |(q, u)| Some(free_run(ctx, s, q, u)? + free_run(ctx, s, q, -u)?))
        .map(move |chord| chord / 2.0 - r_u)
}

/// How far from `p` along `u` the first obstacle lies, within the widest passage that
/// matters, `2 (CAP / target_share + r_u)`: sphere tracing, with the distance field's
/// lower bound while it is large and the exact distance near the obstacle.
fn free_run(
    ctx: &CollisionContext,
    s: &WidenSettings,
    p: Point3<f64>,
    u: Vector3<f64>,
) -> Option<f64> {
    let f = ctx.field();
    let r_v = f.grid().resolution();
    let reach = 2.0 * (CAP / s.target_share + ctx.params().unit_radius as f64);
    let mut t = 0.0;
    while t < reach {
        let q = p + u * t;
        let mut d = f.clearance(q);
        if d < r_v {
            d = distance(ctx, q);
            if d < MILLIMETRE {
                return Some(t);
            }
        }
        t += d.max(MILLIMETRE);
    }
    None
}

/// What widening aims for in a passage whose middle keeps `middle` (m):
/// `WidenSettings::centred` of it, below the cap.
fn aim(s: &WidenSettings, middle: f64) -> f64 {
    (s.centred * middle).min(CAP - s.gain)
}

/// The directions of `vs` across `along` ([`across`]), as unit vectors, those with
/// any part across.
fn across_all(vs: &[Vector3<f64>], along: Option<Vector3<f64>>) -> Vec<Vector3<f64>> {
    vs.iter()
        .filter_map(|&v| across(v, along).try_normalize(TINY))
        .collect()
}

/// The part of `v` across the unit direction `along` (all of it without one).
pub(super) fn across(v: Vector3<f64>, along: Option<Vector3<f64>>) -> Vector3<f64> {
    match along {
        Some(u) => v - u * u.dot(&v),
        None => v,
    }
}
