//! OctoMap's keys and its ray traversal (`OcTreeBaseImpl::computeRayKeys`), reproduced
//! to the bit so that a scan fused here marks the voxels OctoMap marks.
//!
//! OctoMap works on `point3d`, three `f32`s, and on keys: along each axis
//! `key = floor(coordinate * (1 / resolution)) + 32768` in `f64`, valid in `0..65536`.
//! Lattice indices here are keys minus 32768 (`map::Grid`'s indices). The traversal
//! (Amanatides and Woo on keys, as OctoMap writes it):
//! - the origin's and the end's keys; none valid, no ray; equal, an empty ray;
//! - the direction is `end - origin` in `f32`, divided by its `f32` length (the `f64`
//!   square root of the `f32` sum of squares, rounded to `f32`);
//! - per axis, the step is the direction's sign; the first border is the origin key's
//!   centre (`f64`) plus half a voxel rounded to `f32`; `t_max = (border - o) / d` and
//!   `t_delta = resolution / |d|`, in `f64`;
//! - the origin's key is the first of the ray; then the walk steps along the axis of the
//!   smallest `t_max` (ties to the later axis, by OctoMap's strict comparisons) and
//!   stops on reaching the end's key (which is not part of the ray), or when the
//!   smallest `t_max` exceeds the length (rounding kept it from the end's key).

/// OctoMap's `tree_max_val`: the key of lattice index 0.
const TREE_MAX_VAL: i32 = 32768;

/// Most keys one ray may hold (the capacity of OctoMap's `KeyRay`): a longer ray is an
/// error there (an assertion), and refused here.
pub const MAX_RAY_KEYS: usize = 100_000;

/// OctoMap's `coordToKeyChecked` for one coordinate, as a lattice index (key - 32768).
pub fn coord_to_index(coordinate: f64, resolution_factor: f64) -> Option<i32> {
    let scaled = (resolution_factor * coordinate).floor();
    // OctoMap casts to int; outside the key range (or NaN) it is refused either way.
    if !(scaled >= -f64::from(TREE_MAX_VAL) && scaled < f64::from(TREE_MAX_VAL)) {
        return None;
    }
    Some(scaled as i32)
}

/// The lattice index of an OctoMap point, or `None` outside the tree.
pub fn point_to_index(p: [f32; 3], resolution_factor: f64) -> Option<[i32; 3]> {
    Some([
        coord_to_index(f64::from(p[0]), resolution_factor)?,
        coord_to_index(f64::from(p[1]), resolution_factor)?,
        coord_to_index(f64::from(p[2]), resolution_factor)?,
    ])
}

/// OctoMap's `Vector3::norm`: the `f64` square root of the `f32` sum of squares.
pub fn norm_f32(v: [f32; 3]) -> f64 {
    f64::from(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// `a - b` per component in `f32`.
pub fn sub_f32(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// The keys (as lattice indices) OctoMap's `computeRayKeys(origin, end)` returns, in
/// its order, into `out` (cleared first). `false` where OctoMap returns false: an end
/// outside the tree; also where the ray would exceed [`MAX_RAY_KEYS`].
pub fn ray_keys(origin: [f32; 3], end: [f32; 3], resolution: f64, out: &mut Vec<[i32; 3]>) -> bool {
    out.clear();
    let factor = 1.0 / resolution;
    let (Some(key_origin), Some(key_end)) =
        (point_to_index(origin, factor), point_to_index(end, factor))
    else {
        return false;
    };
    if key_origin == key_end {
        return true;
    }
    out.push(key_origin);
    let diff = sub_f32(end, origin);
    let length = norm_f32(diff) as f32;
    let dir = diff.map(|c| c / length);
    let mut step = [0i32; 3];
    let mut t_max = [f64::MAX; 3];
    let mut t_delta = [f64::MAX; 3];
    for a in 0..3 {
        if dir[a] == 0.0 {
            continue;
        }
        step[a] = if dir[a] > 0.0 { 1 } else { -1 };
        let centre = (f64::from(key_origin[a]) + 0.5) * resolution;
        let border = centre + f64::from((f64::from(step[a]) * resolution * 0.5) as f32);
        t_max[a] = (border - f64::from(origin[a])) / f64::from(dir[a]);
        t_delta[a] = resolution / f64::from(dir[a].abs());
    }
    let mut current = key_origin;
    loop {
        let dim = if t_max[0] < t_max[1] {
            if t_max[0] < t_max[2] {
                0
            } else {
                2
            }
        } else if t_max[1] < t_max[2] {
            1
        } else {
            2
        };
        current[dim] += step[dim];
        t_max[dim] += t_delta[dim];
        if current == key_end {
            return true;
        }
        let reached = t_max[0].min(t_max[1]).min(t_max[2]);
        if reached > f64::from(length) {
            return true;
        }
        if out.len() >= MAX_RAY_KEYS {
            out.clear();
            return false;
        }
        out.push(current);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_follow_octomaps_lattice() {
        // floor(x * (1 / r)), not floor(x / r): 4.3 / 0.1 is 42.99999999999999 in f64.
        assert_eq!(coord_to_index(4.3, 1.0 / 0.1), Some(43));
        assert_eq!(coord_to_index(2.6969999999999996, 1.0 / 0.087), Some(31));
        assert_eq!(coord_to_index(-0.05, 10.0), Some(-1));
        assert_eq!(coord_to_index(3276.8, 10.0), None);
        assert_eq!(coord_to_index(-3276.8, 10.0), Some(-32768));
        assert_eq!(coord_to_index(f64::NAN, 10.0), None);
    }

    #[test]
    fn a_ray_along_x_is_the_voxels_before_the_end() {
        let mut out = Vec::new();
        assert!(ray_keys(
            [0.05, 0.05, 0.05],
            [0.55, 0.05, 0.05],
            0.1,
            &mut out
        ));
        assert_eq!(out, (0..5).map(|i| [i, 0, 0]).collect::<Vec<_>>());
        assert!(ray_keys(
            [0.05, 0.05, 0.05],
            [0.06, 0.05, 0.05],
            0.1,
            &mut out
        ));
        assert!(out.is_empty(), "same voxel: an empty ray");
        assert!(!ray_keys([0.0; 3], [1e6, 0.0, 0.0], 0.1, &mut out));
    }

    #[test]
    fn a_diagonal_ray_is_face_connected() {
        let mut out = Vec::new();
        assert!(ray_keys(
            [0.01, 0.02, 0.03],
            [-0.71, 0.93, 0.44],
            0.1,
            &mut out
        ));
        for w in out.windows(2) {
            let d: i32 = (0..3).map(|a| (w[1][a] - w[0][a]).abs()).sum();
            assert_eq!(d, 1, "{w:?}");
        }
        assert_eq!(out[0], [0, 0, 0]);
        assert!(
            !out.contains(&[-8, 9, 4]),
            "the end's voxel is not on the ray"
        );
    }
}
