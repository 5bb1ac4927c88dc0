//! What the units see while the chain flies: every unit's sensor scans the true map at
//! the sensor rate, from the unit's flown pose (tilt included), and the scans are fused
//! into the map that grows (docs/maps.md, "Sensing"). The space the chain's bodies fill
//! (`r_u` plus the clearance around every unit centre), at every recorded step, counts
//! as observed free: the chain was there.

use serde::{Deserialize, Serialize};

use super::occupancy::FusionError;
use super::{DepthSensor, OccupancyMap, PointCloud, SensorError, UnitPose, VoxelChange};
use crate::map::Grid;
use crate::sim::Sample;

/// The sensor rate by default (Hz): a small depth camera's frame rate for mapping.
pub const DEFAULT_RATE_HZ: f64 = 10.0;
/// Highest sensor rate (Hz): above it no camera of this kind delivers frames.
pub const MAX_RATE_HZ: f64 = 100.0;

/// The sensors of a survey: one per unit, all alike, and their rate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Survey {
    /// Every unit's sensor.
    pub sensor: DepthSensor,
    /// Scans per second of every sensor (Hz).
    pub rate_hz: f64,
}

impl Default for Survey {
    fn default() -> Self {
        Self {
            sensor: DepthSensor::default(),
            rate_hz: DEFAULT_RATE_HZ,
        }
    }
}

/// What a survey did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurveyStats {
    /// Scans fused (every unit at every sensor time).
    pub scans: usize,
    /// Rays cast.
    pub rays: usize,
    /// Voxels the map knows at the end.
    pub known: usize,
}

