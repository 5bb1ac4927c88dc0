//! Follow-the-leader shapes: the chain laid back along the way its head came.
//!
//! The paper's shape sources (library, random set) give rigid shapes, and a rigid
//! shape passes a gap only if every unit's straight translation does. A chain longer
//! than the room behind a window cannot line up with it, so it must snake: move the
//! head a short step, then lay the body back along the head's own track, so every
//! unit slides along the curve the head drew. Each step is still "change shape, then
//! translate" (docs/model.md): the translation moves the body off its track by at most
//! one step, the next shape change puts it back.

use aerial_chain_core::kinematics::link_direction;
use aerial_chain_core::{ChainParams, Shape};
use nalgebra::Vector3;

use super::numeric::DIV_GUARD_F32;

/// How far inside the pitch limit a clamped link stays (rad): a controller tracking a
/// shape right at the limit would overshoot it.
///
/// Tuning left a constant: the shapes laid here are made by free functions that the
/// search, threading and connecting share, and a margin is a property of the shapes
/// (like the model's limit it keeps), not of a query.
const PITCH_MARGIN: f32 = 0.02;

/// A sharp corner of a track is cut at this share of its two segments.
///
/// Tuning left a constant, as [`PITCH_MARGIN`]: a quarter keeps three quarters of
/// each segment, so the cut line loses little length and stays near the track.
const CORNER_CUT: f32 = 0.25;

/// Slack (share of a link, over the segment's length) by which a unit may lie past a
/// segment's end: rounding of `f32` positions, not tuning.
const ROUNDING_SLACK: f32 = 1e-4;

/// The shape whose units lie on `track` (head at `track[0]`, then back along the
/// polyline), each `l` from the one before; past the track's end the chain goes on
/// straight. Link pitches are clamped just inside the limit, so a steep track is
/// followed as closely as the joints allow (the caller checks validity anyway).
///
/// Each unit goes to the point `l` from the unit before whose distance along the
/// track is nearest to one link more: on a zig-zag track (a serpentine body laid
/// down earlier) units stay on its corners instead of cutting across them.
#[cfg(test)]
pub fn lay_along(params: &ChainParams, track: &[Vector3<f32>]) -> Shape {
    lay(
        params,
        Track {
            points: track,
            newest_last: false,
        },
    )
}

/// [`lay_along`] on a track stored the other way round, newest point last, so that
/// a step of the head is a push (the follow-the-leader loop grows it step by step).
pub fn lay_along_newest_last(params: &ChainParams, track: &[Vector3<f32>]) -> Shape {
    lay(
        params,
        Track {
            points: track,
            newest_last: true,
        },
    )
}

/// A track read from the head back, whichever way it is stored.
#[derive(Clone, Copy)]
struct Track<'a> {
    points: &'a [Vector3<f32>],
    newest_last: bool,
}

impl Track<'_> {
    fn len(&self) -> usize {
        self.points.len()
    }

    /// Point `i` from the head back.
    fn at(&self, i: usize) -> Vector3<f32> {
        if self.newest_last {
            self.points[self.points.len() - 1 - i]
        } else {
            self.points[i]
        }
    }
}

/// Distance along the track to each vertex, summed only as far as it is asked for:
/// units sit within a few links of the head, so laying the chain costs its reach,
/// not the track's length.
struct Along {
    s: Vec<f32>,
}

impl Along {
    fn get(&mut self, track: Track, i: usize) -> f32 {
        while self.s.len() <= i {
            let k = self.s.len();
            let next = self.s[k - 1] + (track.at(k) - track.at(k - 1)).norm();
            self.s.push(next);
        }
        self.s[i]
    }
}

