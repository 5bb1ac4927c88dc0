//! The library of shape configurations (LSC, paper Sec. 3.2, docs/model.md).
//!
//! For any N the library tries six shapes, all drawn with the head at the origin
//! and the chain trailing behind it along -x:
//! - `LI`: the straight line.
//! - `SE`, `SM`: zig-zag serpentines in the x-y plane, mirror images (SE turns its
//!   first link to the left of the axis, SM to the right).
//! - `SV`: the same zig-zag in the x-z plane (link pitches alternate).
//! - `CA`: a circular arc of 90 degrees in the x-y plane whose N-1 chords of length
//!   `l` span it, symmetric about the x axis.
//! - `PN`: the open polygon, N units on a circle of radius `l / (2 sin(pi/N))`,
//!   the head looking out of the polygon, with an outward sensor heading per unit.
//!
//! Serpentines bend by the largest angle the limits and self-collision allow, less
//! [`LIMIT_MARGIN`]: a shape that sits exactly on a limit would be at the mercy of
//! rounding in every later check. A shape that is still invalid for the given N
//! (for instance PN for N = 3, whose bend equals the default `beta_max`) is left
//! out of that N's library, and [`Library::excluded`] says why.

use core::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

use crate::params::{ChainParams, MAX_UNITS};
use crate::shape::Shape;
use crate::validity::{check_transition, Violation};

/// Slack (rad for angles, m for gaps) every library shape keeps from every limit.
pub const LIMIT_MARGIN: f32 = 1e-3;

/// Serpentine angles are searched downwards in steps of this size (rad).
const SERPENTINE_STEP: f32 = 0.25 * PI / 180.0;

/// The six library shapes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LscKind {
    /// Line.
    Li,
    /// Serpentine in the x-y plane, first link to the left.
    Se,
    /// Serpentine in the x-y plane, first link to the right (mirror of SE).
    Sm,
    /// Serpentine in the x-z plane.
    Sv,
    /// Circular arc of 90 degrees.
    Ca,
    /// Open polygon with outward sensor headings.
    Pn,
}

impl LscKind {
    /// All kinds, in library order.
    pub const ALL: [LscKind; 6] = [Self::Li, Self::Se, Self::Sm, Self::Sv, Self::Ca, Self::Pn];

    /// The two-letter name used by the paper, the tables and the CLI.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Li => "LI",
            Self::Se => "SE",
            Self::Sm => "SM",
            Self::Sv => "SV",
            Self::Ca => "CA",
            Self::Pn => "PN",
        }
    }

    /// The kind with this name (case-insensitive).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(name))
    }
}

/// One library shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LscEntry {
    /// Which shape.
    pub kind: LscKind,
    /// The shape, head at the origin, trailing along -x.
    pub shape: Shape,
    /// Per-unit sensor heading (yaw, rad) for coverage, when the shape defines one.
    pub headings: Option<[f32; MAX_UNITS]>,
}

/// The library for one chain: the shapes that are valid, and why the others are not.
#[derive(Clone, Debug, PartialEq)]
pub struct Library {
    /// Valid shapes, in [`LscKind::ALL`] order.
    pub entries: heapless::Vec<LscEntry, 6>,
    /// Shapes left out, with the first violation found.
    pub excluded: heapless::Vec<(LscKind, Violation), 6>,
}

/// Builds the library for `params` (which must be validated).
pub fn library(params: &ChainParams) -> Library {
    let mut lib = Library {
        entries: heapless::Vec::new(),
        excluded: heapless::Vec::new(),
    };
    for kind in LscKind::ALL {
        // Capacity is exactly the number of kinds: pushes cannot fail.
        let _ = match generate(params, kind) {
            Ok(e) => lib.entries.push(e).map_err(|_| ()),
            Err(v) => lib.excluded.push((kind, v)).map_err(|_| ()),
        };
    }
    lib
}

impl Library {
    /// The entry of this kind, if it is in the library.
    pub fn get(&self, kind: LscKind) -> Option<&LscEntry> {
        self.entries.iter().find(|e| e.kind == kind)
    }
}

