//! The set of random shapes (SRS) and its roadmap `G_SRS` (paper Alg. 2).
//!
//! Offline and map-independent: `N_SRS` random shapes that are valid (limits and
//! self-collision, with [`crate::lsc::LIMIT_MARGIN`] of slack), and a graph joining
//! shapes within `r_S` of each other (in the `C_T` metric) whose straight
//! interpolation stays valid. Seeded and reproducible: the same parameters and seed
//! give the same shapes on every machine (PCG32 is a fixed algorithm, and every
//! computation is plain `f32` with libm).
//!
//! Storage is the caller's: [`Sampler`] is an iterator of shapes and
//! [`build_roadmap`] fills caller-provided adjacency lists, so the host can use
//! vectors while [`Srs`] keeps everything in fixed capacity for no-alloc use.

use core::f32::consts::PI;

use rand_core::{RngCore, SeedableRng};
use rand_pcg::Pcg32;

use crate::cost::transition_cost_sq_within;
use crate::lsc::LIMIT_MARGIN;
use crate::params::ChainParams;
use crate::shape::Shape;
use crate::validity::{bend, check_transition};

/// Neighbour list of one roadmap vertex (indices into the shape list).
pub type Neighbours<const DEG: usize> = heapless::Vec<u16, DEG>;

/// Roadmap candidates of one vertex: `(C_T^2, index)`, nearest first (see
/// [`nearest_later`]).
pub type Candidates<const DEG: usize> = heapless::Vec<(f32, u16), DEG>;

/// Settings of the offline SRS build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SrsSettings {
    /// Number of shapes `N_SRS`.
    pub count: usize,
    /// Seed of the random stream.
    pub seed: u64,
    /// Roadmap connection radius `r_S` in the `C_T` metric.
    pub r_s: f32,
    /// Tries per shape before sampling gives up (a chain whose limits leave almost
    /// no valid shapes would otherwise loop for ever).
    pub max_tries_per_shape: u32,
}

impl SrsSettings {
    /// `count` shapes for a chain of `units` units: `r_S` = [`default_r_s`], 100 000
    /// tries per shape.
    pub fn new(units: u8, count: usize, seed: u64) -> Self {
        Self {
            count,
            seed,
            r_s: default_r_s(units, count),
            max_tries_per_shape: 100_000,
        }
    }
}

/// Default roadmap radius `r_S` (in `C_T`) for `count` shapes of a chain of `units`.
///
/// Between two random shapes `C_T` grows like N (its weights sum to N^2), and the
/// nearest of `count` samples in the 2N-1 dimensions of a shape sits at about
/// `count^(-1/(2N-1))` of that spread: `1.8 N count^(-1/(2N-1))` gives a roadmap of
/// useful degree for every N (3.0 for N = 4 and 500 shapes).
pub fn default_r_s(units: u8, count: usize) -> f32 {
    let dims = (2 * units as u32).saturating_sub(1).max(1) as f32;
    1.8 * units as f32 * libm::powf(count.max(2) as f32, -1.0 / dims)
}

/// Why an SRS could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SrsError {
    /// More shapes were asked for than the storage holds (or than u16 indices reach).
    Capacity,
    /// No valid shape was found within `max_tries_per_shape` tries.
    SamplingFailed,
}

impl core::fmt::Display for SrsError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::Capacity => "more shapes requested than the capacity holds",
            Self::SamplingFailed => "no valid random shape found within the try budget",
        })
    }
}

/// An endless stream of valid random shapes.
///
/// Each link's pitch is uniform in the pitch limits, each yaw uniform on the
/// circle; a link whose bend with the one before breaks the limit is redrawn on
/// the spot (which keeps N = 16 affordable), and a shape that self-collides is
/// thrown away whole. The head looks along its first link.
pub struct Sampler {
    params: ChainParams,
    rng: Pcg32,
    max_tries: u32,
}

impl Sampler {
    /// A sampler for `params` (validated) seeded with `seed`.
    pub fn new(params: ChainParams, seed: u64, max_tries: u32) -> Self {
        Self {
            params,
            rng: Pcg32::seed_from_u64(seed),
            max_tries,
        }
    }

