//! Problems to plan for: the built-in scenarios (the paper's rooms and more) and the
//! parametric families (hard cases `passage:`, `forest:`, `slot:`, `pipe:` and
//! `shaft:`), each a map with a start, a goal and a hand-made route that shows the
//! problem can be solved (a forest's and a shaft's: the head's way only).
//!
//! This layer sits above the map and collision layers (a scenario is a grid; the
//! reason a witness fails is the exact verifier's) and below plan files: the witness
//! plan itself is made in `crate::witness`.

pub mod families;
pub mod large;
pub mod passages;
pub mod pipes;
pub mod scenarios;
pub mod shafts;
pub mod spec;

use crate::collision::verify::PlanViolation;

/// Why a scenario cannot be built, or why its route gives no plan.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ProblemError {
    /// A name that is no built-in scenario.
    #[error(
        "unknown scenario {0:?}; known: {known}, corridor:LENGTH, passage:KEY=VALUE,..., forest:KEY=VALUE,..., slot:KEY=VALUE,..., pipe:KEY=VALUE,..., shaft:KEY=VALUE,..., campus[:RES], hall[:RES]",
        known = scenarios::NAMES.join(", ")
    )]
    UnknownScenario(String),
    /// `corridor:LENGTH` with a length that is no number.
    #[error("corridor length {0:?} is not a number")]
    CorridorLengthNotANumber(String),
    /// A corridor length outside [`scenarios::CORRIDOR_LENGTHS`].
    #[error("corridor length {0} m is outside 10..=100 m")]
    CorridorLength(f64),
    /// A `passage:` part without `=`.
    #[error("{0:?}: expected KEY=VALUE")]
    ExpectedKeyValue(String),
    /// A `passage:` value that is no number.
    #[error("{part:?}: {value:?} is not a number")]
    NotANumber {
        /// The whole `KEY=VALUE` part.
        part: String,
        /// The value as written.
        value: String,
    },
    /// A key that the family does not have.
    #[error("unknown key {0:?}; known: w, angle, offset, wall, door, door_offset, res, sealed, slit, slits (passage:), spacing, seed, res (forest:), tilt, angle, res (slot:), d, square, bends, radius, res (pipe:), w, depth, res (shaft:)")]
    UnknownKey(String),
    /// A count or seed that is not a whole number.
    #[error("{name} = {value} must be a whole number")]
    NotWhole {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A parameter outside its range.
    #[error("{name} = {value} is outside {lo}..={hi}")]
    OutOfRange {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The smallest allowed value.
        lo: f64,
        /// The largest allowed value.
        hi: f64,
    },
    /// Chain parameters that are not a valid chain.
    #[error("chain: {0}")]
    Chain(aerial_chain_core::ParamError),
    /// A grid the map layer refuses.
    #[error("grid: {0}")]
    Grid(#[from] crate::map::grid::GridError),
    /// A shape the chain model refuses.
    #[error("{0:?}")]
    Shape(aerial_chain_core::shape::ShapeError),
    /// A route step that is not a positive number.
    #[error("step {0} must be a positive number")]
    Step(f64),
    /// A route that does not run from the scenario's start to its goal.
    #[error("the route must run from the start to the goal")]
    RouteEnds,
    /// A route whose start leaves no room for the chain behind the head.
    #[error("the route's start is too short for the chain")]
    RouteTooShort,
    /// The follow-the-leader plan along the route fails the exact test.
    #[error("witness is invalid: {0:?}")]
    InvalidWitness(Option<PlanViolation>),
}
