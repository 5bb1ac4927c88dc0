//! Unit tests of the exports: CDR layout, schemas, ticks, frames and the log's order.
//! The files as a whole are decoded by independent readers in python/tests.

use mavlink::dialects::common::MavMessage;
use mavlink::{MavlinkVersion, Message};
use nalgebra::{UnitQuaternion, Vector3};

use super::motion::{Motion, MIN_RATE_HZ};
use super::ros2_msgs::{self as msg, cdr, schema, Time};
use super::tlog::{tlog, TlogOptions};
use super::{attitude_ned, export, ned, ExportError, ExportOptions};
use crate::plan_file::{ChainSection, MapSection, MapSource};
use crate::trajectory::{Limits, SampleRow, TrajectoryFile, TrajectoryStats, FORMAT};

/// A chain of two units whose head flies along +x at `speed` m/s, sampled every `dt`
/// s for `steps` steps, the link trailing along -x.
fn straight(speed: f64, dt: f64, steps: usize) -> TrajectoryFile {
    let params = aerial_chain_core::ChainParams::new(2);
    let samples = (0..=steps)
        .map(|j| {
            let (t, x) = (j as f64 * dt, speed * j as f64 * dt);
            SampleRow {
                t,
                zeta: vec![x, 0.0, 1.0, 0.0, 0.0, 0.0],
                p: vec![[x, 0.0, 1.0], [x - 0.5, 0.0, 1.0]],
                q: vec![[1.0, 0.0, 0.0, 0.0]; 2],
            }
        })
        .collect();
    TrajectoryFile {
        format: FORMAT.into(),
        chain: ChainSection::from_params(&params),
        map: MapSection {
            resolution: 0.1,
            unknown_is_occupied: true,
            source: MapSource::default(),
        },
        limits: Limits::default(),
        dt,
        stats: TrajectoryStats::default(),
        samples,
    }
}

#[test]
fn cdr_writes_the_encapsulation_then_aligned_fields() {
    let header = msg::Header {
        stamp: Time { sec: 1, nanosec: 2 },
        frame_id: "map",
    };
    let bytes = cdr(&header).unwrap();
    let want: Vec<u8> = [0, 1, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 4, 0, 0, 0]
        .into_iter()
        .chain(*b"map\0")
        .collect();
    assert_eq!(bytes, want);
    // A double after a 2-character frame (15 bytes of fields) starts at field offset
    // 16: CDR aligns to the value's size, counted after the encapsulation.
    let pose = msg::PoseStamped {
        header: msg::Header {
            stamp: Time::default(),
            frame_id: "ab",
        },
        pose: msg::Pose {
            position: msg::Vector3 {
                x: 1.5,
                y: 0.0,
                z: 0.0,
            },
            orientation: UnitQuaternion::identity().into(),
        },
    };
    let bytes = cdr(&pose).unwrap();
    assert_eq!(bytes[19], 0, "padding");
    assert_eq!(bytes[20..28], 1.5f64.to_le_bytes());
    assert_eq!(bytes.len(), 4 + 16 + 7 * 8);
}

#[test]
fn time_splits_seconds_and_nanoseconds() {
    assert_eq!(
        Time::of_seconds(2.5),
        Time {
            sec: 2,
            nanosec: 500_000_000
        }
    );
    assert_eq!(
        Time::of_seconds(0.999_999_999_9),
        Time { sec: 1, nanosec: 0 }
    );
}

#[test]
fn schemas_define_every_type_they_name_once() {
    for kind in [
        "trajectory_msgs/MultiDOFJointTrajectory",
        "nav_msgs/Path",
        "tf2_msgs/TFMessage",
        "visualization_msgs/MarkerArray",
        "octomap_msgs/Octomap",
    ] {
        let text = schema(kind);
        let defined: Vec<&str> = text
            .lines()
            .filter_map(|l| l.strip_prefix("MSG: "))
            .collect();
        let mut unique = defined.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), defined.len(), "{kind}: a type twice");
        assert!(text.contains("std_msgs/Header header"), "{kind}");
        assert!(defined.contains(&"builtin_interfaces/Time"), "{kind}");
    }
    let markers = schema("visualization_msgs/MarkerArray");
    for dep in [
        "visualization_msgs/Marker",
        "visualization_msgs/UVCoordinate",
        "visualization_msgs/MeshFile",
        "sensor_msgs/CompressedImage",
        "std_msgs/ColorRGBA",
        "geometry_msgs/Point",
    ] {
        assert!(markers.contains(&format!("MSG: {dep}\n")), "{dep}");
    }
}

