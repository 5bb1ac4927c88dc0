//! A depth sensor fixed to a unit's body: its settings, its rays in the body frame and,
//! for a unit pose, its origin and rays in the world frame W.
//!
//! Frames (docs/model.md): the body frame has x forward, y left, z up; a unit's attitude
//! is the quaternion rotating its body frame into W. The sensor's own frame has x along
//! the optical axis, y left, z up; its mounting pose ([`Mount`]) rotates and offsets that
//! frame in the body frame, and the units after the head may turn theirs about body z
//! ([`DepthSensor::splay_deg`]). Every unit holds the head's yaw (docs/model.md,
//! "Trajectories"), so with the default mount and no splay every sensor looks along the
//! head's heading.

use nalgebra::{Point3, Quaternion, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

/// Most rays one sensor may cast per scan (a 100 x 100 degree field at 0.3 degrees):
/// settings that ask for more are refused, so a scan's cost stays bounded.
pub const MAX_RAYS: usize = 100_000;

/// How far a mounting quaternion's norm may be from 1 (it is normalised after the check).
const QUATERNION_NORM_TOLERANCE: f64 = 1e-6;

/// Where the sensor sits on the unit's body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Mount {
    /// Rotation of the sensor frame into the body frame, `[w, x, y, z]` (Hamilton, unit
    /// norm). Default identity: the optical axis along body +x.
    pub rotation: [f64; 4],
    /// The sensor's origin in the body frame (m). Default the unit's centre.
    pub offset: [f64; 3],
}

impl Default for Mount {
    fn default() -> Self {
        Mount {
            rotation: [1.0, 0.0, 0.0, 0.0],
            offset: [0.0; 3],
        }
    }
}

/// Depth sensor settings: a rectangular frustum of rays, as a small depth camera's.
///
/// Ray `(j, k)` has horizontal angle `a_j = (j - (n_h - 1) / 2) * resolution` (positive
/// to the left) and vertical angle `e_k = (k - (n_v - 1) / 2) * resolution` (positive
/// up), with `n = floor(fov / resolution) + 1` rays per direction, so the rays are
/// centred on the optical axis and span the field of view to within one step. Its
/// direction in the sensor frame is `(1, tan a_j, tan e_k)` normalised: the point on the
/// image plane at those angles, as a camera's pixels lie on a plane.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DepthSensor {
    /// Horizontal field of view (degrees), in (0, 180). Default 87.
    pub fov_h_deg: f64,
    /// Vertical field of view (degrees), in (0, 180). Default 58.
    pub fov_v_deg: f64,
    /// Nearest distance the sensor measures (m). Default 0.2.
    pub min_range: f64,
    /// Farthest distance the sensor measures (m). Default 5.
    pub max_range: f64,
    /// Angle between neighbouring rays, horizontally and vertically (degrees). Default 1.5.
    pub resolution_deg: f64,
    /// Mounting pose on the unit's body.
    pub mount: Mount,
    /// How far the sensors of the units after the head are turned about body z from
    /// `mount` (degrees), alternately to the left (units 1, 3, ...) and to the right
    /// (units 2, 4, ...); the head's sensor keeps `mount`. Default 0: every sensor as
    /// `mount`. At half the horizontal field of view each side view begins at the
    /// head's optical axis and the three views together span twice the head's, the
    /// chain's flanks included; it trades the view straight ahead (seen by every unit
    /// at 0) for the view to the sides, which a shape change sweeps (docs/online.md).
    pub splay_deg: f64,
}

impl Default for DepthSensor {
    fn default() -> Self {
        DepthSensor {
            fov_h_deg: 87.0,
            fov_v_deg: 58.0,
            min_range: 0.2,
            max_range: 5.0,
            resolution_deg: 1.5,
            mount: Mount::default(),
            splay_deg: 0.0,
        }
    }
}

/// Sensor settings (or a unit pose) that cannot be used: the field, its value and the
/// rule it breaks.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{field} = {value}: {rule}")]
pub struct SensorError {
    /// The setting's name, as in the settings file.
    pub field: &'static str,
    /// The value given, as text.
    pub value: String,
    /// What the value must be.
    pub rule: String,
}

