//! Chain parameters: number of units, link length, collision radii and joint limits.

use serde::{Deserialize, Serialize};

/// Largest number of units a chain may have (docs/model.md: 2 <= N <= 16).
pub const MAX_UNITS: usize = 16;
/// Largest number of links (`MAX_UNITS - 1`).
pub const MAX_LINKS: usize = MAX_UNITS - 1;
/// Largest shape dimension `2N - 1`.
pub const MAX_SHAPE_DIM: usize = 2 * MAX_UNITS - 1;
/// Smallest number of units a chain may have.
pub const MIN_UNITS: usize = 2;

/// The physical parameters of a chain. Lengths in metres, angles in radians.
///
/// Build with [`ChainParams::new`] (the docs/model.md defaults for `units`) and
/// check with [`ChainParams::validate`] before use: every function in this crate
/// assumes validated parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ChainParams {
    /// Number of units N (2..=16). Unit 1 is the head.
    pub units: u8,
    /// Link length `l`, unit centre to unit centre (m).
    pub link_length: f32,
    /// Radius `r_u` of each unit's collision sphere (m).
    pub unit_radius: f32,
    /// Radius `r_l` of each link's collision capsule (m).
    pub link_radius: f32,
    /// Limit on every link's absolute pitch: `|theta_i| <= theta_max` (rad, < pi/2).
    pub theta_max: f32,
    /// Limit on the bend between consecutive links' direction vectors (rad, <= pi).
    pub beta_max: f32,
}

/// Every way a [`ChainParams`] can be wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ParamError {
    /// `units` is outside `2..=16`.
    UnitsOutOfRange,
    /// `link_length` is not a finite positive number.
    LinkLength,
    /// `unit_radius` is not a finite positive number.
    UnitRadius,
    /// `link_radius` is not finite and positive, or not smaller than `unit_radius`.
    LinkRadius,
    /// `2 * unit_radius >= link_length`: neighbouring units would overlap.
    UnitsOverlap,
    /// `theta_max` is not in `(0, pi/2)`.
    ThetaMax,
    /// `beta_max` is not in `(0, pi]`.
    BetaMax,
}

impl core::fmt::Display for ParamError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::UnitsOutOfRange => "units must be between 2 and 16",
            Self::LinkLength => "link_length must be a finite positive number",
            Self::UnitRadius => "unit_radius must be a finite positive number",
            Self::LinkRadius => "link_radius must be finite, positive and below unit_radius",
            Self::UnitsOverlap => "2 * unit_radius must be below link_length",
            Self::ThetaMax => "theta_max must lie in (0, 90) degrees",
            Self::BetaMax => "beta_max must lie in (0, 180] degrees",
        })
    }
}

impl ChainParams {
    /// docs/model.md default link length `l` (m).
    pub const DEFAULT_LINK_LENGTH: f32 = 0.50;
    /// docs/model.md default unit radius `r_u` (m).
    pub const DEFAULT_UNIT_RADIUS: f32 = 0.15;
    /// docs/model.md default link radius `r_l` (m).
    pub const DEFAULT_LINK_RADIUS: f32 = 0.01;
    /// docs/model.md default pitch limit (60 degrees).
    pub const DEFAULT_THETA_MAX: f32 = core::f32::consts::FRAC_PI_3;
    /// docs/model.md default bend limit (120 degrees).
    pub const DEFAULT_BETA_MAX: f32 = 2.0 * core::f32::consts::FRAC_PI_3;

    /// The docs/model.md defaults for a chain of `units` units (not yet validated).
    pub const fn new(units: u8) -> Self {
        Self {
            units,
            link_length: Self::DEFAULT_LINK_LENGTH,
            unit_radius: Self::DEFAULT_UNIT_RADIUS,
            link_radius: Self::DEFAULT_LINK_RADIUS,
            theta_max: Self::DEFAULT_THETA_MAX,
            beta_max: Self::DEFAULT_BETA_MAX,
        }
    }

    /// Checks every parameter; returns `self` so construction chains read well:
    /// `ChainParams::new(5).validate()?`.
    pub fn validate(self) -> Result<Self, ParamError> {
        let positive = |v: f32| v.is_finite() && v > 0.0;
        if !(MIN_UNITS..=MAX_UNITS).contains(&(self.units as usize)) {
            return Err(ParamError::UnitsOutOfRange);
        }
        if !positive(self.link_length) {
            return Err(ParamError::LinkLength);
        }
        if !positive(self.unit_radius) {
            return Err(ParamError::UnitRadius);
        }
        if !positive(self.link_radius) || self.link_radius >= self.unit_radius {
            return Err(ParamError::LinkRadius);
        }
        if 2.0 * self.unit_radius >= self.link_length {
            return Err(ParamError::UnitsOverlap);
        }
        if !(self.theta_max > 0.0 && self.theta_max < core::f32::consts::FRAC_PI_2) {
            return Err(ParamError::ThetaMax);
        }
        if !(self.beta_max > 0.0 && self.beta_max <= core::f32::consts::PI) {
            return Err(ParamError::BetaMax);
        }
        Ok(self)
    }

    /// Number of units N.
    pub const fn n(&self) -> usize {
        self.units as usize
    }

    /// Number of links N - 1.
    pub const fn links(&self) -> usize {
        self.units as usize - 1
    }

    /// Shape dimension 2N - 1.
    pub const fn shape_dim(&self) -> usize {
        2 * self.units as usize - 1
    }

    /// Farthest any unit centre can be from the head: `(N - 1) * l`.
    pub fn reach(&self) -> f32 {
        self.links() as f32 * self.link_length
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_for_every_n() {
        for n in 2..=16 {
            assert!(ChainParams::new(n).validate().is_ok(), "N={n}");
        }
    }

    #[test]
    fn each_error_is_reported() {
        let p = ChainParams::new(5);
        assert_eq!(
            ChainParams::new(1).validate(),
            Err(ParamError::UnitsOutOfRange)
        );
        assert_eq!(
            ChainParams::new(17).validate(),
            Err(ParamError::UnitsOutOfRange)
        );
        let e = |q: ChainParams| q.validate().unwrap_err();
        assert_eq!(
            e(ChainParams {
                link_length: f32::NAN,
                ..p
            }),
            ParamError::LinkLength
        );
        assert_eq!(
            e(ChainParams {
                unit_radius: 0.0,
                ..p
            }),
            ParamError::UnitRadius
        );
        assert_eq!(
            e(ChainParams {
                link_radius: 0.2,
                ..p
            }),
            ParamError::LinkRadius
        );
        assert_eq!(
            e(ChainParams {
                unit_radius: 0.25,
                ..p
            }),
            ParamError::UnitsOverlap
        );
        assert_eq!(
            e(ChainParams {
                theta_max: 1.6,
                ..p
            }),
            ParamError::ThetaMax
        );
        assert_eq!(e(ChainParams { beta_max: 0.0, ..p }), ParamError::BetaMax);
    }
}
