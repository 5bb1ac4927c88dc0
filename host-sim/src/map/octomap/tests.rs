//! Tests of the OctoMap reader and writer against the format as OctoMap defines it:
//! bit and child order, header parsing, round trips, pruning, and every way a file can
//! be bad. The comparison with the real library is in `host-sim/tests/octomap_reference.rs`.

use nalgebra::Point3;

use super::query::Leaf;
use super::*;

/// SplitMix64: small deterministic random numbers for tests.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn range(&mut self, lo: i32, hi: i32) -> i32 {
        lo + self.below((hi - lo) as u64) as i32
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn header(size: &str, res: &str) -> Vec<u8> {
    format!("# Octomap OcTree binary file\n# comment\n#\nid OcTree\nsize {size}\nres {res}\ndata\n")
        .into_bytes()
}

/// Root: child 0 occupied leaf, child 1 free leaf, child 7 inner; that one: child 0 free.
fn tiny_bt() -> Vec<u8> {
    let mut b = header("5", "1");
    b.extend_from_slice(&[0x06, 0xc0, 0x01, 0x00]);
    b
}

fn room(res: f64) -> OcTree {
    let mut voxels = Vec::new();
    for i in -6..10 {
        for j in -3..9 {
            for k in 0..8 {
                let wall = i == -6 || i == 9 || j == -3 || j == 8 || k == 0 || k == 7;
                voxels.push(([i, j, k], wall));
            }
        }
    }
    for i in 16..32 {
        for j in -32..-16 {
            for k in 0..16 {
                voxels.push(([i, j, k], false));
            }
        }
    }
    OcTree::from_voxels(res, voxels).unwrap()
}

fn err(bytes: &[u8]) -> MapFileError {
    match OcTree::from_bt_bytes(bytes, "test.bt") {
        Ok(t) => panic!("accepted a bad file: {t:?}"),
        Err(e) => {
            assert!(e.to_string().starts_with("test.bt: "), "{e}");
            e
        }
    }
}

/// OctoMap's calcMinMax, visiting every leaf.
fn brute_bounds(tree: &OcTree) -> Option<(Point3<f64>, Point3<f64>)> {
    let mut out: Option<(Point3<f64>, Point3<f64>)> = None;
    for leaf in tree.leaves() {
        let (mut mn, mut mx) = out.unwrap_or(([f64::MAX; 3].into(), [-f64::MAX; 3].into()));
        for a in 0..3 {
            let lo = leaf.center[a] - leaf.size / 2.0;
            mn[a] = mn[a].min(lo);
            mx[a] = mx[a].max(lo + leaf.size);
        }
        out = Some((mn, mx));
    }
    out
}

#[test]
fn bit_order_and_child_order_follow_octomap() {
    let tree = OcTree::from_bt_bytes(&tiny_bt(), "tiny.bt").unwrap();
    assert_eq!(tree.counts(), (1, 2));
    assert_eq!(tree.node_count(), 5);
    let leaves: Vec<Leaf> = tree.leaves().collect();
    let h = 16384.0;
    assert_eq!(
        leaves,
        vec![
            Leaf {
                center: [-h, -h, -h].into(),
                size: 32768.0,
                occupied: true,
                depth: 1
            },
            Leaf {
                center: [h, -h, -h].into(),
                size: 32768.0,
                occupied: false,
                depth: 1
            },
            Leaf {
                center: [8192.0; 3].into(),
                size: 16384.0,
                occupied: false,
                depth: 2
            },
        ]
    );
    assert_eq!(tree.query([-1.0, -1.0, -1.0]), Some(true));
    assert_eq!(tree.query([1.0, -1.0, -1.0]), Some(false));
    assert_eq!(tree.query([-1.0, 1.0, -1.0]), None);
    assert_eq!(tree.query([1.0, 1.0, 1.0]), Some(false));
    assert_eq!(tree.query([20000.0, 20000.0, 20000.0]), None);
    assert_eq!(
        tree.metric_bounds(),
        Some((
            Point3::new(-32768.0, -32768.0, -32768.0),
            Point3::new(32768.0, 16384.0, 16384.0)
        ))
    );
    // The writer gives back the same tree bytes.
    assert!(tree.to_bt_bytes().ends_with(&[0x06, 0xc0, 0x01, 0x00]));
}

