//! A goal's configuration beyond its head position: the head's yaw and the shape the
//! chain should arrive in (docs/model.md, "Goal configurations").
//!
//! A shape given without a yaw is the shape up to a rotation about the head (a
//! rotation by `d` adds `d` to the head's yaw and to every link yaw): it matches at any
//! heading. A yaw given without a shape asks only for the heading; the chain may keep
//! any shape, turned about its head.

use aerial_chain_core::lsc::LscKind;
use aerial_chain_core::{ChainParams, Shape};

use crate::collision::verify::wrap;

/// How close a configuration must come to the goal's yaw and shape (rad, every angle
/// after wrapping to (-pi, pi]): the contract's tolerance, far above the rounding of
/// `f32` shapes written as decimals.
pub const POSE_TOLERANCE: f64 = 1e-6;

/// The yaw and shape a goal asks for; both `None`: the head position alone matters.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GoalPose {
    /// The head's yaw (rad), if asked for.
    pub yaw: Option<f32>,
    /// The shape, up to a rotation about the head when `yaw` is `None`.
    pub shape: Option<Shape>,
}

/// A goal shape that cannot be used for a chain.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GoalShapeError {
    /// A name that is no library shape.
    #[error("{0:?} is not a library shape (LI, SE, SM, SV, CA, PN) nor a list of angles")]
    Name(String),
    /// A library shape the chain's limits leave out.
    #[error("{name} is not in the library for N = {units} ({why})")]
    NotInLibrary {
        /// The shape's name.
        name: String,
        /// The chain's units.
        units: usize,
        /// Why the library leaves it out.
        why: String,
    },
    /// Explicit angles of the wrong count or not finite.
    #[error("{got} angles, expected 2N - 1 = {expected} finite numbers (rad): head yaw, then every link's pitch and yaw")]
    Angles {
        /// Numbers given.
        got: usize,
        /// Numbers a shape of this chain has.
        expected: usize,
    },
}

/// A goal shape for the chain `params`: a library name (any case), or `2N - 1`
/// comma-separated angles in radians (`eta`: head yaw, then every link's pitch and
/// yaw).
pub fn parse_shape(params: &ChainParams, text: &str) -> Result<Shape, GoalShapeError> {
    if let Some(kind) = LscKind::from_name(text.trim()) {
        return aerial_chain_core::lsc::generate(params, kind)
            .map(|e| e.shape)
            .map_err(|v| GoalShapeError::NotInLibrary {
                name: kind.name().to_string(),
                units: params.n(),
                why: format!("{v:?}"),
            });
    }
    let numbers: Result<Vec<f32>, _> = text.split(',').map(|t| t.trim().parse::<f32>()).collect();
    let Ok(numbers) = numbers else {
        return Err(GoalShapeError::Name(text.to_string()));
    };
    let expected = 2 * params.n() - 1;
    if numbers.len() != expected || numbers.iter().any(|v| !v.is_finite()) {
        return Err(GoalShapeError::Angles {
            got: numbers.len(),
            expected,
        });
    }
    Shape::from_slice(params.units, &numbers).map_err(|_| GoalShapeError::Angles {
        got: numbers.len(),
        expected,
    })
}

impl GoalPose {
    /// Whether the pose asks for nothing beyond the head position.
    pub fn is_any(&self) -> bool {
        self.yaw.is_none() && self.shape.is_none()
    }

    /// Whether the shape `eta` (head yaw, then every link's pitch and yaw) is the pose's
    /// within [`POSE_TOLERANCE`].
    pub fn holds(&self, eta: &[f64]) -> bool {
        let close = |a: f64, b: f64| wrap(a - b).abs() <= POSE_TOLERANCE;
        if let Some(y) = self.yaw {
            if !close(eta[0], y as f64) {
                return false;
            }
        }
        let Some(shape) = self.shape else {
            return true;
        };
        let want = shape.as_slice();
        if want.len() != eta.len() {
            return false;
        }
        // Turned so that its head yaw is the configuration's (or the asked yaw).
        let d = eta[0] - want[0] as f64;
        // eta[0] is the head's yaw, eta[2i] link i's yaw: those turn; pitches do not.
        let turned = |k: usize, w: f64| match k.is_multiple_of(2) {
            true => w + d,
            false => w,
        };
        want.iter()
            .enumerate()
            .all(|(k, &w)| close(eta[k], turned(k, w as f64)))
    }