fn lay(params: &ChainParams, track: Track) -> Shape {
    let l = params.link_length;
    let mut shape = Shape::line(params.units, 0.0);
    if track.len() == 0 {
        return shape;
    }
    let head = track.at(0);
    let mut along = Along { s: vec![0.0f32] };
    let mut prev = Place {
        seg: 0,
        t: 0.0,
        s: 0.0,
        p: head,
    };
    let mut last_dir = Vector3::new(1.0, 0.0, 0.0);
    for k in 0..params.links() {
        let next = next_unit(track, &mut along, &prev, l).unwrap_or(Place {
            p: prev.p - l * last_dir,
            s: f32::INFINITY,
            ..prev
        });
        // Link direction points from the back unit to the front one.
        let d = (prev.p - next.p) / l;
        let limit = params.theta_max - PITCH_MARGIN;
        let pitch = (-d.z).clamp(-1.0, 1.0).asin().clamp(-limit, limit);
        let yaw = d.y.atan2(d.x);
        shape.set_link(k, pitch, yaw);
        last_dir = link_direction(pitch, yaw);
        prev = Place {
            p: prev.p - l * last_dir,
            ..next
        };
    }
    shape.set_head_yaw(shape.yaw(0));
    shape
}

/// The polyline with its sharp corners cut: a vertex where the line turns by more
/// than `max_turn` (rad) is replaced by the points a quarter of the way along its two
/// segments. Gentle corners and the ends stay, so the line loses little length.
pub fn cut_sharp_corners(line: &[Vector3<f32>], max_turn: f32) -> Vec<Vector3<f32>> {
    let mut out: Vec<Vector3<f32>> = line.iter().take(1).copied().collect();
    for w in line.windows(3) {
        let (a, b, c) = (w[0], w[1], w[2]);
        let (u, v) = (b - a, c - b);
        let cos = u.dot(&v) / (u.norm() * v.norm()).max(DIV_GUARD_F32);
        if cos < max_turn.cos() {
            out.push(b + CORNER_CUT * (a - b));
            out.push(b + CORNER_CUT * (c - b));
        } else {
            out.push(b);
        }
    }
    if line.len() > 1 {
        out.push(line[line.len() - 1]);
    }
    out
}

/// A unit's place on the track: segment, parameter on it, distance along the
/// track, and the point.
#[derive(Clone, Copy)]
struct Place {
    seg: usize,
    t: f32,
    s: f32,
    p: Vector3<f32>,
}