#[test]
fn writer_header_is_octomaps() {
    let tree = OcTree::from_voxels(0.05, [([0, 0, 0], true)]).unwrap();
    let bytes = tree.to_bt_bytes();
    let text = String::from_utf8_lossy(&bytes);
    assert!(text.starts_with(
            "# Octomap OcTree binary file\n# (feel free to add / change comments, but leave the first line as it is!)\n#\nid OcTree\nsize 17\nres 0.05\ndata\n"
        ));
    // One voxel: 16 inner nodes (depths 0..=15), 2 bytes each.
    assert_eq!(tree.node_count(), 17);
    let leaves: Vec<Leaf> = tree.leaves().collect();
    assert_eq!(
        leaves,
        vec![Leaf {
            center: [0.025; 3].into(),
            size: 0.05,
            occupied: true,
            depth: 16
        }]
    );
    assert_eq!(
        tree.metric_bounds(),
        Some(([0.0; 3].into(), [0.05; 3].into()))
    );
}

#[test]
fn header_is_read_like_octomap() {
    let data = &tiny_bt()[tiny_bt().len() - 4..];
    let variants: [&[u8]; 4] = [
            b"# Octomap OcTree binary file\nid 1\nsize 5\nres 1.0\ndata\n",
            b"# Octomap OcTree binary file (trailing words are fine)\r\n# c\r\nres 1\r\nfoo bar baz\r\nsize 5\r\nid OcTree\r\ndata\r\n",
            b"# Octomap OcTree binary file\n\n  id   OcTree  size 5 res 1e0\n#data\ndata and the rest of this line\n",
            b"# Octomap OcTree binary file\nres 2\nres 1\nid OcTree\nsize 5\ndata\n",
        ];
    let reference = OcTree::from_bt_bytes(&tiny_bt(), "tiny.bt").unwrap();
    for v in variants {
        let mut b = v.to_vec();
        b.extend_from_slice(data);
        let tree = OcTree::from_bt_bytes(&b, "v.bt").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(tree, reference, "{}", String::from_utf8_lossy(v));
    }
}

#[test]
fn round_trip_of_random_trees() {
    let mut rng = Rng(7);
    for round in 0..60 {
        let res = [0.02, 0.05, 0.08, 0.1, 0.2, 0.5][round % 6];
        let mut voxels = Vec::new();
        let spread = [4, 16, 60, 300][round % 4];
        for _ in 0..rng.below(600) {
            let v = [
                rng.range(-spread, spread),
                rng.range(-spread, spread),
                rng.range(-spread, spread),
            ];
            voxels.push((v, rng.below(3) == 0));
        }
        // Aligned blocks, so that pruning happens at several levels.
        for _ in 0..rng.below(4) {
            let edge = 1 << rng.below(5);
            let o = [
                rng.range(-8, 8) * edge,
                rng.range(-8, 8) * edge,
                rng.range(-8, 8) * edge,
            ];
            let occ = rng.below(2) == 0;
            for i in 0..edge {
                for j in 0..edge {
                    for k in 0..edge {
                        voxels.push(([o[0] + i, o[1] + j, o[2] + k], occ));
                    }
                }
            }
        }
        if round == 0 {
            voxels.clear();
        }
        let tree = OcTree::from_voxels(res, voxels.clone()).unwrap();
        let bytes = tree.to_bt_bytes();
        let back = OcTree::from_bt_bytes(&bytes, "round.bt").unwrap();
        assert_eq!(back, tree);
        assert_eq!(back.to_bt_bytes(), bytes);
        assert!(back.leaves().eq(tree.leaves()));
        let (occ, free) = tree.counts();
        assert_eq!(tree.leaves().filter(|l| l.occupied).count(), occ);
        assert_eq!(tree.leaves().filter(|l| !l.occupied).count(), free);
        assert_eq!(tree.metric_bounds(), brute_bounds(&tree));
        assert_eq!(back.metric_bounds(), tree.metric_bounds());
        // Every voxel reads back as its last state.
        let mut last = std::collections::HashMap::new();
        for (v, occ) in &voxels {
            last.insert(*v, *occ);
        }
        for (v, occ) in &last {
            let c = v.map(|i| (f64::from(i) + 0.5) * res);
            assert_eq!(tree.query(c), Some(*occ), "voxel {v:?}");
        }
        // Random points agree with a brute-force search over the leaves.
        if let Some((mn, mx)) = tree.metric_bounds() {
            for _ in 0..200 {
                let p: [f64; 3] =
                    std::array::from_fn(|a| mn[a] - res + (mx[a] - mn[a] + 2.0 * res) * rng.unit());
                let key = p.map(|c| ((1.0 / res) * c).floor());
                let brute = tree
                    .leaves()
                    .find(|l| {
                        (0..3).all(|a| {
                            let lo = ((l.center[a] - l.size / 2.0) / res).round();
                            key[a] >= lo && key[a] < lo + (l.size / res).round()
                        })
                    })
                    .map(|l| l.occupied);
                assert_eq!(tree.query(p), brute, "point {p:?}");
            }
        }
    }
}