    /// The shapes that reach the pose from `current`, best first: with a yaw, the
    /// goal shape (or `current`) turned to it; without, the goal shape turned to
    /// `current`'s heading, then to `headings - 1` other headings evenly around.
    pub fn targets(&self, current: &Shape, headings: usize) -> Vec<Shape> {
        let shape = self.shape.unwrap_or(*current);
        let head = shape.head_yaw();
        match self.yaw {
            Some(y) => vec![shape.rotated(y - head)],
            None => {
                let base = current.head_yaw() - head;
                let turns = headings.max(1);
                (0..turns)
                    .map(|k| {
                        let d = base + k as f32 * std::f32::consts::TAU / turns as f32;
                        shape.rotated(d)
                    })
                    .collect()
            }
        }
    }

    /// The pose in words, for messages: `yaw 90.0 deg, shape PN` and the like.
    pub fn describe(&self, shape_name: Option<&str>) -> String {
        let yaw = self
            .yaw
            .map(|y| format!("yaw {:.1} deg", (y as f64).to_degrees()));
        let shape = self
            .shape
            .map(|_| format!("shape {}", shape_name.unwrap_or("as given")));
        [yaw, shape]
            .into_iter()
            .flatten()
            .collect::<Vec<_>>()
            .join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shape_matches_at_any_heading_unless_a_yaw_is_asked() {
        let params = ChainParams::new(4);
        let pn = parse_shape(&params, "pn").unwrap();
        let pose = GoalPose {
            yaw: None,
            shape: Some(pn),
        };
        for d in [0.0f32, 0.7, -2.5, 3.1] {
            let eta: Vec<f64> = pn.rotated(d).as_slice().iter().map(|&a| a as f64).collect();
            assert!(pose.holds(&eta), "{d}");
        }
        let line: Vec<f64> = Shape::line(4, 0.3)
            .as_slice()
            .iter()
            .map(|&a| a as f64)
            .collect();
        assert!(!pose.holds(&line));
        let yawed = GoalPose {
            yaw: Some(1.0),
            ..pose
        };
        let at = |d: f32| -> Vec<f64> {
            pn.rotated(d - pn.head_yaw())
                .as_slice()
                .iter()
                .map(|&a| a as f64)
                .collect()
        };
        assert!(yawed.holds(&at(1.0)));
        assert!(!yawed.holds(&at(1.1)));
        assert_eq!(yawed.targets(&Shape::line(4, 0.0), 8).len(), 1);
        let t = pose.targets(&Shape::line(4, 0.4), 8);
        assert_eq!(t.len(), 8);
        assert!((t[0].head_yaw() - 0.4).abs() < 1e-6);
    }

    #[test]
    fn shapes_are_names_or_angles_and_bad_ones_say_why() {
        let params = ChainParams::new(3);
        assert!(parse_shape(&params, "LI").is_ok());
        assert!(parse_shape(&params, "0.1, 0, 0.1, 0.2, 0.3").is_ok());
        assert!(matches!(
            parse_shape(&params, "XX"),
            Err(GoalShapeError::Name(_))
        ));
        assert!(matches!(
            parse_shape(&params, "0.1,0.2"),
            Err(GoalShapeError::Angles {
                got: 2,
                expected: 5
            })
        ));
        assert!(matches!(
            parse_shape(&params, "PN"),
            Err(GoalShapeError::NotInLibrary { .. })
        ));
    }
}
