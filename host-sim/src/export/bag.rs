//! A motion as a ROS 2 bag: an MCAP file (profile `ros2`) of CDR messages with their
//! `ros2msg` schemas, stamped on the motion's clock (docs/model.md, "Exports").
//!
//! Topics, all in the frame `map` (the world frame W: x, y, z up, as ROS's REP 103):
//! - `/arc/map` (`octomap_msgs/Octomap`), once at the start, when a map is given;
//! - `/arc/trajectory` (`trajectory_msgs/MultiDOFJointTrajectory`), once at the start:
//!   one joint per unit (`unit_1` is the head), a point per tick;
//! - `/arc/unit_<i>/path` (`nav_msgs/Path`), once at the start: unit i's poses;
//! - `/tf` (`tf2_msgs/TFMessage`) at every tick: `map` -> `unit_<i>` for every unit;
//! - `/arc/chain` (`visualization_msgs/MarkerArray`) at every tick: the unit spheres
//!   and the links.

use std::collections::BTreeMap;
use std::io::Cursor;

use mcap::records::MessageHeader;
use serde::Serialize;

use super::motion::{Motion, Tick, UnitState};
use super::ros2_msgs::{self as msg, nanoseconds, schema, schema_name, Time};
use super::ExportError;

/// The frame every message is in: the world frame W.
pub const FRAME: &str = "map";

/// What a bag holds: messages per topic.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BagSummary {
    /// `(topic, messages)`, in the order the topics were added.
    pub topics: Vec<(String, usize)>,
}

/// An MCAP writer into memory that knows its channels by topic.
struct Bag {
    writer: mcap::Writer<Cursor<Vec<u8>>>,
    channels: BTreeMap<String, (u16, u32)>,
    summary: BagSummary,
}

/// An MCAP error as an export error.
fn mcap_error(e: mcap::McapError) -> ExportError {
    ExportError::Encode(format!("MCAP: {e}"))
}

impl Bag {
    fn new() -> Result<Self, ExportError> {
        let writer = mcap::WriteOptions::new()
            .compression(None)
            .profile("ros2")
            .create(Cursor::new(Vec::new()))
            .map_err(mcap_error)?;
        Ok(Self {
            writer,
            channels: BTreeMap::new(),
            summary: BagSummary::default(),
        })
    }

    /// Adds the topic `topic` of message type `kind` (`package/Name`).
    fn topic(&mut self, topic: &str, kind: &str) -> Result<(), ExportError> {
        let schema_id = self
            .writer
            .add_schema(&schema_name(kind), "ros2msg", schema(kind).as_bytes())
            .map_err(mcap_error)?;
        let id = self
            .writer
            .add_channel(schema_id, topic, "cdr", &BTreeMap::new())
            .map_err(mcap_error)?;
        self.channels.insert(topic.to_string(), (id, 0));
        self.summary.topics.push((topic.to_string(), 0));
        Ok(())
    }

    /// Writes `message` on `topic` at `t` seconds.
    fn write<T: Serialize>(&mut self, topic: &str, t: f64, message: &T) -> Result<(), ExportError> {
        let data = msg::cdr(message).map_err(|e| ExportError::Encode(format!("CDR: {e}")))?;
        let (id, sequence) = self
            .channels
            .get_mut(topic)
            .ok_or_else(|| ExportError::Encode(format!("no channel {topic} (a bug)")))?;
        let header = MessageHeader {
            channel_id: *id,
            sequence: *sequence,
            log_time: nanoseconds(t),
            publish_time: nanoseconds(t),
        };
        *sequence += 1;
        if let Some(entry) = self.summary.topics.iter_mut().find(|(n, _)| n == topic) {
            entry.1 += 1;
        }
        self.writer
            .write_to_known_channel(&header, &data)
            .map_err(mcap_error)
    }

    fn finish(mut self) -> Result<(Vec<u8>, BagSummary), ExportError> {
        self.writer.finish().map_err(mcap_error)?;
        Ok((self.writer.into_inner().into_inner(), self.summary))
    }
}

/// A header at `t` in [`FRAME`].
fn header(t: f64) -> msg::Header<'static> {
    msg::Header {
        stamp: Time::of_seconds(t),
        frame_id: FRAME,
    }
}

/// Unit `u`'s frame name (`unit_1` is the head).
fn unit_frame(u: usize) -> String {
    format!("unit_{}", u + 1)
}

/// A unit's pose as a transform from [`FRAME`].
fn transform(s: &UnitState) -> msg::Transform {
    msg::Transform {
        translation: s.p.into(),
        rotation: s.q.into(),
    }
}

/// The whole motion as one multi-DOF joint trajectory, a joint per unit.
fn trajectory(motion: &Motion) -> msg::MultiDofTrajectory<'static> {
    let t0 = motion.ticks[0].t;
    let twist = |v: nalgebra::Vector3<f64>, w: nalgebra::Vector3<f64>| msg::Twist {
        linear: v.into(),
        angular: w.into(),
    };
    let points = motion
        .ticks
        .iter()
        .map(|tick| msg::MultiDofPoint {
            transforms: tick.units.iter().map(transform).collect(),
            velocities: tick.units.iter().map(|s| twist(s.v, s.w)).collect(),
            accelerations: tick.units.iter().map(|s| twist(s.a, s.alpha)).collect(),
            time_from_start: Time::of_seconds(tick.t - t0),
        })
        .collect();
    msg::MultiDofTrajectory {
        header: header(t0),
        joint_names: (0..motion.units()).map(unit_frame).collect(),
        points,
    }
}