#[test]
fn ticks_fall_on_the_rate_and_end_at_the_end() {
    let file = straight(0.5, 0.02, 50);
    let m = Motion::of_trajectory(&file, 50.0).unwrap();
    assert_eq!(m.ticks.len(), 51);
    for (k, tick) in m.ticks.iter().enumerate() {
        assert!((tick.t - k as f64 * 0.02).abs() < 1e-12);
        let want = 0.5 * tick.t;
        assert!((tick.units[0].p.x - want).abs() < 1e-12);
        assert!((tick.units[1].p.x - (want - 0.5)).abs() < 1e-12);
    }
    let m = Motion::of_trajectory(&file, 30.0).unwrap();
    let times: Vec<f64> = m.ticks.iter().map(|t| t.t).collect();
    assert_eq!(times.len(), 31);
    assert_eq!(*times.last().unwrap(), 1.0);
    assert!(times
        .windows(2)
        .all(|w| w[1] - w[0] > 1e-6 && w[1] - w[0] <= 1.0 / 30.0 + 1e-12));
    // Between samples the units are where paper Eq. 2 puts the interpolated zeta.
    assert!((m.ticks[1].units[0].p.x - 0.5 / 30.0).abs() < 1e-12);
    // 30 000 s of a 2-unit chain at 50 Hz: 3 M unit states, over the budget.
    let long = straight(0.0, 1000.0, 30);
    assert!(matches!(
        Motion::of_trajectory(&long, 50.0),
        Err(ExportError::TooLong { units: 2, .. })
    ));
    for rate in [MIN_RATE_HZ, 0.0, -1.0, f64::NAN, f64::INFINITY, 1e4] {
        assert!(matches!(
            Motion::of_trajectory(&file, rate),
            Err(ExportError::Rate(_))
        ));
    }
}

#[test]
fn a_steady_motion_has_its_velocity_and_no_acceleration() {
    let m = Motion::of_trajectory(&straight(0.4, 0.02, 100), 50.0).unwrap();
    for tick in &m.ticks {
        for u in &tick.units {
            assert!((u.v - Vector3::new(0.4, 0.0, 0.0)).norm() < 1e-9);
            assert!(u.a.norm() < 1e-6);
            assert_eq!(u.w, Vector3::zeros());
        }
    }
}

#[test]
fn ned_swaps_east_and_north_and_turns_up_down() {
    assert_eq!(ned(&Vector3::new(1.0, 2.0, 3.0)), [2.0, 1.0, -3.0]);
    for psi in [0.0, 0.3, 1.2, -2.0, 3.0] {
        let q = attitude_ned(&UnitQuaternion::from_euler_angles(0.0, 0.0, psi));
        let r = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            q[0] as f64,
            q[1] as f64,
            q[2] as f64,
            q[3] as f64,
        ));
        let (roll, pitch, yaw) = r.euler_angles();
        let want = std::f64::consts::FRAC_PI_2 - psi;
        let d = (yaw - want + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        assert!(
            d.abs() < 1e-6 && roll.abs() < 1e-6 && pitch.abs() < 1e-6,
            "{psi}"
        );
        // FRD's z axis points down: +z of NED.
        assert!((r * Vector3::z() - Vector3::z()).norm() < 1e-6);
    }
    // A unit pitched nose-up in ENU (about its left y axis) is nose-up in NED too.
    let up = attitude_ned(&UnitQuaternion::from_euler_angles(0.0, -0.2, 0.0));
    let r = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
        up[0] as f64,
        up[1] as f64,
        up[2] as f64,
        up[3] as f64,
    ));
    assert!(
        (r * Vector3::x()).z < 0.0,
        "the nose rises: up is -z in NED"
    );
}

/// The `(time, message)` records of a `.tlog`, decoded frame by frame.
fn records(bytes: &[u8]) -> Vec<(f64, u8, MavMessage)> {
    let mut out = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        let micros = u64::from_be_bytes(bytes[at..at + 8].try_into().unwrap());
        let frame = &bytes[at + 8..];
        assert_eq!(frame[0], 0xFD, "MAVLink 2");
        let len = frame[1] as usize;
        let (system, component) = (frame[5], frame[6]);
        assert_eq!((system, component), (255, 191));
        let id = u32::from_le_bytes([frame[7], frame[8], frame[9], 0]);
        // MAVLink 2 trims trailing zeros of a payload; the parser takes it as sent.
        let m = MavMessage::parse(MavlinkVersion::V2, id, &frame[10..10 + len]).unwrap();
        out.push((micros as f64 * 1e-6, frame[4], m));
        at += 8 + 10 + len + 2;
    }
    out
}