#[test]
fn eight_equal_children_are_pruned_into_their_parent() {
    let block = |o: [i32; 3], edge: i32, occ: bool| {
        let mut v = Vec::new();
        for i in 0..edge {
            for j in 0..edge {
                for k in 0..edge {
                    v.push(([o[0] + i, o[1] + j, o[2] + k], occ));
                }
            }
        }
        v
    };
    // Aligned 2x2x2 of one state: one leaf at depth 15; 15 inner nodes + the leaf.
    let t = OcTree::from_voxels(0.1, block([2, -4, 6], 2, true)).unwrap();
    assert_eq!(t.counts(), (1, 0));
    assert_eq!(t.node_count(), 16);
    let leaf = t.leaves().next().unwrap();
    assert_eq!((leaf.depth, leaf.size), (15, 0.2));
    // Aligned 16^3: one leaf at depth 12.
    let t = OcTree::from_voxels(0.05, block([-32, 16, 0], 16, false)).unwrap();
    assert_eq!(t.counts(), (0, 1));
    assert_eq!(t.leaves().next().unwrap().depth, 12);
    let (mn, mx) = t.metric_bounds().unwrap();
    let expected = ([-1.6, 0.8, 0.0], [-0.8, 1.6, 0.8]);
    for a in 0..3 {
        assert!((mn[a] - expected.0[a]).abs() < 1e-12, "{mn:?}");
        assert!((mx[a] - expected.1[a]).abs() < 1e-12, "{mx:?}");
    }
    // Mixed states are not pruned.
    let mut mixed = block([0, 0, 0], 2, true);
    mixed[3].1 = false;
    let t = OcTree::from_voxels(0.1, mixed).unwrap();
    assert_eq!(t.counts(), (7, 1));
    assert!(t.leaves().all(|l| l.depth == 16));
    // Not aligned: nothing to prune.
    let t = OcTree::from_voxels(0.1, block([1, 0, 0], 2, true)).unwrap();
    assert_eq!(t.counts(), (8, 0));
    // Seven of eight: not pruned.
    let mut seven = block([0, 0, 0], 2, true);
    seven.pop();
    assert_eq!(OcTree::from_voxels(0.1, seven).unwrap().counts(), (7, 0));
    // 4x4x4 of one state, aligned: pruned twice, into one depth-14 leaf.
    let t = OcTree::from_voxels(0.1, block([4, 4, 4], 4, false)).unwrap();
    assert_eq!(t.counts(), (0, 1));
    assert_eq!(t.leaves().next().unwrap().depth, 14);
}