fn refuse(
    field: &'static str,
    value: impl std::fmt::Debug,
    rule: impl Into<String>,
) -> SensorError {
    SensorError {
        field,
        value: format!("{value:?}"),
        rule: rule.into(),
    }
}

/// A unit's pose in W: the body's centre and its attitude (tilt included).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitPose {
    /// The unit's centre in W (m).
    pub position: Point3<f64>,
    /// Rotation of the body frame into W.
    pub attitude: UnitQuaternion<f64>,
}

impl UnitPose {
    /// A pose from a position and an attitude `[w, x, y, z]` as flight and trajectory
    /// files record it (`q`, docs/model.md), normalised. Refused, naming the field, when
    /// a number is not finite or the quaternion's norm is off 1 by more than 1e-3 (more
    /// than the `f32` rounding of a recorded attitude).
    pub fn new(position: [f64; 3], attitude: [f64; 4]) -> Result<UnitPose, SensorError> {
        if position.iter().any(|v| !v.is_finite()) {
            return Err(refuse("pose.position", position, "must be finite (m)"));
        }
        let norm = attitude.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm.is_finite() && (norm - 1.0).abs() <= 1e-3) {
            return Err(refuse(
                "pose.attitude",
                attitude,
                format!("must be a unit quaternion [w, x, y, z] (norm {norm})"),
            ));
        }
        let [w, x, y, z] = attitude;
        Ok(UnitPose {
            position: position.into(),
            attitude: UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)),
        })
    }

    /// A pose from a position and a yaw about z (no tilt), as every unit of a
    /// trajectory holds it.
    pub fn level(position: impl Into<Point3<f64>>, yaw: f64) -> UnitPose {
        UnitPose {
            position: position.into(),
            attitude: UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw),
        }
    }
}

impl DepthSensor {
    /// Checks every setting; the error names the first bad field and its value.
    pub fn validate(&self) -> Result<(), SensorError> {
        for (field, v) in [("fov_h_deg", self.fov_h_deg), ("fov_v_deg", self.fov_v_deg)] {
            if !(v.is_finite() && v > 0.0 && v < 180.0) {
                return Err(refuse(field, v, "must be in (0, 180) degrees"));
            }
        }
        if !(self.min_range.is_finite() && self.min_range >= 0.0) {
            return Err(refuse("min_range", self.min_range, "must be >= 0 m"));
        }
        if !(self.max_range.is_finite() && self.max_range > self.min_range) {
            return Err(refuse(
                "max_range",
                self.max_range,
                format!("must be finite and above min_range ({} m)", self.min_range),
            ));
        }
        let r = self.resolution_deg;
        if !(r.is_finite() && r > 0.0) {
            return Err(refuse("resolution_deg", r, "must be a positive angle"));
        }
        let n = self.columns().saturating_mul(self.rows());
        if n > MAX_RAYS {
            return Err(refuse(
                "resolution_deg",
                r,
                format!("gives {n} rays per scan, more than {MAX_RAYS}"),
            ));
        }
        let a = self.splay_deg;
        if !(a.is_finite() && (0.0..=180.0).contains(&a)) {
            return Err(refuse("splay_deg", a, "must be in [0, 180] degrees"));
        }
        self.validate_mount()
    }

    /// The turn of unit `unit`'s sensor about body z from `mount` (rad, positive to the
    /// left): 0 for the head, then the splay to the left and to the right in turn.
    fn unit_turn(&self, unit: usize) -> f64 {
        let splay = self.splay_deg.to_radians();
        match unit {
            0 => 0.0,
            u if u % 2 == 1 => splay,
            _ => -splay,
        }
    }

