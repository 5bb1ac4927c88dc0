//! The chain's bodies and joints in rapier: mass properties, joint frames for the full
//! and the lumped formulation, and the conversions between rapier's glam `f32` types
//! and the nalgebra `f64` types of the rest of the simulation (the one place they meet).

use nalgebra::UnitQuaternion;
use rapier3d::glamx::{Mat3 as GMat3, Quat as GQuat, Vec3 as GVec3};
use rapier3d::prelude::{
    MassProperties, MultibodyJointHandle, PhysicsWorld, Pose, RigidBody, RigidBodyBuilder,
    RigidBodyHandle, SphericalJointBuilder,
};

use super::dynamics::{DynamicsError, M3, V3};
use super::model::ChainModel;

// rapier works in glam's f32 types; these four are the only conversions between them
// and the nalgebra f64 types the rest of the simulation uses.

/// A vector for rapier.
pub(super) fn to_glam(v: &V3) -> GVec3 {
    GVec3::new(v.x as f32, v.y as f32, v.z as f32)
}

/// A vector from rapier.
pub(super) fn from_glam(v: GVec3) -> V3 {
    V3::new(v.x as f64, v.y as f64, v.z as f64)
}

/// A rotation matrix for rapier.
pub(super) fn to_glam_rotation(r: &M3) -> GQuat {
    // Via nalgebra's robust matrix-to-quaternion conversion, then to glam.
    let q = UnitQuaternion::from_matrix(r);
    GQuat::from_xyzw(q.i as f32, q.j as f32, q.k as f32, q.w as f32).normalize()
}

/// A rotation matrix from rapier.
pub(super) fn from_glam_rotation(q: &GQuat) -> M3 {
    let m = GMat3::from_quat(*q);
    M3::from_columns(&[
        from_glam(m.x_axis),
        from_glam(m.y_axis),
        from_glam(m.z_axis),
    ])
}

/// The handles of a chain's bodies in the physics world.
pub(super) struct ChainBodies {
    /// Unit bodies (full formulation only; empty in the lumped one).
    pub units: Vec<RigidBodyHandle>,
    /// Link bodies, head end first.
    pub links: Vec<RigidBodyHandle>,
    /// The spherical joints.
    pub joints: Vec<MultibodyJointHandle>,
    /// Each link's centre of mass along its axis from its middle (m; lumped only).
    pub link_com: Vec<f64>,
}

/// A dynamic body at `pos` turned by `rot` with mass properties `mprops`.
pub(super) fn free_body(pos: &V3, rot: GQuat, mprops: MassProperties) -> RigidBody {
    RigidBodyBuilder::dynamic()
        .translation(to_glam(pos))
        .rotation(rot.to_scaled_axis())
        .additional_mass_properties(mprops)
        .can_sleep(false)
        .build()
}

/// Link `k`'s body, at the middle of unit centres `k` and `k + 1`, turned by
/// `link_rot[k]`.
fn link_body(
    world: &mut PhysicsWorld,
    p: &[V3],
    link_rot: &[M3],
    k: usize,
    mass: MassProperties,
) -> RigidBodyHandle {
    let mid = 0.5 * (p[k] + p[k + 1]);
    world
        .bodies
        .insert(free_body(&mid, to_glam_rotation(&link_rot[k]), mass))
}

/// One end of a joint: the body, where the joint sits on the body's axis (m), and how
/// the joint's frame is turned from the body's.
type JointEnd = (RigidBodyHandle, f32, GQuat);

/// Joins two bodies by a spherical joint between the frames of `first` and `second`;
/// `index` names the joint if rapier refuses it.
fn join(
    world: &mut PhysicsWorld,
    (a, xa, ra): JointEnd,
    (b, xb, rb): JointEnd,
    index: usize,
) -> Result<MultibodyJointHandle, DynamicsError> {
    let joint = SphericalJointBuilder::new()
        .local_frame1(Pose::from_parts(GVec3::new(xa, 0.0, 0.0), ra))
        .local_frame2(Pose::from_parts(GVec3::new(xb, 0.0, 0.0), rb));
    world
        .multibody_joints
        .insert(a, b, joint, true)
        .ok_or(DynamicsError::Joint(index))
}

