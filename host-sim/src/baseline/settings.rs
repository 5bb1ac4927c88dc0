//! The full-state PRM's settings: vertex budget, neighbours, goal samples, seed.

use super::PrmError;

/// Settings of the full-state PRM.
#[derive(Clone, Debug, PartialEq)]
pub struct PrmSettings {
    /// Vertex budget `M_F` (sampled configurations, goal samples included).
    pub vertices: usize,
    /// Neighbours per vertex; `None`: the PRM* rule ([`prm_star_k`]).
    pub k: Option<usize>,
    /// Configurations sampled in the goal ball; `None`: 1% of the budget, at least 10.
    pub goal_samples: Option<usize>,
    /// Seed of the sampler.
    pub seed: u64,
}

impl Default for PrmSettings {
    fn default() -> Self {
        Self {
            vertices: 1500,
            k: None,
            goal_samples: None,
            seed: 1,
        }
    }
}

impl PrmSettings {
    /// Checks the numbers (a vertex budget of at least 1, `k >= 1`).
    pub fn validate(&self) -> Result<(), PrmError> {
        if self.vertices == 0 {
            return Err(PrmError::BadSettings("vertices must be at least 1".into()));
        }
        if self.k == Some(0) {
            return Err(PrmError::BadSettings("k must be at least 1".into()));
        }
        Ok(())
    }

    pub(super) fn goal_count(&self) -> usize {
        self.goal_samples
            .unwrap_or((self.vertices / 100).max(10))
            .min(self.vertices)
    }
}

/// The PRM* neighbour count `ceil(e (1 + 1/d) ln n)` for `n` vertices in dimension `d`
/// (at least 1).
pub fn prm_star_k(n: usize, d: usize) -> usize {
    let n = n.max(2) as f64;
    let d = d.max(1) as f64;
    ((std::f64::consts::E * (1.0 + 1.0 / d) * n.ln()).ceil() as usize).max(1)
}