    /// The sensor of unit `unit`: this one with its mount turned about body z, by 0
    /// for the head and then by [`Self::splay_deg`] to the left and to the right in turn.
    pub fn for_unit(&self, unit: usize) -> DepthSensor {
        let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), self.unit_turn(unit));
        let q = turn * self.mount_rotation();
        let mut out = self.clone();
        out.mount.rotation = [q.w, q.i, q.j, q.k];
        out
    }

    fn validate_mount(&self) -> Result<(), SensorError> {
        let q = self.mount.rotation;
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm.is_finite() && (norm - 1.0).abs() <= QUATERNION_NORM_TOLERANCE) {
            return Err(refuse(
                "mount.rotation",
                q,
                format!("must be a unit quaternion [w, x, y, z] (norm {norm})"),
            ));
        }
        if self.mount.offset.iter().any(|v| !v.is_finite()) {
            return Err(refuse(
                "mount.offset",
                self.mount.offset,
                "must be finite (m)",
            ));
        }
        Ok(())
    }

    /// Rays per row (horizontal): `floor(fov_h / resolution) + 1`.
    pub fn columns(&self) -> usize {
        count(self.fov_h_deg, self.resolution_deg)
    }

    /// Rays per column (vertical): `floor(fov_v / resolution) + 1`.
    pub fn rows(&self) -> usize {
        count(self.fov_v_deg, self.resolution_deg)
    }

    /// The mounting rotation (sensor frame into body frame), normalised.
    fn mount_rotation(&self) -> UnitQuaternion<f64> {
        let [w, x, y, z] = self.mount.rotation;
        UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z))
    }

    /// The unit ray directions in the body frame, row by row from the bottom, each row
    /// from the right (negative horizontal angle) to the left. Call [`Self::validate`]
    /// first: invalid settings give no rays.
    pub fn body_rays(&self) -> Vec<Vector3<f64>> {
        if self.validate().is_err() {
            return Vec::new();
        }
        let step = self.resolution_deg.to_radians();
        let (nh, nv) = (self.columns(), self.rows());
        let angle = |j: usize, n: usize| (j as f64 - (n as f64 - 1.0) / 2.0) * step;
        let mount = self.mount_rotation();
        let mut rays = Vec::with_capacity(nh * nv);
        for k in 0..nv {
            let tan_e = angle(k, nv).tan();
            for j in 0..nh {
                let d = Vector3::new(1.0, angle(j, nh).tan(), tan_e).normalize();
                rays.push(mount * d);
            }
        }
        rays
    }

    /// The sensor's origin in W for a unit at `pose`.
    pub fn origin(&self, pose: &UnitPose) -> Point3<f64> {
        pose.position + pose.attitude * Vector3::from(self.mount.offset)
    }

    /// Whether point `p` (W) lies in the view of the sensor of a unit at `pose`: within
    /// the angles its rays span (to the outermost ray) and at a distance in
    /// `[min_range, max_range]`. Nothing in the way is considered: a prediction of
    /// what a scan may see, not a scan.
    pub fn in_view(&self, pose: &UnitPose, p: &Point3<f64>) -> bool {
        let d = (pose.attitude * self.mount_rotation()).inverse() * (p - self.origin(pose));
        let range = d.norm();
        if d.x <= 0.0 || range < self.min_range || range > self.max_range {
            return false;
        }
        // The outermost rays themselves are in view, rounding aside.
        let half = |n: usize| (n as f64 - 1.0) / 2.0 * self.resolution_deg.to_radians();
        let within = |slope: f64, n: usize| slope.abs() <= half(n).tan() + 1e-12;
        within(d.y / d.x, self.columns()) && within(d.z / d.x, self.rows())
    }

    /// The unit ray directions in W for a unit at `pose` (in [`Self::body_rays`]'s order).
    pub fn world_rays(&self, pose: &UnitPose) -> Vec<Vector3<f64>> {
        self.body_rays()
            .into_iter()
            .map(|d| pose.attitude * d)
            .collect()
    }
}

