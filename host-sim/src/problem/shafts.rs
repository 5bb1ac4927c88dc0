//! Shafts: two storeys joined by a square hatch through a floor, for the refusals a
//! unit's sphere cannot prove.
//!
//! `shaft:KEY=VALUE,...`: a 10 x 5 m building of two 2.4 m storeys inside a 0.2 m
//! shell, the floor between them `depth` thick with a `w` square hatch 6 m along it.
//!
//! | key | default | meaning |
//! |---|---|---|
//! | `w` | 0.45 | the hatch's side (m), 0.3 to 1.5, widened to whole voxels |
//! | `depth` | 1.5 | the floor's thickness (m), 0.1 to 2 |
//! | `res` | 0.05 | map resolution (m), 0.025 to 0.1 |
//!
//! The head starts in the lower storey 1.5 m before the hatch's axis, looking at it
//! (room behind for N = 8), and the goal is in the upper storey 1.5 m beyond it; the route runs straight up the
//! hatch's axis. A unit's sphere fits a hatch wider than `2 (r_u + c)`, but a link may
//! pitch no more than `theta_max` (60 degrees): half way down a floor deeper than
//! `2 l sin(theta_max)` (0.87 m) both ends of every link lie in the hatch, at least
//! `l cos(theta_max)` (0.25 m) apart across it, which a hatch narrower than
//! `2 (r_u + c) + l cos(theta_max) / sqrt(2)` (0.477 m with no clearance) cannot
//! hold ([`ShaftSpec::closed`]). Such
//! a shaft passes the head and no chain: `arc plan` must refuse it with a proof
//! (`planner::linked`), not search until its time limit. The route is the head's, not
//! a witness.

use super::scenarios::{fill, points, shell_box, Scenario};
use super::spec::{Family, Key, Values::Real};
use super::ProblemError;
use crate::map::grid::Cell;

/// Parameters of one shaft.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShaftSpec {
    /// The hatch's side (m).
    pub w: f64,
    /// The floor's thickness (m).
    pub depth: f64,
    /// Map resolution (m).
    pub res: f64,
}

impl Default for ShaftSpec {
    fn default() -> Self {
        Self {
            w: 0.45,
            depth: 1.5,
            res: 0.05,
        }
    }
}

impl Family for ShaftSpec {
    const FAMILY: &'static str = "shaft";
    const KEYS: &'static [Key<Self>] = &[
        Key::new("w", Real(0.3, 1.5), |s| &mut s.w),
        Key::new("depth", Real(0.1, 2.0), |s| &mut s.depth),
        Key::new("res", Real(0.025, 0.1), |s| &mut s.res),
    ];
}

/// The building's length (x) and width (m), where the hatch's axis stands (x, m), a
/// storey's height (m) and the shell's thickness (m).
const SIZE: [f64; 2] = [10.0, 5.0];
const AXIS_X: f64 = 6.0;
const STOREY: f64 = 2.4;
const SHELL: f64 = 0.2;
/// How far from the hatch's axis the head starts and ends (m), and at what height
/// above its storey's floor.
const ASIDE: f64 = 1.5;
const HEIGHT: f64 = 1.2;

impl ShaftSpec {
    /// Whether no chain of `params` passes, by the argument of the module docs: the
    /// floor is deeper than `2 l sin(theta_max)` and the hatch as built narrower than
    /// `2 r_u + l cos(theta_max) / sqrt(2)` (a clearance only narrows it further).
    pub fn closed(&self, params: &aerial_chain_core::ChainParams) -> bool {
        let (l, t) = (f64::from(params.link_length), f64::from(params.theta_max));
        self.depth > 2.0 * l * t.sin()
            && self.side() < 2.0 * f64::from(params.unit_radius) + l * t.cos() / 2f64.sqrt()
    }

    /// The hatch's side as built (m): `w` widened to whole voxels.
    pub fn side(&self) -> f64 {
        self.voxels() * self.res
    }