/// Unit `u`'s path: its pose at every tick.
fn path(motion: &Motion, u: usize) -> msg::Path<'static> {
    let poses = motion
        .ticks
        .iter()
        .map(|tick| msg::PoseStamped {
            header: header(tick.t),
            pose: msg::Pose {
                position: tick.units[u].p.into(),
                orientation: tick.units[u].q.into(),
            },
        })
        .collect();
    msg::Path {
        header: header(motion.ticks[0].t),
        poses,
    }
}

/// The transforms of every unit at a tick.
fn tf<'a>(tick: &Tick, frames: &'a [String]) -> msg::TfMessage<'a> {
    let transforms = tick
        .units
        .iter()
        .zip(frames)
        .map(|(s, frame)| msg::TransformStamped {
            header: header(tick.t),
            child_frame_id: frame,
            transform: transform(s),
        })
        .collect();
    msg::TfMessage { transforms }
}

/// The colour of the units (orange) and of the links (grey).
const UNIT_COLOUR: msg::ColorRgba = msg::ColorRgba {
    r: 1.0,
    g: 0.55,
    b: 0.1,
    a: 1.0,
};
const LINK_COLOUR: msg::ColorRgba = msg::ColorRgba {
    r: 0.3,
    g: 0.3,
    b: 0.3,
    a: 1.0,
};

/// One list marker of the chain at `t`: `points` drawn as `kind` of size `size` (m).
fn marker(
    t: f64,
    id: i32,
    kind: i32,
    size: f64,
    colour: msg::ColorRgba,
    points: Vec<msg::Vector3>,
) -> msg::Marker<'static> {
    msg::Marker {
        header: header(t),
        ns: "arc",
        id,
        kind,
        action: 0,
        pose: msg::Pose {
            position: msg::Vector3::default(),
            orientation: nalgebra::UnitQuaternion::identity().into(),
        },
        scale: msg::Vector3 {
            x: size,
            y: size,
            z: size,
        },
        color: colour,
        lifetime: Time::default(),
        frame_locked: false,
        points,
        colors: Vec::new(),
        texture_resource: "",
        texture: msg::CompressedImage {
            header: header(t),
            format: "",
            data: Vec::new(),
        },
        uv_coordinates: Vec::new(),
        text: "",
        mesh_resource: "",
        mesh_file: msg::MeshFile {
            filename: "",
            data: Vec::new(),
        },
        mesh_use_embedded_materials: false,
    }
}

/// The chain at a tick: its unit spheres (diameter 2 r_u) and its links (width 2 r_l).
fn chain_markers(motion: &Motion, tick: &Tick) -> msg::MarkerArray<'static> {
    let centres: Vec<msg::Vector3> = tick.units.iter().map(|s| s.p.into()).collect();
    let links = centres.windows(2).flat_map(|w| [w[0], w[1]]).collect();
    let c = &motion.chain;
    msg::MarkerArray {
        markers: vec![
            marker(
                tick.t,
                0,
                msg::SPHERE_LIST,
                2.0 * c.unit_radius,
                UNIT_COLOUR,
                centres,
            ),
            marker(
                tick.t,
                1,
                msg::LINE_LIST,
                2.0 * c.link_radius,
                LINK_COLOUR,
                links,
            ),
        ],
    }
}

/// The bag of `motion`, with the map's OctoMap stream (`writeBinaryData`) and its
/// resolution when given: the file's bytes and what it holds.
pub fn bag(
    motion: &Motion,
    map: Option<(&[u8], f64)>,
) -> Result<(Vec<u8>, BagSummary), ExportError> {
    let mut bag = Bag::new()?;
    let t0 = motion.ticks[0].t;
    if let Some((stream, resolution)) = map {
        bag.topic("/arc/map", "octomap_msgs/Octomap")?;
        let message = msg::Octomap {
            header: header(t0),
            binary: true,
            id: "OcTree",
            resolution,
            data: stream.iter().map(|&b| b as i8).collect(),
        };
        bag.write("/arc/map", t0, &message)?;
    }
    bag.topic("/arc/trajectory", "trajectory_msgs/MultiDOFJointTrajectory")?;
    bag.write("/arc/trajectory", t0, &trajectory(motion))?;
    for u in 0..motion.units() {
        let topic = format!("/arc/{}/path", unit_frame(u));
        bag.topic(&topic, "nav_msgs/Path")?;
        bag.write(&topic, t0, &path(motion, u))?;
    }
    bag.topic("/tf", "tf2_msgs/TFMessage")?;
    bag.topic("/arc/chain", "visualization_msgs/MarkerArray")?;
    let frames: Vec<String> = (0..motion.units()).map(unit_frame).collect();
    for tick in &motion.ticks {
        bag.write("/tf", tick.t, &tf(tick, &frames))?;
        bag.write("/arc/chain", tick.t, &chain_markers(motion, tick))?;
    }
    bag.finish()
}
