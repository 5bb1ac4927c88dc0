//! Our fusion (`aerial_chain::sensing`) against OctoMap's own `insertPointCloud` and
//! `computeRayKeys`.
//!
//! `tests/fixtures/octomap/fusion.cpp` is compiled with g++ against the installed OctoMap
//! library; it inserts the same clouds (every number passed as its bits) and prints every
//! voxel of its tree at depth 16 with its log-odds and state. The free, occupied and
//! unknown voxels, and every log-odds value, must be identical to ours, and so must the
//! bytes of the `.bt` each writes of the seen map. Random clouds
//! (hits, misses beyond the range, end points on voxel faces and in the origin's voxel,
//! axis-aligned rays) at 0.05, 0.1 and 0.087 m are inserted repeatedly, so that the
//! hit/miss arithmetic and the clamping are exercised; scans cast by our simulated
//! sensor into a truth map are inserted too. Without g++ or the OctoMap library this
//! test fails and names the package to install (`./test` installs both).

mod support;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use aerial_chain::map::{Cell, Grid};
use aerial_chain::sensing::ray_keys::ray_keys;
use aerial_chain::sensing::{raycast, DepthSensor, OccupancyMap, PointCloud, UnitPose};
use nalgebra::{Point3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// OctoMap's key of lattice index 0.
const KEY0: i64 = 32768;

/// The fusion program compiled against OctoMap, or why it cannot be.
fn program() -> &'static Result<PathBuf, String> {
    static PROGRAM: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    PROGRAM.get_or_init(|| {
        let src =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/octomap/fusion.cpp");
        support::octomap_program(&src, "octomap_fusion")
    })
}

/// Runs the OctoMap program on `commands` in `dir`; its standard output.
fn octomap_in(dir: &Path, commands: &str) -> String {
    let exe = program()
        .as_ref()
        .unwrap_or_else(|why| panic!("the OctoMap fusion check cannot run: {why}"));
    let file = dir.join("commands.txt");
    std::fs::write(&file, commands).unwrap();
    let out = Command::new(exe).arg(&file).output().unwrap();
    assert!(
        out.status.success(),
        "OctoMap's program failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Runs the OctoMap program on `commands`; its standard output.
fn octomap(commands: &str) -> String {
    octomap_in(tempfile::tempdir().unwrap().path(), commands)
}

fn f32_hex(v: f32) -> String {
    format!("{:08x}", v.to_bits())
}

fn point_hex(p: [f32; 3]) -> String {
    format!("{} {} {}", f32_hex(p[0]), f32_hex(p[1]), f32_hex(p[2]))
}

/// One `scan` command.
fn scan_command(cloud: &PointCloud, max_range: f64) -> String {
    let mut s = format!(
        "scan {:016x} {} {}\n",
        max_range.to_bits(),
        point_hex(cloud.origin),
        cloud.points.len()
    );
    for p in &cloud.points {
        writeln!(s, "{}", point_hex(*p)).unwrap();
    }
    s
}

/// OctoMap's voxels: lattice index -> (log-odds bits, occupied).
type Voxels = std::collections::BTreeMap<[i32; 3], (u32, bool)>;

fn parse_dump(text: &str) -> ([u32; 5], Voxels) {
    let mut params = [0u32; 5];
    let mut voxels = Voxels::new();
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["params", rest @ ..] => {
                for (p, v) in params.iter_mut().zip(rest) {
                    *p = u32::from_str_radix(v, 16).unwrap();
                }
            }
            ["voxel", x, y, z, l, o] => {
                let k = [x, y, z].map(|v| (v.parse::<i64>().unwrap() - KEY0) as i32);
                let prev = voxels.insert(k, (u32::from_str_radix(l, 16).unwrap(), *o == "1"));
                assert!(prev.is_none(), "OctoMap listed {k:?} twice");
            }
            _ => panic!("unexpected line {line:?}"),
        }
    }
    (params, voxels)
}

