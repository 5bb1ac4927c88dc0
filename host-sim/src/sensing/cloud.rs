//! A scan as the point cloud OctoMap's `insertPointCloud` takes: a sensor origin and
//! end points, `f32` (OctoMap's `point3d`), in W.

use nalgebra::Point3;

use super::raycast::{RayReturn, Scan};

/// How far a return's end point is moved from the hit point into the voxel it hit: along
/// the ray, as a fraction of a voxel edge, or, where that leaves the voxel, towards its
/// centre, as a fraction of the way. The hit point lies on the cube's face, which
/// OctoMap's `floor` may give to the free voxel in front; 1 % (at least 0.5 % of a voxel
/// edge from every face towards the centre) survives rounding to `f32` for coordinates
/// up to about 1 km at 0.05 m.
pub const ENDPOINT_NUDGE: f64 = 0.01;

/// A sensor origin and the end points of its rays (W, `f32` as OctoMap stores them).
#[derive(Clone, Debug, PartialEq)]
pub struct PointCloud {
    /// The sensor's origin.
    pub origin: [f32; 3],
    /// One end point per ray with a measurement.
    pub points: Vec<[f32; 3]>,
}

/// `p` rounded to `f32`, as OctoMap's `point3d` holds it.
pub fn to_f32(p: &Point3<f64>) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}

/// The end point of a return at `distance` along `direction` from `o` in `voxel`: a
/// little further along the ray ([`ENDPOINT_NUDGE`] of a voxel edge), so the segment
/// the fusion traverses stays on the ray, which entered no obstacle before; where that
/// point leaves the voxel (the ray entered it at an edge or a corner), the hit point
/// moved [`ENDPOINT_NUDGE`] of the way to the voxel's centre.
fn end_point(
    o: Point3<f64>,
    direction: nalgebra::Vector3<f64>,
    distance: f64,
    voxel: [i32; 3],
    resolution: f64,
) -> [f32; 3] {
    let hit = o + direction * distance;
    let along = to_f32(&(hit + direction * (ENDPOINT_NUDGE * resolution)));
    let key = along.map(|c| (f64::from(c) / resolution).floor() as i32);
    if key == voxel {
        return along;
    }
    let centre = Point3::from(voxel.map(|i| (f64::from(i) + 0.5) * resolution));
    to_f32(&(hit + (centre - hit) * ENDPOINT_NUDGE))
}

impl PointCloud {
    /// The cloud of a scan, as a depth camera's driver would give it to OctoMap:
    /// - a [`RayReturn::Hit`] gives its hit point moved a little into the voxel hit
    ///   (`end_point`): along the ray where it can, so that the segment traversed does
    ///   not tilt into an obstacle a grazing ray passes;
    /// - a ray without a return ([`RayReturn::Nothing`]) gives the point at twice the
    ///   maximum range along the ray, which the fusion, as OctoMap, clears up to the
    ///   maximum range without marking an end point;
    /// - a [`RayReturn::TooClose`] gives nothing: the sensor measured nothing valid.
    ///
    /// `resolution` is the voxel edge of the map the scan was cast in.
    pub fn from_scan(scan: &Scan, resolution: f64) -> PointCloud {
        let o = scan.origin;
        let points = scan
            .rays
            .iter()
            .filter_map(|ray| match ray.ret {
                RayReturn::Hit { distance, voxel } => {
                    Some(end_point(o, ray.direction, distance, voxel, resolution))
                }
                RayReturn::Nothing => Some(to_f32(&(o + ray.direction * (2.0 * scan.max_range)))),
                RayReturn::TooClose { .. } => None,
            })
            .collect();
        PointCloud {
            origin: to_f32(&o),
            points,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sensing::raycast::Ray;
    use nalgebra::Vector3;

    #[test]
    fn hits_land_in_their_voxel_misses_beyond_range_too_close_nowhere() {
        let scan = Scan {
            origin: Point3::new(0.25, 0.55, 0.55),
            max_range: 5.0,
            rays: vec![
                Ray {
                    direction: Vector3::x(),
                    ret: RayReturn::Hit {
                        distance: 0.55,
                        voxel: [8, 5, 5],
                    },
                },
                Ray {
                    direction: -Vector3::x(),
                    ret: RayReturn::Hit {
                        distance: 0.25,
                        voxel: [-1, 5, 5],
                    },
                },
                Ray {
                    direction: Vector3::y(),
                    ret: RayReturn::Nothing,
                },
                Ray {
                    direction: Vector3::z(),
                    ret: RayReturn::TooClose {
                        distance: 0.1,
                        voxel: [2, 5, 6],
                    },
                },
            ],
        };
        let cloud = PointCloud::from_scan(&scan, 0.1);
        assert_eq!(cloud.points.len(), 3);
        // floor(0.8 / 0.1) alone would say voxel 7 or 8; the nudged point is in voxel 8.
        assert_eq!((f64::from(cloud.points[0][0]) * 10.0).floor(), 8.0);
        assert_eq!((f64::from(cloud.points[1][0]) * 10.0).floor(), -1.0);
        assert!((f64::from(cloud.points[2][1]) - 10.55).abs() < 1e-5);
    }
}