#[test]
fn from_voxels_last_state_wins_and_checks_range() {
    let t = OcTree::from_voxels(0.1, [([0, 0, 0], true), ([0, 0, 0], false)]).unwrap();
    assert_eq!(t.counts(), (0, 1));
    let t = OcTree::from_voxels(0.1, [([-32768, 32767, 0], true)]).unwrap();
    assert_eq!(t.query([-3276.75, 3276.75, 0.05]), Some(true));
    let e = OcTree::from_voxels(0.1, [([32768, 0, 0], true)]).unwrap_err();
    assert!(
        matches!(
            e,
            MapFileError::VoxelOutOfRange {
                voxel: [32768, 0, 0],
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().starts_with("<from_voxels>: "));
    let e = OcTree::from_voxels(f64::NAN, [([0, 0, 0], true)]).unwrap_err();
    assert!(matches!(e, MapFileError::BadResolution { .. }), "{e}");
}

#[test]
fn empty_tree() {
    let t = OcTree::from_voxels(0.1, []).unwrap();
    assert_eq!(t.counts(), (0, 0));
    assert_eq!(t.node_count(), 0);
    assert_eq!(t.metric_bounds(), None);
    assert_eq!(t.leaves().count(), 0);
    assert_eq!(t.query([0.0; 3]), None);
    let bytes = t.to_bt_bytes();
    assert!(bytes.ends_with(b"size 0\nres 0.1\ndata\n"));
    assert_eq!(OcTree::from_bt_bytes(&bytes, "e.bt").unwrap(), t);
}

#[test]
fn queries_outside_the_tree_are_unknown() {
    let t = OcTree::from_voxels(
        0.5,
        [([-32768, -32768, -32768], true), ([32767, 0, 0], false)],
    )
    .unwrap();
    let edge = 32768.0 * 0.5;
    assert_eq!(t.query([-edge, -edge, -edge]), Some(true));
    assert_eq!(t.query([edge - 0.25, 0.25, 0.25]), Some(false));
    assert_eq!(t.query([edge, 0.25, 0.25]), None);
    assert_eq!(t.query([-edge - 1e-9, -edge, -edge]), None);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300] {
        assert_eq!(t.query([bad, 0.0, 0.0]), None);
        assert_eq!(t.query([0.0, 0.0, bad]), None);
    }
}

#[test]
fn ot_files_we_write_read_back_as_the_same_tree() {
    let t = OcTree::from_bt_bytes(&tiny_bt(), "tiny.bt").unwrap();
    let ot = t.to_ot_bytes();
    assert!(ot.starts_with(b"# Octomap OcTree file\n"));
    assert_eq!(OcTree::from_bt_bytes(&ot, "tiny.ot").unwrap(), t);
    let empty = OcTree::empty(0.1);
    assert_eq!(
        OcTree::from_bt_bytes(&empty.to_ot_bytes(), "e.ot").unwrap(),
        empty
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.ot");
    t.write_ot(&path).unwrap();
    assert_eq!(OcTree::read_bt(&path).unwrap(), t);
}

#[test]
fn full_ot_files_are_read() {
    // The tiny tree as a full .ot: log-odds f32 + child-exists bits per node.
    let mut b = b"# Octomap OcTree file\n# c\nid OcTree\nsize 5\nres 1\ndata\n".to_vec();
    let rec = |b: &mut Vec<u8>, v: f32, mask: u8| {
        b.extend_from_slice(&v.to_le_bytes());
        b.push(mask);
    };
    rec(&mut b, 3.5, 0b1000_0011);
    rec(&mut b, 0.0, 0); // log-odds 0 is occupied (probability 0.5 >= threshold)
    rec(&mut b, -0.4, 0);
    rec(&mut b, 0.85, 0b0000_0001);
    rec(&mut b, -2.0, 0);
    let t = OcTree::from_bt_bytes(&b, "tiny.ot").unwrap();
    assert_eq!(t, OcTree::from_bt_bytes(&tiny_bt(), "tiny.bt").unwrap());
    // Bad .ot files.
    let mut nan = b.clone();
    let n = nan.len();
    nan[n - 5..n - 1].copy_from_slice(&f32::NAN.to_le_bytes());
    assert!(matches!(err(&nan), MapFileError::Corrupt { .. }));
    for cut in 1..b.len() - 52 {
        assert!(matches!(
            err(&b[..b.len() - cut]),
            MapFileError::Truncated { .. } | MapFileError::SizeImpossible { .. }
        ));
    }
    let mut extra = b.clone();
    extra.push(0);
    assert!(matches!(
        err(&extra),
        MapFileError::TrailingBytes { count: 1, .. }
    ));
    let mut lie = b.clone();
    let at = lie.windows(6).position(|w| w == b"size 5").unwrap();
    lie[at + 5] = b'4';
    assert!(matches!(
        err(&lie),
        MapFileError::SizeMismatch {
            header: 4,
            found: 5,
            ..
        }
    ));
    let mut color = b.clone();
    let at = color.windows(9).position(|w| w == b"id OcTree").unwrap() + 3;
    color.splice(at..at, b"Color".iter().copied());
    assert!(matches!(err(&color), MapFileError::UnknownId { .. }));
    let root_leaf = b"# Octomap OcTree file\nid OcTree\nsize 1\nres 1\ndata\n\0\0\0\0\0".to_vec();
    assert!(matches!(err(&root_leaf), MapFileError::Corrupt { .. }));
    // A chain 17 nodes deep: the node at depth 16 must not have children.
    let mut deep = b"# Octomap OcTree file\nid OcTree\nsize 18\nres 1\ndata\n".to_vec();
    for _ in 0..17 {
        rec(&mut deep, 1.0, 1);
    }
    rec(&mut deep, 1.0, 0);
    assert!(matches!(err(&deep), MapFileError::Corrupt { .. }));
}

#[test]
fn bad_files_give_clear_errors() {
    let good = room(0.1).to_bt_bytes();
    assert!(matches!(err(b""), MapFileError::Empty { .. }));
    let e = err(b"hello world\nid OcTree\n");
    assert!(matches!(e, MapFileError::NotOctoMap { .. }));
    assert!(e.to_string().contains("hello world"), "{e}");
    let mut legacy = 3i32.to_le_bytes().to_vec();
    legacy.extend_from_slice(&0.1f64.to_le_bytes());
    assert!(matches!(err(&legacy), MapFileError::LegacyFormat { .. }));
    // Header problems.
    for (h, what) in [
        (
            "# Octomap OcTree binary file\nid OcTree\nsize 5\nres 1\n",
            "data",
        ),
        ("# Octomap OcTree binary file\nsize 5\nres 1\ndata\n", "id"),
        (
            "# Octomap OcTree binary file\nid OcTree\nsize 5\ndata\n",
            "res",
        ),
        (
            "# Octomap OcTree binary file\nid OcTree\nres 1\ndata\n",
            "size",
        ),
        (
            "# Octomap OcTree binary file\nid OcTree\nsize -1\nres 1\ndata\n",
            "size",
        ),
        (
            "# Octomap OcTree binary file\nid OcTree\nsize 99999999999999999999999\nres 1\ndata\n",
            "size",
        ),
        (
            "# Octomap OcTree binary file\nid OcTree\nsize 5\nres abc\ndata\n",
            "res",
        ),
        ("# Octomap OcTree binary file", "data"),
    ] {
        let e = err(h.as_bytes());
        assert!(matches!(e, MapFileError::Header { .. }), "{h}: {e}");
        assert!(e.to_string().contains(what), "{e}");
    }
    // Resolutions.
    for r in ["nan", "inf", "-inf", "-0.1", "0", "1e-9", "1e6", "0.0009"] {
        let mut b = header("5", r);
        b.extend_from_slice(&[0x06, 0xc0, 0x01, 0x00]);
        let e = err(&b);
        assert!(matches!(e, MapFileError::BadResolution { .. }), "{r}: {e}");
        assert!(e.to_string().contains("resolution"), "{e}");
    }
    // Ids.
    let e = err(&String::from_utf8_lossy(&good)
        .replace("id OcTree", "id ColorOcTree")
        .into_bytes());
    assert!(
        matches!(e, MapFileError::UnknownId { ref id, .. } if id == "ColorOcTree"),
        "{e}"
    );
    // Sizes that lie.
    let nodes = room(0.1).node_count();
    let body = &good[good.windows(5).position(|w| w == b"data\n").unwrap() + 5..];
    for (claim, expect_impossible) in [
        (nodes + 1, false),
        (nodes - 1, false),
        (0, false),
        (4_000_000_000, true),
        (u64::MAX, true),
    ] {
        let mut b = header(&claim.to_string(), "0.1");
        b.extend_from_slice(body);
        let e = err(&b);
        if expect_impossible {
            assert!(
                matches!(e, MapFileError::SizeImpossible { .. }),
                "{claim}: {e}"
            );
        } else if claim == 0 {
            assert!(
                matches!(e, MapFileError::TrailingBytes { .. }),
                "{claim}: {e}"
            );
        } else {
            assert!(
                matches!(e, MapFileError::SizeMismatch { header, found, .. } if header == claim && found == nodes),
                "{e}"
            );
        }
    }
    // Trailing bytes.
    let mut extra = good.clone();
    extra.extend_from_slice(b"\n");
    assert!(matches!(
        err(&extra),
        MapFileError::TrailingBytes { count: 1, .. }
    ));
    // Corrupt trees: a childless inner node, a root without children, children at depth 16.
    let mut b = header("5", "1");
    b.extend_from_slice(&[0x06, 0xc0, 0x00, 0x00]);
    assert!(matches!(err(&b), MapFileError::Corrupt { .. }));
    let mut b = header("1", "1");
    b.extend_from_slice(&[0x00, 0x00]);
    assert!(matches!(err(&b), MapFileError::Corrupt { .. }));
    let mut b = header("18", "1");
    for _ in 0..17 {
        b.extend_from_slice(&[0x03, 0x00]);
    }
    b.extend_from_slice(&[0x02, 0x00]);
    let e = err(&b);
    assert!(matches!(e, MapFileError::Corrupt { .. }), "{e}");
    assert!(e.to_string().contains("16"), "{e}");
}

#[test]
fn every_truncation_is_an_error() {
    let good = room(0.2).to_bt_bytes();
    let data_start = good.windows(5).position(|w| w == b"data\n").unwrap() + 5;
    for len in 0..good.len() {
        let e = err(&good[..len]);
        if len > data_start {
            assert!(
                matches!(
                    e,
                    MapFileError::Truncated { .. } | MapFileError::SizeImpossible { .. }
                ),
                "{len}: {e}"
            );
        }
    }
}

#[test]
fn random_bytes_never_panic() {
    let mut rng = Rng(99);
    let good = room(0.1).to_bt_bytes();
    let data_start = good.windows(5).position(|w| w == b"data\n").unwrap() + 5;
    for round in 0..3000 {
        let mut b: Vec<u8> = if round % 3 == 0 {
            (0..rng.below(300)).map(|_| rng.next() as u8).collect()
        } else {
            good.clone()
        };
        if round % 3 == 1 {
            // Flip a few bytes of the tree.
            for _ in 0..1 + rng.below(4) {
                let at = data_start + rng.below((good.len() - data_start) as u64) as usize;
                b[at] = rng.next() as u8;
            }
        } else if round % 3 == 2 {
            // Valid header, random tree of a random length.
            b.truncate(data_start);
            b.extend((0..rng.below(200)).map(|_| rng.next() as u8));
        }
        if let Ok(t) = OcTree::from_bt_bytes(&b, "random.bt") {
            assert_eq!(OcTree::from_bt_bytes(&t.to_bt_bytes(), "again").unwrap(), t);
            let (o, f) = t.counts();
            assert_eq!(t.leaves().count(), o + f);
        }
    }
}

#[test]
fn files_are_written_atomically_and_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("room.bt");
    let tree = room(0.05);
    tree.write_bt(&path).unwrap();
    assert_eq!(OcTree::read_bt(&path).unwrap(), tree);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    let missing = dir.path().join("missing.bt");
    let e = OcTree::read_bt(&missing).unwrap_err();
    assert!(matches!(e, MapFileError::Io { action: "read", .. }));
    assert!(e.to_string().contains("missing.bt"), "{e}");
    let e = tree
        .write_bt(&dir.path().join("no/such/dir/x.bt"))
        .unwrap_err();
    assert!(
        matches!(
            e,
            MapFileError::Io {
                action: "write",
                ..
            }
        ),
        "{e}"
    );
}
