//! Per-query state of the lattice points a search touches, in hash maps keyed by
//! packed lattice point, so that work and memory follow the free space explored.

use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

use super::HeadLattice;
use crate::map::distance::DistanceField;

/// A fast hasher for packed lattice keys (a multiplicative mix; keys are not hostile).
#[derive(Default, Clone, Copy)]
pub struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ b as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }
    fn write_u64(&mut self, v: u64) {
        let x = (v ^ (v >> 31)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        self.0 = x ^ (x >> 29);
    }
}

pub(super) type KeyMap<V> = HashMap<u64, V, BuildHasherDefault<KeyHasher>>;
pub(super) type KeySet = HashSet<u64, BuildHasherDefault<KeyHasher>>;

/// What a query knows about one lattice point.
#[derive(Clone, Copy)]
pub(super) struct Node {
    /// Clearance (m) when free at `r_min`, NaN when blocked.
    pub(super) clear: f32,
    /// A* cost so far (infinite: not reached).
    pub(super) g: f64,
    /// A* parent (`u64::MAX`: none).
    pub(super) parent: u64,
    /// Expanded by the A* (or reached by the flood from the start).
    pub(super) closed: bool,
    /// Reached by the flood from the goal.
    pub(super) flooded: bool,
}

/// Per-query state of the lattice points touched.
pub(super) struct Nodes<'a> {
    pub(super) lat: &'a HeadLattice,
    pub(super) field: &'a DistanceField,
    pub(super) map: KeyMap<Node>,
}

impl<'a> Nodes<'a> {
    /// No point touched yet on `lat` over `field`.
    pub(super) fn new(lat: &'a HeadLattice, field: &'a DistanceField) -> Self {
        Self {
            lat,
            field,
            map: KeyMap::default(),
        }
    }

    /// The point's record, its clearance computed on first touch.
    pub(super) fn get(&mut self, k: u64) -> &mut Node {
        let (lat, field) = (self.lat, self.field);
        self.map.entry(k).or_insert_with(|| {
            let c = lat.point_clearance(field, lat.point(k));
            Node {
                clear: c.map_or(f32::NAN, |v| v as f32),
                g: f64::INFINITY,
                parent: u64::MAX,
                closed: false,
                flooded: false,
            }
        })
    }

    /// The point's clearance when free.
    pub(super) fn clear(&mut self, k: u64) -> Option<f64> {
        let c = self.get(k).clear;
        (!c.is_nan()).then_some(c as f64)
    }
}
