//! Physical parameters of the simulated chain: units, links, actuators, gravity.
//!
//! The geometry (N, link length, radii, joint limits) comes from the plan's
//! [`ChainParams`]; everything else here is a documented default of a small
//! quadrotor (about 1 kg, 0.17 m arms) and a carbon tube link, configurable.

use aerial_chain_core::ChainParams;

use super::dynamics::V3;
use super::{all_non_negative, all_positive, SettingsError};

/// Standard gravity (m/s^2).
pub const GRAVITY: f64 = 9.81;

/// One ARC-unit: a quadrotor whose centre is the joint (paper assumption A1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitModel {
    /// Mass (kg).
    pub mass: f64,
    /// Principal moments of inertia about body x, y, z (kg m^2).
    pub inertia: V3,
    /// Smallest collective thrust (N): rotors do not reverse.
    pub thrust_min: f64,
    /// Largest collective thrust (N).
    pub thrust_max: f64,
    /// Largest body moment about x, y, z (N m).
    pub max_moment: V3,
    /// Time constant of the first-order lag from commanded to produced thrust and
    /// moment (s): the motors' spin-up.
    pub motor_time_constant: f64,
}

impl Default for UnitModel {
    fn default() -> Self {
        Self {
            mass: 1.0,
            inertia: V3::new(0.0082, 0.0082, 0.0149),
            thrust_min: 0.5,
            // A thrust-to-weight ratio of about 2.2 for a unit carrying a link.
            thrust_max: 24.0,
            max_moment: V3::new(1.0, 1.0, 0.15),
            motor_time_constant: 0.02,
        }
    }
}

/// One link: a uniform rigid tube between two unit centres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinkModel {
    /// Mass (kg).
    pub mass: f64,
    /// Smallest moment of inertia used about the link's own axis (kg m^2). A thin
    /// tube's true value (about 5e-6) would only make the integration stiff: the twist
    /// about the axis is not actuated, not coupled to anything (the joints are
    /// spherical and at the axis) and not observed.
    pub min_axial_inertia: f64,
}

impl Default for LinkModel {
    fn default() -> Self {
        Self {
            mass: 0.1,
            min_axial_inertia: 1e-4,
        }
    }
}

impl LinkModel {
    /// Principal inertia of a link of length `l` about its axis (x) and across it.
    pub fn inertia(&self, l: f64) -> V3 {
        let across = self.mass * l * l / 12.0;
        V3::new(self.min_axial_inertia, across, across)
    }
}

/// Everything the dynamics need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChainModel {
    /// Geometry and joint limits.
    pub params: ChainParams,
    /// Every unit.
    pub unit: UnitModel,
    /// Every link.
    pub link: LinkModel,
    /// Gravity along -z (m/s^2).
    pub gravity: f64,
}

impl ChainModel {
    /// The default bodies for the chain `params`.
    pub fn new(params: ChainParams) -> Self {
        Self {
            params,
            unit: UnitModel::default(),
            link: LinkModel::default(),
            gravity: GRAVITY,
        }
    }

    /// Number of units N.
    pub fn units(&self) -> usize {
        self.params.n()
    }

    /// Link length l (m).
    pub fn link_length(&self) -> f64 {
        self.params.link_length as f64
    }

    /// Total mass (kg).
    pub fn total_mass(&self) -> f64 {
        let n = self.units() as f64;
        n * self.unit.mass + (n - 1.0) * self.link.mass
    }

    /// Checks that every number is finite and physical.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let u = &self.unit;
        SettingsError::check(
            all_positive(&[u.mass]) && all_positive(u.inertia.as_slice()),
            "unit mass and inertia must be positive",
        )?;
        SettingsError::check(
            all_non_negative(&[u.thrust_min])
                && all_positive(&[u.thrust_max])
                && u.thrust_max > u.thrust_min,
            "unit thrust limits must satisfy 0 <= min < max",
        )?;
        SettingsError::check(
            all_positive(u.max_moment.as_slice()) && all_positive(&[u.motor_time_constant]),
            "unit moment limits and motor time constant must be positive",
        )?;
        SettingsError::check(
            all_positive(&[self.link.mass, self.link.min_axial_inertia, self.gravity]),
            "link mass, axial inertia and gravity must be positive",
        )?;
        // Every unit must be able to hover with its share of the links.
        let hover = (u.mass + self.link.mass) * self.gravity;
        if u.thrust_max < 1.2 * hover {
            return Err(SettingsError::ThrustMargin {
                thrust_max: u.thrust_max,
                hover,
            });
        }
        Ok(())
    }
}
