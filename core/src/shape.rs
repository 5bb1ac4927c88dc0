//! The shape `eta` and the configuration `zeta` of a chain.
//!
//! `eta = [psi1_r, theta_1, psi_1, ..., theta_{N-1}, psi_{N-1}]` (dimension 2N-1):
//! the head's yaw, then each link's ABSOLUTE pitch and yaw in the world frame.
//! `zeta = [x1, y1, z1, eta...]` adds the head position `xi`.

use crate::angle;
use crate::params::{MAX_SHAPE_DIM, MAX_UNITS};

/// A chain shape `eta` in a fixed-capacity array (no allocation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shape {
    units: u8,
    eta: [f32; MAX_SHAPE_DIM],
}

/// Why a slice is not a shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ShapeError {
    /// `units` is outside `2..=16`.
    UnitsOutOfRange,
    /// The slice does not have `2N - 1` entries.
    WrongLength,
    /// An angle is NaN or infinite.
    NotFinite,
}

impl Shape {
    /// The straight line LI: every link trails straight behind the head at `yaw`.
    ///
    /// # Panics
    /// If `units` is outside `2..=16` (a programming error: validate parameters first).
    pub fn line(units: u8, yaw: f32) -> Self {
        assert!((2..=MAX_UNITS as u8).contains(&units), "units out of range");
        let mut s = Self {
            units,
            eta: [0.0; MAX_SHAPE_DIM],
        };
        s.eta[0] = yaw;
        for k in 0..s.links() {
            s.set_link(k, 0.0, yaw);
        }
        s
    }

    /// A shape from its `2N - 1` angles, in docs/model.md order.
    pub fn from_slice(units: u8, eta: &[f32]) -> Result<Self, ShapeError> {
        if !(2..=MAX_UNITS as u8).contains(&units) {
            return Err(ShapeError::UnitsOutOfRange);
        }
        if eta.len() != 2 * units as usize - 1 {
            return Err(ShapeError::WrongLength);
        }
        if eta.iter().any(|a| !a.is_finite()) {
            return Err(ShapeError::NotFinite);
        }
        let mut s = Self {
            units,
            eta: [0.0; MAX_SHAPE_DIM],
        };
        s.eta[..eta.len()].copy_from_slice(eta);
        Ok(s)
    }

    /// Number of units N.
    pub fn units(&self) -> usize {
        self.units as usize
    }

    /// Number of links N - 1.
    pub fn links(&self) -> usize {
        self.units as usize - 1
    }

    /// The `2N - 1` angles.
    pub fn as_slice(&self) -> &[f32] {
        &self.eta[..2 * self.units as usize - 1]
    }

    /// The head's yaw `psi1_r`.
    pub fn head_yaw(&self) -> f32 {
        self.eta[0]
    }

    /// Pitch `theta` of link `k` (0-based: link `k` joins unit `k` to unit `k + 1`).
    pub fn pitch(&self, k: usize) -> f32 {
        self.eta[1 + 2 * k]
    }

    /// Yaw `psi` of link `k` (0-based).
    pub fn yaw(&self, k: usize) -> f32 {
        self.eta[2 + 2 * k]
    }

    /// Sets the head's yaw.
    pub fn set_head_yaw(&mut self, yaw: f32) {
        self.eta[0] = yaw;
    }

    /// Sets link `k`'s pitch and yaw (0-based).
    pub fn set_link(&mut self, k: usize, pitch: f32, yaw: f32) {
        self.eta[1 + 2 * k] = pitch;
        self.eta[2 + 2 * k] = yaw;
    }

    /// The shape rotated by `d` about the head's vertical axis: `d` is added to the
    /// head's yaw and to every link's yaw (wrapped), pitches stay.
    pub fn rotated(&self, d: f32) -> Self {
        let mut s = *self;
        s.eta[0] = angle::wrap(s.eta[0] + d);
        for k in 0..self.links() {
            s.eta[2 + 2 * k] = angle::wrap(s.eta[2 + 2 * k] + d);
        }
        s
    }

    /// The point at fraction `t` of the straight motion from `self` to `to`, each angle
    /// moving along its shortest signed difference (docs/model.md shape-change edge).
    pub fn lerp(&self, to: &Shape, t: f32) -> Shape {
        debug_assert_eq!(self.units, to.units);
        let mut s = *self;
        for (a, b) in s
            .eta
            .iter_mut()
            .zip(to.eta.iter())
            .take(2 * self.units as usize - 1)
        {
            *a = angle::wrap(*a + t * angle::diff(*a, *b));
        }
        s
    }

    /// Largest absolute wrapped angle difference to `other` over all entries (rad).
    pub fn max_angle_diff(&self, other: &Shape) -> f32 {
        self.as_slice()
            .iter()
            .zip(other.as_slice())
            .map(|(a, b)| angle::diff(*a, *b).abs())
            .fold(0.0, f32::max)
    }
}

/// A full configuration `zeta`: head position `xi` and shape `eta`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// Head position `xi = [x1, y1, z1]` in the world frame (m).
    pub xi: [f32; 3],
    /// Shape `eta`.
    pub shape: Shape,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::angle::deg;

    #[test]
    fn line_has_all_yaws_equal() {
        let s = Shape::line(4, 0.3);
        assert_eq!(s.as_slice(), &[0.3, 0.0, 0.3, 0.0, 0.3, 0.0, 0.3]);
    }

    #[test]
    fn from_slice_rejects_bad_input() {
        assert_eq!(
            Shape::from_slice(3, &[0.0; 4]),
            Err(ShapeError::WrongLength)
        );
        assert_eq!(
            Shape::from_slice(1, &[0.0; 1]),
            Err(ShapeError::UnitsOutOfRange)
        );
        assert_eq!(
            Shape::from_slice(2, &[0.0, f32::NAN, 0.0]),
            Err(ShapeError::NotFinite)
        );
    }

    #[test]
    fn lerp_goes_the_short_way_and_ends_exactly() {
        let a = Shape::from_slice(2, &[deg(170.0), 0.0, deg(170.0)]).unwrap();
        let b = Shape::from_slice(2, &[deg(-170.0), 0.1, deg(-170.0)]).unwrap();
        let mid = a.lerp(&b, 0.5);
        assert!((mid.head_yaw().abs() - deg(180.0)).abs() < 1e-5);
        assert!((mid.pitch(0) - 0.05).abs() < 1e-6);
        let end = a.lerp(&b, 1.0);
        assert!(end.max_angle_diff(&b) < 1e-6);
    }

    #[test]
    fn rotation_moves_only_yaws() {
        let s = Shape::from_slice(3, &[0.0, 0.2, 0.1, -0.3, 0.5])
            .unwrap()
            .rotated(1.0);
        assert_eq!(s.as_slice(), &[1.0, 0.2, 1.1, -0.3, 1.5]);
    }
}