/// Why a survey cannot run.
#[derive(Debug, thiserror::Error)]
pub enum SurveyError {
    /// A sensor setting outside its limits.
    #[error("sensor: {0}")]
    Sensor(#[from] SensorError),
    /// A rate outside (0, MAX_RATE_HZ].
    #[error("rate_hz = {0}: a positive number of scans per second, at most {MAX_RATE_HZ}")]
    Rate(f64),
    /// The fusion refused an argument.
    #[error("fusion: {0}")]
    Fusion(#[from] FusionError),
}

impl Survey {
    /// Checks the sensor and the rate.
    pub fn validate(&self) -> Result<(), SurveyError> {
        self.sensor.validate()?;
        if !(self.rate_hz > 0.0 && self.rate_hz <= MAX_RATE_HZ) {
            return Err(SurveyError::Rate(self.rate_hz));
        }
        Ok(())
    }

    /// The map seen along a recorded flight over the true map `truth`: at the first
    /// recorded step and then every `1 / rate_hz` s every unit scans; at every recorded
    /// step every unit's sphere of radius `free_radius` (r_u plus the clearance) is
    /// marked free.
    pub fn fly(
        &self,
        truth: &Grid,
        samples: &[Sample],
        free_radius: f64,
    ) -> Result<(OccupancyMap, SurveyStats), SurveyError> {
        self.fly_with(truth, samples, free_radius, &mut |_| {})
    }

    /// [`Self::fly`], handing every insertion's changes of state to `on_change` as they
    /// happen (to update a distance field, or a planner's structures, where they reach).
    pub fn fly_with(
        &self,
        truth: &Grid,
        samples: &[Sample],
        free_radius: f64,
        on_change: &mut dyn FnMut(&[VoxelChange]),
    ) -> Result<(OccupancyMap, SurveyStats), SurveyError> {
        self.validate()?;
        let mut map = OccupancyMap::new(truth.resolution())?;
        let mut stats = SurveyStats::default();
        let mut next = samples.first().map_or(0.0, |s| s.t);
        for s in samples {
            if s.t + 1e-9 >= next {
                for (i, unit) in s.units.iter().enumerate() {
                    let q = unit.q.map(f64::from);
                    let pose = UnitPose::new(unit.p.map(f64::from), q)?;
                    let scan = super::raycast::scan(truth, &self.sensor.for_unit(i), &pose);
                    stats.rays += scan.rays.len();
                    let cloud = PointCloud::from_scan(&scan, truth.resolution());
                    on_change(&map.insert(&cloud, scan.max_range)?);
                    stats.scans += 1;
                }
                next += 1.0 / self.rate_hz;
            }
            for unit in &s.units {
                on_change(&map.mark_free_sphere(unit.p.map(f64::from), free_radius)?);
            }
        }
        stats.known = map.known();
        Ok((map, stats))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flying::{fly, FlyOptions};
    use crate::map::{Cell, Grid};
    use crate::planner::Query;
    use crate::planning::{plan, PlanOptions, Request};
    use crate::problem::scenarios;
    use crate::sim::{Flight, Progress};
    use aerial_chain_core::ChainParams;

    /// Scenario `name`, planned for `units` units as `arc plan` plans it and flown as
    /// `arc sim` flies it.
    fn flown(name: &str, units: u8) -> (scenarios::Scenario, ChainParams, Flight) {
        let sc = scenarios::build(name).unwrap();
        let params = ChainParams::new(units);
        let query = Query::new(sc.start, sc.start_shape(units).unwrap(), sc.goal);
        let request = Request::new(sc.grid.clone(), params, query);
        let planned = plan(&request, None, &PlanOptions::default()).unwrap();
        let options = FlyOptions::default();
        let (flight, _) = fly(&planned.plan, &sc.grid, &options, &Progress::default()).unwrap();
        (sc, params, flight)
    }

    #[test]
    fn what_the_units_see_along_a_flight_is_what_is_there() {
        let (sc, params, flight) = flown("window", 4);
        let survey = Survey::default();
        let r = params.unit_radius as f64 + crate::collision::DEFAULT_CLEARANCE;
        let (seen, stats) = survey.fly(&sc.grid, &flight.samples, r).unwrap();
        let duration = flight.samples.last().unwrap().t - flight.samples[0].t;
        let expected = ((duration * DEFAULT_RATE_HZ).floor() as usize + 1) * 4;
        assert!(
            stats.scans >= expected - 4 && stats.scans <= expected + 4,
            "{stats:?}"
        );
        assert!(stats.known > 10_000, "{stats:?}");
        let (mut occupied, mut free) = (0, 0);
        for (i, _) in seen.voxels() {
            match seen.state(i) {
                Cell::Occupied => {
                    occupied += 1;
                    assert_eq!(sc.grid.cell(i), Cell::Occupied, "seen occupied at {i:?}");
                }
                Cell::Free => {
                    free += 1;
                    assert_ne!(sc.grid.cell(i), Cell::Occupied, "seen free at {i:?}");
                }
                Cell::Unknown => {}
            }
        }
        assert!(
            occupied > 1000 && free > 1000,
            "{occupied} occupied, {free} free"
        );
        // Where the chain flew is free in the seen map.
        for s in &flight.samples {
            let p = s.units[0].p.map(f64::from);
            assert_eq!(seen.state(sc.grid.lattice_index(p)), Cell::Free);
        }
    }

    #[test]
    fn a_distance_field_updated_scan_by_scan_is_the_seen_maps_field() {
        let (sc, _, flight) = flown("maze", 5);
        // The box of the truth, all unknown (occupied) at first, as a chain entering it
        // knows it; the field follows every insertion.
        let (o, d) = (sc.grid.origin(), sc.grid.dims());
        let blank = Grid::new(sc.grid.resolution(), o, d, Cell::Unknown, true).unwrap();
        let mut field = crate::map::DistanceField::new(blank);
        field.prepare_updates();
        let mut batches = 0;
        let survey = Survey::default();
        let (seen, _) = survey
            .fly_with(&sc.grid, &flight.samples, 0.2, &mut |changes| {
                let inside: Vec<([i32; 3], Cell)> = changes
                    .iter()
                    .filter(|c| field.grid().local(c.voxel).is_some())
                    .map(|c| (c.voxel, c.new))
                    .collect();
                field.update(&inside).unwrap();
                batches += 1;
            })
            .unwrap();
        assert!(batches > 100);
        let fresh = crate::map::DistanceField::new(field.grid().clone());
        let mut checked = 0;
        for z in 0..d[2] as i32 {
            for y in 0..d[1] as i32 {
                for x in 0..d[0] as i32 {
                    let i = [o[0] + x, o[1] + y, o[2] + z];
                    assert_eq!(field.grid().cell(i), seen.state(i), "{i:?}");
                    let (a, b) = (field.voxel_clearance(i), fresh.voxel_clearance(i));
                    assert_eq!(a.to_bits(), b.to_bits(), "{i:?}: {a} updated, {b} rebuilt");
                    checked += 1;
                }
            }
        }
        assert!(checked > 100_000);
    }

    #[test]
    fn bad_rates_and_sensors_are_refused() {
        for rate in [0.0, -1.0, f64::NAN, 1e3] {
            let s = Survey {
                rate_hz: rate,
                ..Survey::default()
            };
            assert!(matches!(s.validate(), Err(SurveyError::Rate(_))));
        }
        let mut s = Survey::default();
        s.sensor.max_range = -1.0;
        assert!(matches!(s.validate(), Err(SurveyError::Sensor(_))));
    }
}