/// Inserts `clouds` into OctoMap and into our map; asserts the two agree voxel for voxel.
/// Returns (occupied, free) voxel counts.
fn compare(name: &str, resolution: f64, clouds: &[(PointCloud, f64)]) -> (usize, usize) {
    let mut commands = format!("tree {:016x}\n", resolution.to_bits());
    let mut ours = OccupancyMap::new(resolution).unwrap();
    for (cloud, max_range) in clouds {
        commands.push_str(&scan_command(cloud, *max_range));
        ours.insert(cloud, *max_range).unwrap();
    }
    let dir = tempfile::tempdir().unwrap();
    let (their_bt, our_bt) = (dir.path().join("octomap.bt"), dir.path().join("ours.bt"));
    writeln!(commands, "dump\nwrite {}", their_bt.display()).unwrap();
    let (params, theirs) = parse_dump(&octomap_in(dir.path(), &commands));
    let p = ours.params();
    assert_eq!(
        params,
        [p.hit, p.miss, p.min, p.max, p.threshold].map(f32::to_bits),
        "{name}: OctoMap's default log-odds"
    );
    let mut mine = Voxels::new();
    for (i, state) in ours.voxels() {
        let l = ours.log_odds(i).unwrap();
        mine.insert(i, (l.to_bits(), state == Cell::Occupied));
    }
    let only_theirs: Vec<_> = theirs
        .iter()
        .filter(|(k, _)| !mine.contains_key(*k))
        .take(5)
        .collect();
    let only_mine: Vec<_> = mine
        .iter()
        .filter(|(k, _)| !theirs.contains_key(*k))
        .take(5)
        .collect();
    assert!(
        only_theirs.is_empty() && only_mine.is_empty(),
        "{name}: known voxels differ: OctoMap only {only_theirs:?}, ours only {only_mine:?}"
    );
    for (k, v) in &theirs {
        assert_eq!(mine[k], *v, "{name}: voxel {k:?} (log-odds bits, occupied)");
    }
    // The seen map as a .bt: the bytes of OctoMap's writeBinary of its own tree.
    ours.write_bt(&our_bt).unwrap();
    assert!(
        std::fs::read(&our_bt).unwrap() == std::fs::read(&their_bt).unwrap(),
        "{name}: our .bt of the seen map differs from OctoMap's writeBinary"
    );
    let occupied = theirs.values().filter(|v| v.1).count();
    eprintln!(
        "{name}: {} clouds, {} voxels identical ({occupied} occupied, {} free)",
        clouds.len(),
        theirs.len(),
        theirs.len() - occupied
    );
    (occupied, theirs.len() - occupied)
}

fn random_direction(rng: &mut Pcg64) -> Vector3<f64> {
    if rng.gen_bool(0.15) {
        // Axis-aligned and diagonal: zero components and DDA ties.
        loop {
            let d = Vector3::new(
                f64::from(rng.gen_range(-1i8..=1)),
                f64::from(rng.gen_range(-1i8..=1)),
                f64::from(rng.gen_range(-1i8..=1)),
            );
            if d.norm() > 0.0 {
                return d.normalize();
            }
        }
    }
    loop {
        let d = Vector3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        if d.norm() > 0.1 && d.norm() <= 1.0 {
            return d.normalize();
        }
    }
}

/// A random cloud around `origin`: hits within range, points beyond it (misses), end
/// points on voxel faces, in the origin's own voxel, and at the range's edge.
fn random_cloud(
    rng: &mut Pcg64,
    origin: [f32; 3],
    max_range: f64,
    resolution: f64,
    n: usize,
) -> PointCloud {
    let o = Point3::new(
        f64::from(origin[0]),
        f64::from(origin[1]),
        f64::from(origin[2]),
    );
    let points = (0..n)
        .map(|_| {
            let d = random_direction(rng);
            let kind = rng.gen_range(0..20);
            let t = match kind {
                0..=11 => rng.gen_range(0.0..max_range),
                12..=15 => rng.gen_range(max_range..3.0 * max_range),
                16 => rng.gen_range(0.0..0.5 * resolution),
                _ => max_range * (1.0 + rng.gen_range(-1e-6..1e-6)),
            };
            let p = o + d * t;
            if kind == 17 {
                // On a voxel face along one axis (as exactly as f32 allows).
                let a = rng.gen_range(0..3);
                let mut q = p;
                q[a] = (p[a] / resolution).round() * resolution;
                return [q.x as f32, q.y as f32, q.z as f32];
            }
            [p.x as f32, p.y as f32, p.z as f32]
        })
        .collect();
    PointCloud { origin, points }
}

fn random_origin(rng: &mut Pcg64, around: [f32; 3], spread: f32) -> [f32; 3] {
    around.map(|c| c + rng.gen_range(-spread..spread))
}