/// The point of the track after `prev`, `l` from `prev.p`, whose distance along the
/// track is nearest to `prev.s + l`.
fn next_unit(track: Track, along: &mut Along, prev: &Place, l: f32) -> Option<Place> {
    let target = prev.s + l;
    let mut best: Option<Place> = None;
    for i in prev.seg..track.len().saturating_sub(1) {
        let err = |s: f32| (s - target).abs();
        let s_i = along.get(track, i);
        if best.is_some_and(|b| s_i - target > err(b.s)) {
            break;
        }
        let (a, b) = (track.at(i), track.at(i + 1));
        let d = b - a;
        let dd = d.norm_squared();
        if dd < DIV_GUARD_F32 {
            continue;
        }
        // |a + t d - c|^2 = l^2, both roots.
        let f = a - prev.p;
        let (bh, c) = (f.dot(&d), f.norm_squared() - l * l);
        let disc = bh * bh - dd * c;
        if disc < 0.0 {
            continue;
        }
        let lo = if i == prev.seg { prev.t } else { 0.0 };
        // A body laid along the track before has its units exactly on the track's
        // vertices: rounding must not push them past the segment's end.
        let slack = ROUNDING_SLACK * l / dd.sqrt();
        for t in [(-bh - disc.sqrt()) / dd, (-bh + disc.sqrt()) / dd] {
            if t < lo || t > 1.0 + slack {
                continue;
            }
            let t = t.min(1.0);
            let s = s_i + t * dd.sqrt();
            if s > prev.s && best.is_none_or(|b| err(s) < err(b.s)) {
                best = Some(Place {
                    seg: i,
                    t,
                    s,
                    p: a + t * d,
                });
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use aerial_chain_core::kinematics::offsets;

    fn v(x: f32, y: f32, z: f32) -> Vector3<f32> {
        Vector3::new(x, y, z)
    }

    #[test]
    fn straight_track_gives_a_line_trailing_behind() {
        let p = ChainParams::new(5);
        let s = lay_along(&p, &[v(0.0, 0.0, 1.0), v(-10.0, 0.0, 1.0)]);
        let o = offsets(&p, &s);
        for (k, u) in o.iter().take(5).enumerate() {
            assert!(
                (u - v(-0.5 * k as f32, 0.0, 0.0)).norm() < 1e-5,
                "unit {k}: {u}"
            );
        }
        assert!(s.head_yaw().abs() < 1e-6);
    }

    #[test]
    fn units_sit_on_a_bent_track_one_link_apart() {
        let p = ChainParams::new(6);
        // Back 0.8 m along -x, then along +y.
        let track = [v(0.0, 0.0, 0.0), v(-0.8, 0.0, 0.0), v(-0.8, 5.0, 0.0)];
        let s = lay_along(&p, &track);
        let o = offsets(&p, &s);
        for u in o.iter().take(6) {
            let on_first = u.y.abs() < 1e-4 && u.x <= 1e-4 && u.x >= -0.8 - 1e-4;
            let on_second = (u.x + 0.8).abs() < 1e-4 && u.y >= -1e-4;
            assert!(on_first || on_second, "unit off the track: {u}");
        }
        for k in 0..5 {
            assert!(((o[k] - o[k + 1]).norm() - 0.5).abs() < 1e-4);
        }
    }

    #[test]
    fn units_keep_to_the_corners_of_a_zig_zag() {
        // A zig-zag whose every other corner is exactly one link from the last.
        let p = ChainParams::new(6);
        let (dx, dy) = (0.25f32, 0.5 * 3f32.sqrt() / 2.0 * 2.0 / 2.0);
        let track: Vec<_> = (0..12)
            .map(|k| v(-dx * k as f32, if k % 2 == 0 { 0.0 } else { dy }, 0.0))
            .collect();
        let s = lay_along(&p, &track);
        let o = offsets(&p, &s);
        for (k, u) in o.iter().take(6).enumerate() {
            assert!(
                (u - track[k]).norm() < 1e-3,
                "unit {k} at {u}, corner {}",
                track[k]
            );
        }
    }

    #[test]
    fn both_storages_of_a_track_lay_the_same_chain() {
        let p = ChainParams::new(7);
        let track: Vec<_> = (0..400)
            .map(|k| {
                let a = k as f32 * 0.05;
                v(-0.02 * k as f32, a.sin(), 0.3 * (0.5 * a).cos())
            })
            .collect();
        let reversed: Vec<_> = track.iter().rev().copied().collect();
        assert_eq!(
            lay_along(&p, &track).as_slice(),
            lay_along_newest_last(&p, &reversed).as_slice()
        );
    }

    #[test]
    fn only_sharp_corners_are_cut() {
        let right = std::f32::consts::FRAC_PI_2;
        let line = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(2.0, 0.0, 0.0)];
        assert_eq!(cut_sharp_corners(&line, right), line.to_vec());
        // A gentle 45 degree bend stays.
        let gentle = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(2.0, 1.0, 0.0)];
        assert_eq!(cut_sharp_corners(&gentle, right), gentle.to_vec());
        // A 135 degree turn is cut; the ends stay.
        let sharp = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)];
        let cut = cut_sharp_corners(&sharp, right);
        assert_eq!(cut.len(), 4);
        assert_eq!((cut[0], cut[3]), (sharp[0], sharp[2]));
        assert!(cut.iter().all(|p| (p - v(1.0, 0.0, 0.0)).norm() > 0.2));
    }

    #[test]
    fn short_track_goes_on_straight() {
        let p = ChainParams::new(4);
        let s = lay_along(&p, &[v(0.0, 0.0, 0.0), v(0.0, -0.6, 0.0)]);
        let o = offsets(&p, &s);
        assert!((o[3] - v(0.0, -1.5, 0.0)).norm() < 1e-4, "{}", o[3]);
    }

    #[test]
    fn steep_track_is_clamped_to_the_pitch_limit() {
        let p = ChainParams::new(3);
        let s = lay_along(&p, &[v(0.0, 0.0, 3.0), v(0.0, 0.0, 0.0)]);
        for k in 0..2 {
            assert!(s.pitch(k).abs() <= p.theta_max - PITCH_MARGIN + 1e-6);
        }
    }
}