    /// How many voxels the hatch spans across.
    fn voxels(&self) -> f64 {
        (self.w / self.res - 1e-9).ceil()
    }

    /// The hatch's corners (x, y): whole voxels, at least `w` across, centred as near
    /// `(AXIS_X, SIZE[1] / 2)` as the voxels allow.
    fn hatch(&self) -> ([f64; 2], [f64; 2]) {
        let (r, n) = (self.res, self.voxels());
        let corner = |c: f64| {
            (
                (c / r - n / 2.0).round() * r,
                ((c / r - n / 2.0).round() + n) * r,
            )
        };
        let (x0, x1) = corner(AXIS_X);
        let (y0, y1) = corner(SIZE[1] / 2.0);
        ([x0, y0], [x1, y1])
    }

    /// The scenario.
    pub fn build(&self) -> Result<Scenario, ProblemError> {
        self.check()?;
        let floor = SHELL + STOREY;
        let top = floor + self.depth;
        let mut g = shell_box([SIZE[0], SIZE[1], top + STOREY + SHELL], self.res, SHELL);
        fill(
            &mut g,
            [0.0, 0.0, floor],
            [SIZE[0], SIZE[1], top],
            Cell::Occupied,
        );
        let (lo, hi) = self.hatch();
        fill(
            &mut g,
            [lo[0], lo[1], floor],
            [hi[0], hi[1], top],
            Cell::Free,
        );
        let (x, y) = ((lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0);
        let (low, high) = (SHELL + HEIGHT, top + HEIGHT);
        let start = [x - ASIDE, y, low];
        let goal = [x + ASIDE, y, high];
        Ok(Scenario {
            name: self.name(),
            description: format!(
                "Two storeys at {} m joined by a {} m square hatch through a {} m floor; the \
                 head flies from the lower storey up the hatch to the upper one.",
                self.res, self.w, self.depth
            ),
            grid: g,
            start: start.into(),
            start_yaw: 0.0,
            goal: goal.into(),
            default_units: 4,
            route: points(&[start, [x, y, low], [x, y, high], goal]),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hatch_is_open_through_the_floor_and_the_floor_closed_beside_it() {
        let s = ShaftSpec::parse("w=0.5,depth=1,res=0.05").unwrap();
        let sc = s.build().unwrap();
        let g = &sc.grid;
        let (lo, hi) = s.hatch();
        assert!((hi[0] - lo[0] - 0.5).abs() < 1e-9 && (hi[1] - lo[1] - 0.5).abs() < 1e-9);
        let (x, y, mid) = (AXIS_X, SIZE[1] / 2.0, SHELL + STOREY + 0.5);
        assert!(!g.is_obstacle_at([x, y, mid]));
        assert!(!g.is_obstacle_at([x + 0.2, y - 0.2, mid]));
        assert!(g.is_obstacle_at([x + 0.3, y, mid]));
        assert!(g.is_obstacle_at([x - 1.0, y, mid]));
        assert!(!g.is_obstacle_at(sc.start));
        assert!(!g.is_obstacle_at(sc.goal));
        assert!(sc.goal.z - sc.start.z > 3.0);
    }

    #[test]
    fn deep_narrow_shafts_are_closed_and_wide_or_shallow_ones_are_not() {
        let p = aerial_chain_core::ChainParams::new(4);
        let closed = |t: &str| ShaftSpec::parse(t).unwrap().closed(&p);
        assert!(closed("w=0.45,depth=1,res=0.05"));
        assert!(closed("w=0.4,depth=1.5,res=0.087"));
        // 0.45 m widened to 0.522 m at 0.087 m: room for a link across the diagonal.
        assert!(!closed("w=0.45,depth=1.5,res=0.087"));
        assert!(!closed("w=0.45,depth=0.8,res=0.05"));
    }

    #[test]
    fn keys_out_of_range_are_refused() {
        assert!(ShaftSpec::parse("w=0.2").is_err());
        assert!(ShaftSpec::parse("depth=3").is_err());
    }
}
