//! Floating-point guards of the planner: not tuning. Each lies orders of magnitude
//! below anything the model resolves (docs/model.md checks lengths to 1e-6 m at the
//! finest and angles to the shape tables' `f32`), so it only keeps a division, a
//! normalisation or a comparison from deciding on rounding error; no plan of the
//! behaviour snapshot depends on its exact value.

/// Guards a division by a length or a product of lengths that may vanish (m, m^2).
pub(crate) const DIV_GUARD: f64 = 1e-12;

/// Ties and vanishing vectors (m, rad, or a share): below it two values are equal
/// and a vector has no direction.
pub(crate) const TIE: f64 = 1e-9;

/// A length (m) or an angle (rad) too small to matter: a point that moves less has
/// not moved; a direction shorter is none.
pub(crate) const TINY: f64 = 1e-6;

/// [`TINY`] for `f32` lengths (m): a track point nearer the last is the same point.
pub(crate) const TINY_F32: f32 = 1e-6;

/// [`DIV_GUARD`] for `f32` lengths (m^2).
pub(crate) const DIV_GUARD_F32: f32 = 1e-12;

/// Angles (rad) closer than this are the same shape: no shape change is needed.
pub(crate) const SAME_SHAPE: f32 = 1e-6;

/// Angles (rad) closer than this are the same shape for the candidates a shape change
/// chooses among (a change smaller than this is no change worth a check).
pub(crate) const DISTINCT_SHAPE: f32 = 1e-4;

/// Angles (rad) closer than this are the same library shape at a heading (carry's
/// candidates, whose headings differ by an eighth of a turn).
pub(crate) const SAME_HEADING: f32 = 1e-5;

/// Millimetres per metre: a length rounded down to millimetres is
/// `(x * PER_MILLIMETRE).floor() / PER_MILLIMETRE`.
pub(crate) const PER_MILLIMETRE: f64 = 1000.0;

/// Smallest length (m) a clearance or a sphere-tracing step counts: a millimetre, the
/// resolution the plan files record lengths to.
pub(crate) const MILLIMETRE: f64 = 1e-3;
