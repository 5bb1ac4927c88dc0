//! The ROS 2 messages a bag holds, as serde types laid out field for field as their
//! `.msg` definitions (so that CDR encodes them as ROS 2 does), and those definitions
//! as the `ros2msg` schema text an MCAP reader decodes them with.
//!
//! The definitions are those of ROS 2's `common_interfaces`, `geometry2` and
//! `octomap_msgs` (the same since Humble), without their comments.

use byteorder::LittleEndian;
use serde::Serialize;

/// `builtin_interfaces/Time` and `builtin_interfaces/Duration` (the same layout).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Time {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds, below 1e9.
    pub nanosec: u32,
}

impl Time {
    /// `t` seconds (at least 0) as seconds and nanoseconds, rounded to a nanosecond.
    pub fn of_seconds(t: f64) -> Self {
        let ns = nanoseconds(t);
        Self {
            sec: (ns / 1_000_000_000) as i32,
            nanosec: (ns % 1_000_000_000) as u32,
        }
    }
}

/// `t` seconds (at least 0) in whole nanoseconds, rounded.
pub fn nanoseconds(t: f64) -> u64 {
    (t.max(0.0) * 1e9).round() as u64
}

/// `std_msgs/Header`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Header<'a> {
    /// When.
    pub stamp: Time,
    /// The frame the data is in.
    pub frame_id: &'a str,
}

/// `geometry_msgs/Vector3` and `geometry_msgs/Point` (the same layout).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

impl From<nalgebra::Vector3<f64>> for Vector3 {
    fn from(v: nalgebra::Vector3<f64>) -> Self {
        Self {
            x: v.x,
            y: v.y,
            z: v.z,
        }
    }
}

impl From<nalgebra::Point3<f64>> for Vector3 {
    fn from(p: nalgebra::Point3<f64>) -> Self {
        p.coords.into()
    }
}

/// `geometry_msgs/Quaternion` (x, y, z, w: ROS's order).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

impl From<nalgebra::UnitQuaternion<f64>> for Quaternion {
    fn from(q: nalgebra::UnitQuaternion<f64>) -> Self {
        Self {
            x: q.i,
            y: q.j,
            z: q.k,
            w: q.w,
        }
    }
}

/// `geometry_msgs/Pose`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Pose {
    /// Position (a `geometry_msgs/Point`).
    pub position: Vector3,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `geometry_msgs/Transform`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Transform {
    /// Translation.
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}

/// `geometry_msgs/Twist` (velocities and accelerations alike).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Twist {
    /// Linear part.
    pub linear: Vector3,
    /// Angular part.
    pub angular: Vector3,
}

/// `geometry_msgs/TransformStamped`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TransformStamped<'a> {
    /// Stamp and parent frame.
    pub header: Header<'a>,
    /// The child frame.
    pub child_frame_id: &'a str,
    /// The child's pose in the parent frame.
    pub transform: Transform,
}

/// `tf2_msgs/TFMessage`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TfMessage<'a> {
    /// The transforms.
    pub transforms: Vec<TransformStamped<'a>>,
}

/// `trajectory_msgs/MultiDOFJointTrajectoryPoint`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MultiDofPoint {
    /// One pose per joint.
    pub transforms: Vec<Transform>,
    /// One velocity per joint.
    pub velocities: Vec<Twist>,
    /// One acceleration per joint.
    pub accelerations: Vec<Twist>,
    /// Time from the trajectory's start (a `builtin_interfaces/Duration`).
    pub time_from_start: Time,
}

/// `trajectory_msgs/MultiDOFJointTrajectory`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MultiDofTrajectory<'a> {
    /// Start time and frame.
    pub header: Header<'a>,
    /// One joint per unit.
    pub joint_names: Vec<String>,
    /// The points.
    pub points: Vec<MultiDofPoint>,
}

/// `geometry_msgs/PoseStamped`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PoseStamped<'a> {
    /// Stamp and frame.
    pub header: Header<'a>,
    /// The pose.
    pub pose: Pose,
}

/// `nav_msgs/Path`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Path<'a> {
    /// Stamp and frame.
    pub header: Header<'a>,
    /// The poses, in time order.
    pub poses: Vec<PoseStamped<'a>>,
}