#[test]
fn the_log_holds_then_arms_then_flies() {
    let m = Motion::of_trajectory(&straight(0.5, 0.02, 150), 50.0).unwrap();
    let options = TlogOptions {
        sysid_base: 3,
        arm: true,
        ..TlogOptions::default()
    };
    let (bytes, summary) = tlog(&m, &options).unwrap();
    let recs = records(&bytes);
    assert_eq!(
        recs.len(),
        summary.heartbeats + summary.position_targets + summary.commands
    );
    assert!(recs.windows(2).all(|w| w[1].0 >= w[0].0), "time order");
    let seq: Vec<u8> = recs.iter().map(|r| r.1).collect();
    assert!(
        seq.iter().enumerate().all(|(i, s)| *s == i as u8),
        "sequence"
    );
    let beats: Vec<f64> = recs
        .iter()
        .filter(|r| matches!(r.2, MavMessage::HEARTBEAT(_)))
        .map(|r| r.0)
        .collect();
    assert_eq!(beats, vec![0.0, 1.0, 2.0, 3.0, 4.0]); // 1 s hold + 3 s of motion
    let commands: Vec<(f64, u8, u16)> = recs
        .iter()
        .filter_map(|r| match &r.2 {
            MavMessage::COMMAND_LONG(c) => Some((r.0, c.target_system, c.command as u16)),
            _ => None,
        })
        .collect();
    assert_eq!(
        commands,
        vec![(1.0, 3, 176), (1.0, 3, 400), (1.0, 4, 176), (1.0, 4, 400)]
    );
    let unit4: Vec<(f64, f32)> = recs
        .iter()
        .filter_map(|r| match &r.2 {
            MavMessage::SET_POSITION_TARGET_LOCAL_NED(s) if s.target_system == 4 => {
                Some((r.0, s.y))
            }
            _ => None,
        })
        .collect();
    assert_eq!(unit4.len(), 50 + 151);
    let first_setpoint = unit4[0].0;
    assert!(commands[0].0 - first_setpoint >= 1.0 - 1e-9);
    // Unit 2 trails 0.5 m behind the head: east is NED's y.
    assert!((unit4[0].1 - -0.5).abs() < 1e-6);
    assert!((unit4.last().unwrap().1 - 1.0).abs() < 1e-6);
}

#[test]
fn bad_options_are_refused_and_leave_no_file() {
    let m = Motion::of_trajectory(&straight(0.5, 0.02, 10), 50.0).unwrap();
    for options in [
        TlogOptions {
            sysid_base: 0,
            ..TlogOptions::default()
        },
        TlogOptions {
            sysid_base: 254,
            ..TlogOptions::default()
        },
        TlogOptions {
            hold: 0.5,
            arm: true,
            ..TlogOptions::default()
        },
        TlogOptions {
            hold: f64::NAN,
            ..TlogOptions::default()
        },
    ] {
        assert!(matches!(tlog(&m, &options), Err(ExportError::Option(_))));
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.tlog");
    let options = ExportOptions {
        tlog: TlogOptions {
            sysid_base: 0,
            ..TlogOptions::default()
        },
    };
    assert!(export(&m, None, &path, &options).is_err());
    assert!(!path.exists());
    let txt = dir.path().join("x.txt");
    assert!(matches!(
        export(&m, None, &txt, &ExportOptions::default()),
        Err(ExportError::Format(_))
    ));
    assert!(!txt.exists());
}

#[test]
fn a_bag_holds_a_message_per_tick_on_its_streams() {
    let m = Motion::of_trajectory(&straight(0.5, 0.02, 20), 50.0).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("b.mcap");
    let w = export(&m, None, &path, &ExportOptions::default()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(bytes.len(), w.bytes);
    let mut count = std::collections::BTreeMap::new();
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        let message = message.unwrap();
        assert_eq!(message.channel.message_encoding, "cdr");
        let schema = message.channel.schema.as_ref().unwrap();
        assert_eq!(schema.encoding, "ros2msg");
        assert_eq!(&message.data[..4], &[0, 1, 0, 0]);
        *count.entry(message.channel.topic.clone()).or_insert(0) += 1;
    }
    assert_eq!(count["/tf"], 21);
    assert_eq!(count["/arc/chain"], 21);
    assert_eq!(count["/arc/trajectory"], 1);
    assert_eq!(count["/arc/unit_2/path"], 1);
    assert!(!count.contains_key("/arc/map"), "no map given");
}