/// `floor(fov / step) + 1`, saturating; a tiny tolerance keeps `87 / 1.5 = 58` whole.
fn count(fov: f64, step: f64) -> usize {
    let q = fov / step;
    if !q.is_finite() || q < 0.0 {
        return usize::MAX;
    }
    let n = (q + 1e-9).floor();
    if n >= (MAX_RAYS as f64) {
        usize::MAX
    } else {
        n as usize + 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn defaults_are_a_small_depth_camera() {
        let s = DepthSensor::default();
        assert_eq!(s.validate(), Ok(()));
        assert_eq!((s.columns(), s.rows()), (59, 39));
        let rays = s.body_rays();
        assert_eq!(rays.len(), 59 * 39);
        // The corners of the frustum: +-43.5 deg horizontally, +-28.5 deg vertically.
        let c = rays[0];
        assert!((c.y / c.x - (-43.5f64).to_radians().tan()).abs() < 1e-12);
        assert!((c.z / c.x - (-28.5f64).to_radians().tan()).abs() < 1e-12);
        // The middle ray is the optical axis, body +x.
        let mid = rays[19 * 59 + 29];
        assert!((mid - Vector3::x()).norm() < 1e-12);
        assert!(rays
            .iter()
            .all(|d| (d.norm() - 1.0).abs() < 1e-12 && d.x > 0.0));
    }

    #[test]
    fn bad_settings_name_the_field_and_value() {
        /// A change to the default sensor.
        type Change = fn(&mut DepthSensor);
        let cases: [(Change, &str); 11] = [
            (|s| s.fov_h_deg = 180.0, "fov_h_deg = 180.0"),
            (|s| s.fov_v_deg = 0.0, "fov_v_deg = 0.0"),
            (|s| s.fov_v_deg = f64::NAN, "fov_v_deg = NaN"),
            (|s| s.min_range = -0.1, "min_range = -0.1"),
            (|s| s.max_range = 0.2, "max_range = 0.2"),
            (|s| s.resolution_deg = 0.0, "resolution_deg = 0.0"),
            (
                |s| s.resolution_deg = 0.1,
                "resolution_deg = 0.1: gives 506051 rays per scan, more than 100000",
            ),
            (
                |s| s.mount.rotation = [1.0, 1.0, 0.0, 0.0],
                "mount.rotation = [1.0, 1.0, 0.0, 0.0]",
            ),
            (
                |s| s.mount.offset = [0.0, f64::INFINITY, 0.0],
                "mount.offset = [0.0, inf, 0.0]",
            ),
            (|s| s.splay_deg = -1.0, "splay_deg = -1.0"),
            (|s| s.splay_deg = f64::NAN, "splay_deg = NaN"),
        ];
        for (change, expected) in cases {
            let mut s = DepthSensor::default();
            change(&mut s);
            let e = s.validate().expect_err(expected).to_string();
            assert!(e.contains(expected), "{e:?} should say {expected:?}");
            assert!(s.body_rays().is_empty());
        }
    }

    #[test]
    fn settings_read_from_json_with_defaults() {
        let s: DepthSensor =
            serde_json::from_str(r#"{"max_range": 3.0, "mount": {"offset": [0.1, 0, 0]}}"#)
                .unwrap();
        assert_eq!(s.max_range, 3.0);
        assert_eq!(s.fov_h_deg, 87.0);
        assert_eq!(s.mount.rotation, [1.0, 0.0, 0.0, 0.0]);
        assert!(serde_json::from_str::<DepthSensor>(r#"{"fov": 3}"#).is_err());
    }

    #[test]
    fn the_units_after_the_head_look_left_and_right_in_turn() {
        // The optical axis (body +x in the sensor frame) of each unit's sensor.
        let axis = |s: &DepthSensor, unit: usize| {
            let d = s.for_unit(unit).body_rays()[19 * 59 + 29];
            d.y.atan2(d.x).to_degrees()
        };
        let ahead = DepthSensor::default();
        assert!((0..4).all(|u| axis(&ahead, u).abs() < 1e-9));
        let splayed = DepthSensor {
            splay_deg: 43.5,
            ..DepthSensor::default()
        };
        for (unit, expected) in [(0, 0.0), (1, 43.5), (2, -43.5), (3, 43.5), (4, -43.5)] {
            assert!(
                (axis(&splayed, unit) - expected).abs() < 1e-9,
                "unit {unit}"
            );
        }
        // The splay turns the mounted sensor about body z: one looking down stays down.
        let down = DepthSensor {
            splay_deg: 43.5,
            ..looking_down()
        };
        let d = down.for_unit(1).body_rays()[19 * 59 + 29];
        assert!((d - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-9, "{d}");
        let read: DepthSensor = serde_json::from_str(r#"{"splay_deg": 90}"#).unwrap();
        assert!((axis(&read, 2) + 90.0).abs() < 1e-9);
    }

    /// The default sensor mounted pitched by +90 degrees about body y (looking down),
    /// 0.1 m ahead of and 0.05 m below the unit's centre.
    fn looking_down() -> DepthSensor {
        let half = std::f64::consts::FRAC_PI_4;
        DepthSensor {
            mount: Mount {
                rotation: [half.cos(), 0.0, half.sin(), 0.0],
                offset: [0.1, 0.0, -0.05],
            },
            ..Default::default()
        }
    }

    #[test]
    fn world_rays_follow_the_tilted_body_and_the_mount() {
        // Looking down: the mount pitches the optical axis by +90 deg about body y.
        let s = looking_down();
        let axis = s.body_rays()[19 * 59 + 29];
        assert!((axis - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-12);
        // The unit yawed by 90 deg and rolled by 90 deg (tilt): body x -> W y, body z -> W x.
        let pose = UnitPose {
            position: Point3::new(1.0, 2.0, 3.0),
            attitude: UnitQuaternion::from_axis_angle(&Vector3::z_axis(), FRAC_PI_2)
                * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), FRAC_PI_2),
        };
        let o = s.origin(&pose);
        // offset (0.1, 0, -0.05): body x -> W y, body z -> W x.
        assert!(
            (o - Point3::new(1.0 - 0.05, 2.1, 3.0)).norm() < 1e-12,
            "{o}"
        );
        let w = s.world_rays(&pose)[19 * 59 + 29];
        assert!((w - Vector3::new(-1.0, 0.0, 0.0)).norm() < 1e-12, "{w}");
        // The same pose from a recorded [w, x, y, z]; bad records are refused by name.
        let q = pose.attitude.quaternion();
        let recorded = UnitPose::new([1.0, 2.0, 3.0], [q.w, q.i, q.j, q.k]).unwrap();
        assert!((s.world_rays(&recorded)[19 * 59 + 29] - w).norm() < 1e-12);
        let e = UnitPose::new([0.0; 3], [1.0, 0.1, 0.0, 0.0])
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("pose.attitude = [1.0, 0.1, 0.0, 0.0]: must be"),
            "{e}"
        );
        assert!(UnitPose::new([f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]).is_err());
        // A level pose at yaw 0 leaves the body rays as they are.
        let level = UnitPose::level([0.0, 0.0, 1.0], 0.0);
        assert_eq!(
            DepthSensor::default().world_rays(&level),
            DepthSensor::default().body_rays()
        );
    }

    #[test]
    fn in_view_holds_the_points_along_the_rays_and_no_others() {
        let s = looking_down();
        let pose = UnitPose {
            position: Point3::new(1.0, 2.0, 3.0),
            attitude: UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.7)
                * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.3),
        };
        let o = s.origin(&pose);
        let rays = s.world_rays(&pose);
        // Every ray, at the near and far ends of the range and between, is in view.
        for d in &rays {
            for r in [0.2 + 1e-9, 1.0, 5.0 - 1e-9] {
                assert!(s.in_view(&pose, &(o + d * r)), "{d} at {r} m");
            }
            assert!(!s.in_view(&pose, &(o + d * 0.19)), "nearer than min_range");
            assert!(!s.in_view(&pose, &(o + d * 5.01)), "beyond max_range");
            assert!(!s.in_view(&pose, &(o - d * 1.0)), "behind the sensor");
        }
        // Just outside the corner rays, horizontally and vertically.
        let mount = pose.attitude * s.mount_rotation();
        let beyond = |h: f64, v: f64| {
            o + mount * Vector3::new(1.0, h.to_radians().tan(), v.to_radians().tan())
        };
        assert!(s.in_view(&pose, &beyond(43.4, 28.4)));
        assert!(!s.in_view(&pose, &beyond(43.6, 0.0)));
        assert!(!s.in_view(&pose, &beyond(0.0, -28.6)));
    }
}