    /// Uniform in `[lo, hi)`, from 24 random bits.
    fn uniform(&mut self, lo: f32, hi: f32) -> f32 {
        let u = (self.rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32;
        lo + (hi - lo) * u
    }

    /// One candidate with every bend within limits, or None after too many redraws.
    fn candidate(&mut self) -> Option<Shape> {
        let p = self.params;
        let pitch_max = p.theta_max - LIMIT_MARGIN;
        let mut s = Shape::line(p.units, 0.0);
        for k in 0..s.links() {
            let mut ok = false;
            for _ in 0..64 {
                let pitch = self.uniform(-pitch_max, pitch_max);
                let yaw = self.uniform(-PI, PI);
                s.set_link(k, pitch, yaw);
                if k == 0 || bend(&s, k - 1) <= p.beta_max - LIMIT_MARGIN {
                    ok = true;
                    break;
                }
            }
            if !ok {
                return None;
            }
        }
        s.set_head_yaw(s.yaw(0));
        Some(s)
    }

    /// The next valid shape, or `SamplingFailed`.
    pub fn next_shape(&mut self) -> Result<Shape, SrsError> {
        for _ in 0..self.max_tries {
            if let Some(s) = self.candidate() {
                if check_transition(&self.params, &s, &s, LIMIT_MARGIN).is_ok() {
                    return Ok(s);
                }
            }
        }
        Err(SrsError::SamplingFailed)
    }
}

/// Fills `adjacency[i]` with the roadmap neighbours of `shapes[i]`: up to `DEG`
/// nearest shapes within `r_s` (in `C_T`) whose straight transition is valid, with
/// [`LIMIT_MARGIN`] of slack. Edges are symmetric; a vertex whose list is full
/// takes no more. Quadratic in the number of shapes; the host finds the same
/// candidates faster with an index ([`nearest_later`] on fewer shapes, then
/// [`connect`]).
pub fn build_roadmap<const DEG: usize>(
    params: &ChainParams,
    shapes: &[Shape],
    r_s: f32,
    adjacency: &mut [Neighbours<DEG>],
) {
    for a in adjacency.iter_mut() {
        a.clear();
    }
    for i in 0..shapes.len() {
        let near = nearest_later::<DEG>(shapes, i, r_s, i + 1..shapes.len());
        connect(params, shapes, i, &near, adjacency);
    }
}

/// Roadmap candidates of `shapes[i]`: the `DEG` nearest of `later` (indices above
/// `i`, ascending) within `r_s` in `C_T`, nearest first, as `(C_T^2, index)`; of
/// equally near shapes the lower index. `later` may skip shapes that are provably
/// farther than `r_s`: the result is the same.
pub fn nearest_later<const DEG: usize>(
    shapes: &[Shape],
    i: usize,
    r_s: f32,
    later: impl Iterator<Item = usize>,
) -> Candidates<DEG> {
    let r2 = r_s * r_s;
    let mut near: Candidates<DEG> = heapless::Vec::new();
    for j in later {
        // Only a shape nearer than the farthest kept one can enter: stop summing
        // its cost as soon as it cannot (the same costs, far fewer terms).
        let bound = match near.last() {
            Some(&(last, _)) if near.is_full() => last.min(r2),
            _ => r2,
        };
        let Some(d) = transition_cost_sq_within(&shapes[i], &shapes[j], bound) else {
            continue;
        };
        if near.is_full() {
            if d >= near[DEG - 1].0 {
                continue;
            }
            near.pop();
        }
        let at = near.iter().position(|&(e, _)| e > d).unwrap_or(near.len());
        let _ = near.insert(at, (d, j as u16));
    }
    near
}

/// Joins `shapes[i]` to its candidates `near` (from [`nearest_later`]), nearest
/// first, where both lists have room and the straight transition is valid. Called
/// for `i` in ascending order, it builds the roadmap of [`build_roadmap`].
pub fn connect<const DEG: usize>(
    params: &ChainParams,
    shapes: &[Shape],
    i: usize,
    near: &[(f32, u16)],
    adjacency: &mut [Neighbours<DEG>],
) {
    for &(_, j) in near.iter() {
        let j = j as usize;
        if adjacency[i].is_full() || adjacency[j].is_full() {
            continue;
        }
        if check_transition(params, &shapes[i], &shapes[j], LIMIT_MARGIN).is_ok() {
            let _ = adjacency[i].push(j as u16);
            let _ = adjacency[j].push(i as u16);
        }
    }
}

/// An SRS in fixed capacity: at most `CAP` shapes, at most `DEG` neighbours each.
#[derive(Clone, Debug)]
pub struct Srs<const CAP: usize, const DEG: usize> {
    /// The chain the shapes are for.
    pub params: ChainParams,
    /// The shapes `L_SRS`.
    pub shapes: heapless::Vec<Shape, CAP>,
    /// `adjacency[i]`: neighbours of shape `i` in `G_SRS`.
    pub adjacency: heapless::Vec<Neighbours<DEG>, CAP>,
}

impl<const CAP: usize, const DEG: usize> Srs<CAP, DEG> {
    /// Samples `settings.count` shapes and builds their roadmap.
    pub fn generate(params: ChainParams, settings: &SrsSettings) -> Result<Self, SrsError> {
        if settings.count > CAP || settings.count > u16::MAX as usize + 1 {
            return Err(SrsError::Capacity);
        }
        let mut sampler = Sampler::new(params, settings.seed, settings.max_tries_per_shape);
        let mut srs = Self {
            params,
            shapes: heapless::Vec::new(),
            adjacency: heapless::Vec::new(),
        };
        for _ in 0..settings.count {
            let s = sampler.next_shape()?;
            srs.shapes.push(s).map_err(|_| SrsError::Capacity)?;
            srs.adjacency
                .push(Neighbours::new())
                .map_err(|_| SrsError::Capacity)?;
        }
        build_roadmap(&params, &srs.shapes, settings.r_s, &mut srs.adjacency);
        Ok(srs)
    }