/// `std_msgs/ColorRGBA`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ColorRgba {
    /// Red, 0 to 1.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
    /// Opacity.
    pub a: f32,
}

/// `sensor_msgs/CompressedImage` (a marker's texture; left empty here).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompressedImage<'a> {
    /// Stamp and frame.
    pub header: Header<'a>,
    /// Image format.
    pub format: &'a str,
    /// Image bytes.
    pub data: Vec<u8>,
}

/// `visualization_msgs/UVCoordinate`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct UvCoordinate {
    /// u.
    pub u: f32,
    /// v.
    pub v: f32,
}

/// `visualization_msgs/MeshFile` (left empty here).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeshFile<'a> {
    /// File name.
    pub filename: &'a str,
    /// File bytes.
    pub data: Vec<u8>,
}

/// `visualization_msgs/Marker`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Marker<'a> {
    /// Stamp and frame.
    pub header: Header<'a>,
    /// Namespace.
    pub ns: &'a str,
    /// Id within the namespace.
    pub id: i32,
    /// Shape: [`SPHERE_LIST`], [`LINE_LIST`], ...
    #[serde(rename = "type")]
    pub kind: i32,
    /// 0: add or modify.
    pub action: i32,
    /// Pose of the marker's frame.
    pub pose: Pose,
    /// Size: sphere diameters, or line width in `x`.
    pub scale: Vector3,
    /// Colour.
    pub color: ColorRgba,
    /// How long it stays (0: until replaced).
    pub lifetime: Time,
    /// Whether it moves with its frame.
    pub frame_locked: bool,
    /// Points of list shapes.
    pub points: Vec<Vector3>,
    /// Per-point colours (none: `color` for all).
    pub colors: Vec<ColorRgba>,
    /// Texture (unused).
    pub texture_resource: &'a str,
    /// Texture image (unused).
    pub texture: CompressedImage<'a>,
    /// Texture coordinates (unused).
    pub uv_coordinates: Vec<UvCoordinate>,
    /// Text of text markers (unused).
    pub text: &'a str,
    /// Mesh (unused).
    pub mesh_resource: &'a str,
    /// Mesh file (unused).
    pub mesh_file: MeshFile<'a>,
    /// Mesh materials (unused).
    pub mesh_use_embedded_materials: bool,
}

/// `Marker.SPHERE_LIST`.
pub const SPHERE_LIST: i32 = 7;
/// `Marker.LINE_LIST`.
pub const LINE_LIST: i32 = 5;

/// `visualization_msgs/MarkerArray`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MarkerArray<'a> {
    /// The markers.
    pub markers: Vec<Marker<'a>>,
}

/// `octomap_msgs/Octomap`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Octomap<'a> {
    /// Stamp and frame.
    pub header: Header<'a>,
    /// Whether `data` is the binary (max-likelihood) stream of `writeBinaryData`.
    pub binary: bool,
    /// The tree's type, `"OcTree"`.
    pub id: &'a str,
    /// Voxel edge (m).
    pub resolution: f64,
    /// The tree's stream.
    pub data: Vec<i8>,
}

/// A message as ROS 2 puts it on the wire and in a bag: a CDR little-endian
/// encapsulation header, then the fields.
pub fn cdr<T: Serialize>(message: &T) -> Result<Vec<u8>, cdr_encoding::Error> {
    let mut out = vec![0x00, 0x01, 0x00, 0x00];
    cdr_encoding::to_writer::<_, LittleEndian, _>(&mut out, message)?;
    Ok(out)
}