/// The full formulation's bodies: units and links as bodies of their own, joined by
/// spherical joints at the unit centres. Returns units, links and joints.
pub(super) fn build_full(
    world: &mut PhysicsWorld,
    model: &ChainModel,
    p: &[V3],
    r_unit: &M3,
    link_rot: &[M3],
) -> Result<ChainBodies, DynamicsError> {
    let n = p.len();
    let l = model.link_length();
    let half = (0.5 * l) as f32;
    let ui = model.unit.inertia;
    let (mut units, mut links, mut joints) = (Vec::new(), Vec::with_capacity(n - 1), Vec::new());
    let unit_mass = MassProperties::new(
        GVec3::ZERO,
        model.unit.mass as f32,
        GVec3::new(ui[0] as f32, ui[1] as f32, ui[2] as f32),
    );
    let li = model.link.inertia(l);
    let link_mass = MassProperties::new(
        GVec3::ZERO,
        model.link.mass as f32,
        GVec3::new(li[0] as f32, li[1] as f32, li[2] as f32),
    );
    for q in p {
        units.push(
            world
                .bodies
                .insert(free_body(q, to_glam_rotation(r_unit), unit_mass)),
        );
    }
    for k in 0..n - 1 {
        links.push(link_body(world, p, link_rot, k, link_mass));
    }
    // The joints' reference frames are chosen so that zero joint coordinates
    // are the start configuration (a multibody places its children from its
    // joint coordinates, not from the bodies' initial poses).
    for k in 0..n - 1 {
        let unit_to_link = to_glam_rotation(&(r_unit.transpose() * link_rot[k]));
        let front = (units[k], 0.0, unit_to_link);
        joints.push(join(
            world,
            front,
            (links[k], half, GQuat::IDENTITY),
            2 * k,
        )?);
        let link_to_unit = to_glam_rotation(&(link_rot[k].transpose() * r_unit));
        let back = (links[k], -half, link_to_unit);
        joints.push(join(
            world,
            back,
            (units[k + 1], 0.0, GQuat::IDENTITY),
            2 * k + 1,
        )?);
    }
    Ok(ChainBodies {
        link_com: vec![0.0; links.len()],
        units,
        links,
        joints,
    })
}

/// The lumped formulation's bodies: links carrying the units' masses, joined at the
/// unit centres. Returns links, joints and each link's centre of mass on its axis.
pub(super) fn build_lumped(
    world: &mut PhysicsWorld,
    model: &ChainModel,
    p: &[V3],
    link_rot: &[M3],
) -> Result<ChainBodies, DynamicsError> {
    let n = p.len();
    let half = (0.5 * model.link_length()) as f32;
    let (mut links, mut joints, mut link_com) =
        (Vec::with_capacity(n - 1), Vec::new(), vec![0.0; n - 1]);
    for (k, com) in link_com.iter_mut().enumerate() {
        let (mp, xc) = lumped_mass(model, k == 0);
        *com = xc;
        links.push(link_body(world, p, link_rot, k, mp));
    }
    for k in 1..n - 1 {
        // Link k-1's back end is link k's front end (unit k's centre).
        let turn = to_glam_rotation(&(link_rot[k - 1].transpose() * link_rot[k]));
        let back = (links[k - 1], -half, turn);
        joints.push(join(world, back, (links[k], half, GQuat::IDENTITY), k)?);
    }
    Ok(ChainBodies {
        units: Vec::new(),
        links,
        joints,
        link_com,
    })
}

/// Mass properties of link `k`'s body in the lumped formulation: the tube, the unit at
/// its back end and, for the first link, the head at its front end (all on the axis).
fn lumped_mass(model: &ChainModel, first: bool) -> (MassProperties, f64) {
    let l = model.link_length();
    let (mu, ml) = (model.unit.mass, model.link.mass);
    let mut parts = vec![(ml, 0.0), (mu, -0.5 * l)];
    if first {
        parts.push((mu, 0.5 * l));
    }
    let m: f64 = parts.iter().map(|p| p.0).sum();
    let xc = parts.iter().map(|p| p.0 * p.1).sum::<f64>() / m;
    let across = ml * l * l / 12.0 + parts.iter().map(|p| p.0 * (p.1 - xc).powi(2)).sum::<f64>();
    let axial = model.link.min_axial_inertia;
    let mp = MassProperties::new(
        GVec3::new(xc as f32, 0.0, 0.0),
        m as f32,
        GVec3::new(axial as f32, across as f32, across as f32),
    );
    (mp, xc)
}
