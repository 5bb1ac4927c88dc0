//! What the online planner believes of the world: the seen map (OctoMap's fusion) and
//! two distance fields over the world's box that follow it voxel by voxel, one with
//! unknown space occupied (what a committed piece is checked on) and one with unknown
//! space free (what the route to the goal is searched on).

use std::sync::Arc;
use std::time::Instant;

use nalgebra::Point3;

use crate::map::{Cell, DistanceField, Grid, GridError};
use crate::sensing::occupancy::FusionError;
use crate::sensing::{OccupancyMap, PointCloud, VoxelChange};

/// The seen map and its two distance fields.
#[derive(Clone, Debug)]
pub struct Belief {
    seen: OccupancyMap,
    commit: Arc<DistanceField>,
    route: DistanceField,
    changed: usize,
    update_s: f64,
}

/// What one observation changed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Fused {
    /// Voxels inside the box whose state changed.
    pub voxels: usize,
    /// Time spent updating both distance fields (s).
    pub update_s: f64,
    /// The voxels among them that became occupied (lattice indices).
    pub occupied: Vec<[i32; 3]>,
}

impl Belief {
    /// Nothing seen yet in the box of `bounds` (its origin, dimensions and resolution;
    /// its contents are not read), or, with `prior`, what `prior` knows inside that box
    /// (a map of the same resolution whose known voxels count as seen).
    pub fn new(bounds: &Grid, prior: Option<&Grid>) -> Result<Self, GridError> {
        let (res, origin, dims) = (bounds.resolution(), bounds.origin(), bounds.dims());
        let mut commit = Grid::new(res, origin, dims, Cell::Unknown, true)?;
        let mut route = walled_box(res, origin, dims)?;
        let mut seen = OccupancyMap::new(res).map_err(|_| GridError::Resolution(res))?;
        if let Some(prior) = prior {
            for (i, occupied) in prior.known_voxels() {
                if commit.local(i).is_some() {
                    let state = if occupied { Cell::Occupied } else { Cell::Free };
                    commit.set(i, state);
                    route.set(i, state);
                    seen.assume(i, state);
                }
            }
        }
        let mut commit = DistanceField::new(commit);
        let mut route = DistanceField::new(route);
        commit.prepare_updates();
        route.prepare_updates();
        Ok(Self {
            seen,
            commit: Arc::new(commit),
            route,
            changed: 0,
            update_s: 0.0,
        })
    }

    /// Fuses a sensor's point cloud (world frame, its origin the sensor's) as OctoMap's
    /// `insertPointCloud` does, rays without a return cleared to `max_range`.
    pub fn fuse(&mut self, cloud: &PointCloud, max_range: f64) -> Result<Fused, FusionError> {
        let changes = self.seen.insert(cloud, max_range)?;
        Ok(self.apply(&changes))
    }

    /// Marks free the voxels whose cubes lie inside the ball of `radius` about every
    /// point of `centres` (the space the chain's bodies fill as they fly).
    pub fn mark_flown(
        &mut self,
        centres: &[Point3<f64>],
        radius: f64,
    ) -> Result<Fused, FusionError> {
        let mut changes = Vec::new();
        for c in centres {
            changes.extend(self.seen.mark_free_sphere(*c, radius)?);
        }
        Ok(self.apply(&changes))
    }

    /// Marks free the voxels whose cubes come within `radius` of each segment of
    /// `bodies` (a ball where its ends agree): the space around a configuration known
    /// to be valid with that clearance.
    pub fn mark_clear(
        &mut self,
        bodies: &[(Point3<f64>, Point3<f64>, f64)],
    ) -> Result<Fused, FusionError> {
        let mut changes = Vec::new();
        for (a, b, r) in bodies {
            changes.extend(self.seen.mark_free_near(*a, *b, *r)?);
        }
        Ok(self.apply(&changes))
    }

    /// Updates both fields for `changes` (the voxels outside the box are kept in the
    /// seen map only: the planner never leaves the box).
    fn apply(&mut self, changes: &[VoxelChange]) -> Fused {
        let grid = self.commit.grid();
        let inside: Vec<([i32; 3], Cell)> = changes
            .iter()
            .filter(|c| grid.local(c.voxel).is_some())
            .map(|c| (c.voxel, c.new))
            .collect();
        if inside.is_empty() {
            return Fused::default();
        }
        let began = Instant::now();
        // Inside the box by the filter above, so neither update can refuse.
        let commit = Arc::make_mut(&mut self.commit);
        commit.update(&inside).expect("changes inside the box");
        self.route.update(&inside).expect("changes inside the box");
        let update_s = began.elapsed().as_secs_f64();
        self.changed += inside.len();
        self.update_s += update_s;
        Fused {
            voxels: inside.len(),
            update_s,
            occupied: inside
                .iter()
                .filter(|(_, cell)| *cell == Cell::Occupied)
                .map(|(v, _)| *v)
                .collect(),
        }
    }

    /// The seen map.
    pub fn seen(&self) -> &OccupancyMap {
        &self.seen
    }

    /// The distance field with unknown space occupied (shared with the planner of a
    /// replan; updates copy it only while a planner holds it).
    pub fn commit_field(&self) -> &Arc<DistanceField> {
        &self.commit
    }

    /// The distance field with unknown space free, over the box and a layer of
    /// occupied voxels around it: a plan never leaves the box (unknown space outside it
    /// is occupied to the pieces), so neither may the route, nor its proof.
    pub fn route_field(&self) -> &DistanceField {
        &self.route
    }

    /// Voxels changed inside the box so far.
    pub fn changed(&self) -> usize {
        self.changed
    }

    /// Time spent updating the fields so far (s).
    pub fn update_s(&self) -> f64 {
        self.update_s
    }
}

/// The box of `dims` voxels from lattice index `origin`, unknown inside (free to the
/// route) and wrapped in one layer of occupied voxels.
fn walled_box(res: f64, origin: [i32; 3], dims: [usize; 3]) -> Result<Grid, GridError> {
    let mut g = Grid::new(
        res,
        origin.map(|o| o - 1),
        dims.map(|d| d + 2),
        Cell::Occupied,
        false,
    )?;
    // The centres of the box's first and last voxels along each axis.
    let first = origin.map(|o| (o as f64 + 0.5) * res);
    let last = [0, 1, 2].map(|a| (origin[a] as f64 + dims[a] as f64 - 0.5) * res);
    g.fill_box(first, last, Cell::Unknown);
    Ok(g)
}