#[test]
fn random_clouds_fuse_as_octomap_fuses_them() {
    let mut rng = Pcg64::seed_from_u64(35);
    for (case, resolution) in [0.05, 0.1, 0.087, 0.1, 0.05, 0.087].into_iter().enumerate() {
        let centre = random_origin(&mut rng, [0.0; 3], 3.0);
        let mut clouds = Vec::new();
        for _ in 0..6 {
            let origin = random_origin(&mut rng, centre, 0.5);
            let max_range = rng.gen_range(0.5..5.0);
            let cloud = random_cloud(&mut rng, origin, max_range, resolution, 250);
            // The same cloud several times: the values climb to the clamping bounds.
            for _ in 0..rng.gen_range(1..6) {
                clouds.push((cloud.clone(), max_range));
            }
        }
        // A point exactly at the origin and one on the origin's voxel corner.
        let o = clouds[0].0.origin;
        let corner = o.map(|c| ((f64::from(c) / resolution).floor() * resolution) as f32);
        clouds.push((
            PointCloud {
                origin: o,
                points: vec![o, corner],
            },
            5.0,
        ));
        let (occupied, free) = compare(
            &format!("random case {case} at {resolution} m"),
            resolution,
            &clouds,
        );
        assert!(
            occupied > 100 && free > 1000,
            "the case exercises both states"
        );
    }
}

/// A truth map: a room with pillars, unknown space occupied.
fn truth(resolution: f64, rng: &mut Pcg64) -> Grid {
    let n = (4.0 / resolution).round() as usize;
    let mut g = Grid::new(resolution, [0, 0, 0], [n, n, n / 2], Cell::Free, true).unwrap();
    for _ in 0..12 {
        let c = [rng.gen_range(0.3..3.7), rng.gen_range(0.3..3.7)];
        let r = rng.gen_range(0.05..0.3);
        g.fill_box(
            [c[0] - r, c[1] - r, 0.0],
            [c[0] + r, c[1] + r, 1.6],
            Cell::Occupied,
        );
    }
    g
}

#[test]
fn simulated_scans_fuse_as_octomap_fuses_them() {
    let mut rng = Pcg64::seed_from_u64(36);
    for resolution in [0.1f64, 0.05, 0.087] {
        let world = truth(resolution, &mut rng);
        let sensor = DepthSensor {
            max_range: 3.0,
            resolution_deg: 3.0,
            ..Default::default()
        };
        let mut clouds = Vec::new();
        for _ in 0..8 {
            let p = [
                rng.gen_range(0.5..3.5),
                rng.gen_range(0.5..3.5),
                rng.gen_range(0.5..1.5),
            ];
            // Tilted as a flying unit is: roll and pitch up to 0.3 rad, any yaw.
            let attitude = UnitQuaternion::from_euler_angles(
                rng.gen_range(-0.3..0.3),
                rng.gen_range(-0.3..0.3),
                rng.gen_range(-std::f64::consts::PI..std::f64::consts::PI),
            );
            let pose = UnitPose {
                position: Point3::from(p),
                attitude,
            };
            let scan = raycast::scan(&world, &sensor, &pose);
            let cloud = PointCloud::from_scan(&scan, resolution);
            for _ in 0..rng.gen_range(1..4) {
                clouds.push((cloud.clone(), sensor.max_range));
            }
        }
        compare(
            &format!("simulated scans at {resolution} m"),
            resolution,
            &clouds,
        );
    }
}

#[test]
fn ray_keys_are_octomaps() {
    let mut rng = Pcg64::seed_from_u64(37);
    for resolution in [0.05f64, 0.1, 0.087] {
        let mut commands = format!("tree {:016x}\n", resolution.to_bits());
        let mut segments = Vec::new();
        for _ in 0..400 {
            let o = random_origin(&mut rng, [0.0; 3], 4.0);
            let cloud = random_cloud(&mut rng, o, 4.0, resolution, 1);
            segments.push((o, cloud.points[0]));
        }
        // Out of the tree's key range: OctoMap refuses the ray.
        segments.push(([0.0; 3], [1e6, 0.0, 0.0]));
        for (o, e) in &segments {
            writeln!(commands, "ray {} {}", point_hex(*o), point_hex(*e)).unwrap();
        }
        let text = octomap(&commands);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), segments.len());
        let mut keys = Vec::new();
        let mut total = 0;
        for ((o, e), line) in segments.iter().zip(lines) {
            let ok = ray_keys(*o, *e, resolution, &mut keys);
            let w: Vec<&str> = line.split_whitespace().collect();
            if w[1] == "fail" {
                assert!(
                    !ok,
                    "{resolution}: OctoMap refused {o:?} -> {e:?}, we did not"
                );
                continue;
            }
            assert!(ok, "{resolution}: we refused {o:?} -> {e:?}");
            let n: usize = w[2].parse().unwrap();
            let theirs: Vec<[i32; 3]> = (0..n)
                .map(|k| {
                    [0, 1, 2].map(|a| (w[3 + 3 * k + a].parse::<i64>().unwrap() - KEY0) as i32)
                })
                .collect();
            assert_eq!(keys, theirs, "{resolution}: keys of {o:?} -> {e:?}");
            total += n;
        }
        eprintln!(
            "ray keys at {resolution} m: {} segments, {total} keys identical",
            segments.len()
        );
    }
}