/// Builds one library shape, or the violation that keeps it out.
pub fn generate(params: &ChainParams, kind: LscKind) -> Result<LscEntry, Violation> {
    let n = params.units;
    let entry = |shape: Shape| LscEntry {
        kind,
        shape,
        headings: None,
    };
    let e = match kind {
        LscKind::Li => entry(Shape::line(n, 0.0)),
        LscKind::Se => entry(largest_serpentine(params, |a| zigzag_yaw(n, a))?),
        LscKind::Sm => entry(largest_serpentine(params, |a| zigzag_yaw(n, -a))?),
        LscKind::Sv => entry(largest_serpentine(params, |a| zigzag_pitch(n, a))?),
        LscKind::Ca => entry(arc(n)),
        LscKind::Pn => polygon(params),
    };
    check_transition(params, &e.shape, &e.shape, LIMIT_MARGIN)?;
    Ok(e)
}

/// Links alternate `+a, -a` in yaw about the -x axis; head looks along +x.
fn zigzag_yaw(n: u8, a: f32) -> Shape {
    let mut s = Shape::line(n, 0.0);
    for k in 0..s.links() {
        s.set_link(k, 0.0, if k % 2 == 0 { a } else { -a });
    }
    s
}

/// Links alternate `+a, -a` in pitch: the zig-zag stands in the x-z plane.
fn zigzag_pitch(n: u8, a: f32) -> Shape {
    let mut s = Shape::line(n, 0.0);
    for k in 0..s.links() {
        s.set_link(k, if k % 2 == 0 { a } else { -a }, 0.0);
    }
    s
}

/// The largest zig-zag amplitude (bend = 2a) that keeps every limit with margin.
fn largest_serpentine(
    params: &ChainParams,
    make: impl Fn(f32) -> Shape,
) -> Result<Shape, Violation> {
    // The pitch limit caps SV; the bend limit caps all; 90 degrees caps the geometry.
    let mut a = (0.5 * params.beta_max).min(params.theta_max).min(FRAC_PI_2) - LIMIT_MARGIN;
    let mut last = Err(Violation::Bend(0));
    while a > SERPENTINE_STEP {
        let s = make(a);
        match check_transition(params, &s, &s, LIMIT_MARGIN) {
            Ok(()) => return Ok(s),
            Err(v) => last = Err(v),
        }
        a -= SERPENTINE_STEP;
    }
    last
}

/// The 90-degree arc: link `k` turns by `phi = (pi/2)/(N-1)` from the one before,
/// symmetric about the x axis.
fn arc(n: u8) -> Shape {
    let mut s = Shape::line(n, 0.0);
    let phi = FRAC_PI_2 / s.links() as f32;
    for k in 0..s.links() {
        s.set_link(k, 0.0, -FRAC_PI_4 + 0.5 * phi + k as f32 * phi);
    }
    s
}