/// Every definition a bag's messages use: `(package/Name, text)`.
const DEFINITIONS: &[(&str, &str)] = &[
    ("builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n"),
    ("builtin_interfaces/Duration", "int32 sec\nuint32 nanosec\n"),
    (
        "std_msgs/Header",
        "builtin_interfaces/Time stamp\nstring frame_id\n",
    ),
    (
        "std_msgs/ColorRGBA",
        "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n",
    ),
    ("geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"),
    ("geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"),
    (
        "geometry_msgs/Quaternion",
        "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
    ),
    (
        "geometry_msgs/Pose",
        "Point position\nQuaternion orientation\n",
    ),
    (
        "geometry_msgs/PoseStamped",
        "std_msgs/Header header\nPose pose\n",
    ),
    (
        "geometry_msgs/Transform",
        "Vector3 translation\nQuaternion rotation\n",
    ),
    (
        "geometry_msgs/TransformStamped",
        "std_msgs/Header header\nstring child_frame_id\nTransform transform\n",
    ),
    ("geometry_msgs/Twist", "Vector3 linear\nVector3 angular\n"),
    (
        "tf2_msgs/TFMessage",
        "geometry_msgs/TransformStamped[] transforms\n",
    ),
    (
        "trajectory_msgs/MultiDOFJointTrajectory",
        "std_msgs/Header header\nstring[] joint_names\nMultiDOFJointTrajectoryPoint[] points\n",
    ),
    (
        "trajectory_msgs/MultiDOFJointTrajectoryPoint",
        "geometry_msgs/Transform[] transforms\ngeometry_msgs/Twist[] velocities\n\
         geometry_msgs/Twist[] accelerations\nbuiltin_interfaces/Duration time_from_start\n",
    ),
    (
        "nav_msgs/Path",
        "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n",
    ),
    (
        "sensor_msgs/CompressedImage",
        "std_msgs/Header header\nstring format\nuint8[] data\n",
    ),
    ("visualization_msgs/UVCoordinate", "float32 u\nfloat32 v\n"),
    (
        "visualization_msgs/MeshFile",
        "string filename\nuint8[] data\n",
    ),
    (
        "visualization_msgs/Marker",
        "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n\
         int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n\
         int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\n\
         int32 ARROW_STRIP=12\nint32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n\
         std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n\
         geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n\
         builtin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\n\
         std_msgs/ColorRGBA[] colors\nstring texture_resource\n\
         sensor_msgs/CompressedImage texture\nUVCoordinate[] uv_coordinates\nstring text\n\
         string mesh_resource\nMeshFile mesh_file\nbool mesh_use_embedded_materials\n",
    ),
    ("visualization_msgs/MarkerArray", "Marker[] markers\n"),
    (
        "octomap_msgs/Octomap",
        "std_msgs/Header header\nbool binary\nstring id\nfloat64 resolution\nint8[] data\n",
    ),
];

/// The `.msg` primitive types: no definition of their own.
const PRIMITIVES: &[&str] = &[
    "bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
    "uint64", "float32", "float64", "string", "wstring",
];

/// The definition of `name` (`package/Name`).
fn definition(name: &str) -> &'static str {
    DEFINITIONS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| *text)
        .unwrap_or_else(|| panic!("no definition of {name} (a bug: add it)"))
}

/// The full names of the message types the fields of `package`'s `text` name, in
/// order: a field's type without its array suffix, with `package` where it names
/// none. Constants (`TYPE NAME=VALUE`) are no fields.
fn field_types(package: &str, text: &str) -> Vec<String> {
    text.lines()
        .filter(|line| !line.contains('='))
        .filter_map(|line| line.split_whitespace().next())
        .map(|t| t.split('[').next().unwrap_or(t))
        .filter(|t| !PRIMITIVES.contains(t))
        .map(|t| match t.contains('/') {
            true => t.to_string(),
            false => format!("{package}/{t}"),
        })
        .collect()
}

/// The `ros2msg` schema of the message type `name` (`package/Name`): its definition,
/// then every type it depends on, each once, after a line of 80 `=` and `MSG: name`,
/// as ROS 2's bag recorder writes it.
pub fn schema(name: &str) -> String {
    let mut text = definition(name).to_string();
    let mut seen = vec![name.to_string()];
    let mut queue = vec![name.to_string()];
    while let Some(current) = queue.pop() {
        let package = current.split('/').next().unwrap_or("");
        for dep in field_types(package, definition(&current)) {
            if seen.contains(&dep) {
                continue;
            }
            text.push_str(&"=".repeat(80));
            text.push_str(&format!("\nMSG: {dep}\n{}", definition(&dep)));
            seen.push(dep.clone());
            queue.push(dep);
        }
    }
    text
}

/// The type's name as a bag's schema names it: `package/msg/Name`.
pub fn schema_name(name: &str) -> String {
    match name.split_once('/') {
        Some((package, message)) => format!("{package}/msg/{message}"),
        None => name.to_string(),
    }
}
