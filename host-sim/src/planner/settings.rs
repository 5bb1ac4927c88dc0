//! The ARC planner's parameters: shape sources, shape preference and the numbers
//! of its roadmap and online construction.

/// Which shape sources the planner may use (the paper's ablation).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// Library and random shapes (the full ARCplanner).
    Both,
    /// Library shapes only.
    Lsc,
    /// Random shapes only (plus yaw rotations of the current shape).
    Srs,
}

/// What the planner prefers when several shapes fit.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Preference {
    /// Keep the shape as long as it fits; cheapest change otherwise.
    #[default]
    Least,
    /// Fly the sensor-coverage polygon PN wherever it fits (the silo demo).
    Coverage,
}

/// Planner parameters; every one has a command-line flag. In a file (serde), a field
/// left out takes its default.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Settings {
    /// Head roadmap vertices `M_VT`.
    pub vertices: usize,
    /// Head roadmap connection radius `r_T` (m).
    pub r_t: f64,
    /// Most neighbours a vertex takes (the nearest within `r_T`).
    pub max_neighbours: usize,
    /// Discrete headings per library shape and rotations of the current shape.
    pub n_psi: usize,
    /// `G_Val` connection radius `d_c` (`C_T` metric); `None`: the roadmap radius
    /// `aerial_chain_core::srs::default_r_s` for the chain and the SRS size.
    pub d_c: Option<f32>,
    /// Shape sources.
    pub mode: Mode,
    /// Shape preference.
    pub prefer: Preference,
    /// Seed of the uniform roadmap's sampler (unused by a query that flies the
    /// lattice's head route alone).
    pub seed: u64,
    /// Replans (dropped head edges) allowed without progress (the chain reaching a
    /// vertex farther along its way than before) before the roadmap grows.
    pub max_replans: usize,
    /// Times a failing query may double the roadmap and try again.
    pub max_growth: usize,
    /// How strongly head paths avoid passing close to obstacles (0: shortest paths,
    /// as in the paper); see `super::roadmap::Roadmap::build`.
    pub clearance_weight: f64,
    /// Step (m) of follow-the-leader motion (`super::follow`), tried after the library
    /// and before SRSConnect; 0 turns it off (the paper's planner).
    pub follow_step: f64,
    /// Smallest clearance margin (m) the planner may give way to where a passage is
    /// narrower than the context's (preferred) clearance; 0 is docs/model.md's exact
    /// contract. Values above the preferred clearance are taken as it.
    pub clearance_min: f64,
    /// Search a head route over the half-cell lattice of the map (`super::lattice`) and add
    /// it to the roadmap before each query; off: the paper's uniform roadmap only.
    pub head_lattice: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            vertices: 1500,
            r_t: 1.5,
            max_neighbours: 30,
            n_psi: 8,
            d_c: None,
            mode: Mode::Both,
            prefer: Preference::Least,
            seed: 1,
            max_replans: 200,
            max_growth: 3,
            clearance_weight: 2.0,
            follow_step: 0.1,
            clearance_min: 0.0,
            head_lattice: true,
        }
    }
}