/// The open polygon: every link turns by `2 pi / N`; rotated so that the polygon's
/// centre lies straight behind the head, which then looks outwards along +x.
fn polygon(params: &ChainParams) -> LscEntry {
    let n = params.units;
    let turn = TAU / n as f32;
    // Link k's direction before rotation; the back unit lies at -l * d from the front.
    let mut yaws = [0.0f32; MAX_UNITS];
    let (mut cx, mut cy, mut x, mut y) = (0.0f32, 0.0f32, 0.0f32, 0.0f32);
    for (k, yaw) in yaws.iter_mut().enumerate().take(n as usize - 1) {
        *yaw = k as f32 * turn;
        x -= params.link_length * libm::cosf(*yaw);
        y -= params.link_length * libm::sinf(*yaw);
        cx += x;
        cy += y;
    }
    // The N units are evenly spread on the full circle: their mean is its centre.
    let (cx, cy) = (cx / n as f32, cy / n as f32);
    let rot = PI - libm::atan2f(cy, cx);
    let mut s = Shape::line(n, 0.0);
    for (k, yaw) in yaws.iter().enumerate().take(s.links()) {
        s.set_link(k, 0.0, crate::angle::wrap(yaw + rot));
    }
    let p = crate::kinematics::offsets(params, &s);
    let centre = p
        .iter()
        .take(n as usize)
        .fold(nalgebra::Vector3::zeros(), |a, q| a + q)
        / n as f32;
    let mut headings = [0.0f32; MAX_UNITS];
    for (h, q) in headings.iter_mut().zip(p.iter()).take(n as usize) {
        *h = libm::atan2f(q.y - centre.y, q.x - centre.x);
    }
    s.set_head_yaw(headings[0]);
    LscEntry {
        kind: LscKind::Pn,
        shape: s,
        headings: Some(headings),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::offsets;
    use crate::validity::{bend, check_shape};

    #[test]
    fn every_claimed_shape_is_valid_for_every_n() {
        for n in 2..=16 {
            let p = ChainParams::new(n).validate().unwrap();
            let lib = library(&p);
            assert_eq!(lib.entries.len() + lib.excluded.len(), 6);
            for e in &lib.entries {
                assert_eq!(check_shape(&p, &e.shape), Ok(()), "N={n} {}", e.kind.name());
            }
            assert!(lib.get(LscKind::Li).is_some());
        }
    }

    #[test]
    fn default_library_contents() {
        // PN for N = 3 bends by exactly beta_max = 120 deg: out. Everything else is in.
        let lib = library(&ChainParams::new(3));
        assert_eq!(lib.excluded.len(), 1);
        assert_eq!(lib.excluded[0].0, LscKind::Pn);
        for n in [4, 5, 6, 12, 16] {
            assert_eq!(library(&ChainParams::new(n)).entries.len(), 6, "N={n}");
        }
    }

    #[test]
    fn serpentines_use_the_bend_limit_and_mirror() {
        let p = ChainParams::new(5);
        let se = generate(&p, LscKind::Se).unwrap().shape;
        let sm = generate(&p, LscKind::Sm).unwrap().shape;
        assert!((bend(&se, 0) - p.beta_max).abs() < 2.0 * LIMIT_MARGIN + 1e-4);
        let (a, b) = (offsets(&p, &se), offsets(&p, &sm));
        for i in 0..5 {
            assert!((a[i].x - b[i].x).abs() < 1e-5 && (a[i].y + b[i].y).abs() < 1e-5);
        }
        let sv = generate(&p, LscKind::Sv).unwrap().shape;
        assert!(offsets(&p, &sv).iter().all(|q| q.y.abs() < 1e-6));
    }

    #[test]
    fn arc_spans_ninety_degrees_and_polygon_is_regular() {
        let p = ChainParams::new(6);
        let ca = generate(&p, LscKind::Ca).unwrap().shape;
        let turn = crate::angle::diff(ca.yaw(0), ca.yaw(4));
        assert!((turn - FRAC_PI_2 * 4.0 / 5.0).abs() < 1e-5);
        let pn = generate(&p, LscKind::Pn).unwrap();
        let q = offsets(&p, &pn.shape);
        let r = 0.5 / (2.0 * libm::sinf(PI / 6.0));
        let c = q
            .iter()
            .take(6)
            .fold(nalgebra::Vector3::zeros(), |a, v| a + v)
            / 6.0;
        for v in q.iter().take(6) {
            assert!(((v - c).norm() - r).abs() < 1e-4);
        }
        // Centre behind the head, head looking out along +x.
        assert!(c.x < 0.0 && c.y.abs() < 1e-4);
        assert!(pn.shape.head_yaw().abs() < 1e-4);
        let h = pn.headings.unwrap();
        assert!(
            (crate::angle::diff(h[3], 0.0).abs() - PI).abs() < 1e-3,
            "unit 4 looks backwards"
        );
    }

    #[test]
    fn names_round_trip() {
        for k in LscKind::ALL {
            assert_eq!(LscKind::from_name(k.name()), Some(k));
        }
        assert_eq!(LscKind::from_name("pn"), Some(LscKind::Pn));
        assert_eq!(LscKind::from_name("XX"), None);
    }
}