    /// Number of roadmap edges (each counted once).
    pub fn edge_count(&self) -> usize {
        self.adjacency.iter().map(|a| a.len()).sum::<usize>() / 2
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::validity::check_shape;
    use proptest::prelude::*;

    #[test]
    fn same_seed_same_shapes() {
        let p = ChainParams::new(6);
        let a = Srs::<60, 8>::generate(p, &SrsSettings::new(6, 60, 7)).unwrap();
        let b = Srs::<60, 8>::generate(p, &SrsSettings::new(6, 60, 7)).unwrap();
        let c = Srs::<60, 8>::generate(p, &SrsSettings::new(6, 60, 8)).unwrap();
        assert_eq!(a.shapes, b.shapes);
        assert_eq!(a.adjacency, b.adjacency);
        assert_ne!(a.shapes, c.shapes);
        assert!(a.edge_count() > 0);
    }

    #[test]
    fn capacity_is_checked() {
        let p = ChainParams::new(4);
        assert_eq!(
            Srs::<10, 4>::generate(p, &SrsSettings::new(4, 11, 1)).unwrap_err(),
            SrsError::Capacity
        );
    }

    #[test]
    fn impossible_limits_fail_instead_of_looping() {
        // A bend limit of 0.5 mrad is below the sampler's margin: nothing is valid.
        let p = ChainParams {
            beta_max: 5e-4,
            ..ChainParams::new(4)
        };
        let s = SrsSettings {
            max_tries_per_shape: 50,
            ..SrsSettings::new(4, 3, 1)
        };
        assert_eq!(
            Srs::<3, 2>::generate(p, &s).unwrap_err(),
            SrsError::SamplingFailed
        );
    }

    #[test]
    fn sixteen_units_sample() {
        let p = ChainParams::new(16);
        let srs = Srs::<20, 6>::generate(p, &SrsSettings::new(16, 20, 3)).unwrap();
        assert!(srs.shapes.iter().all(|s| check_shape(&p, s).is_ok()));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(12))]
        /// Every sampled shape is valid, every roadmap edge interpolates validly
        /// (checked here by dense sampling with the exact single-shape test), and
        /// edges are symmetric.
        #[test]
        fn shapes_and_edges_are_valid(n in 3u8..9, seed in 0u64..1000) {
            let p = ChainParams::new(n);
            let srs = Srs::<40, 6>::generate(p, &SrsSettings::new(n, 40, seed)).unwrap();
            for s in &srs.shapes {
                prop_assert!(check_shape(&p, s).is_ok());
            }
            for (i, nb) in srs.adjacency.iter().enumerate() {
                for &j in nb {
                    prop_assert!(srs.adjacency[j as usize].contains(&(i as u16)));
                    let (a, b) = (&srs.shapes[i], &srs.shapes[j as usize]);
                    for step in 0..=200 {
                        let s = a.lerp(b, step as f32 / 200.0);
                        prop_assert!(check_shape(&p, &s).is_ok(), "edge {i}-{j} invalid at {step}/200");
                    }
                }
            }
        }
    }
}
