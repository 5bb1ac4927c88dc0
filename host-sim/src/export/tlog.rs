//! A motion as a MAVLink 2 telemetry log (`.tlog`): the offboard setpoints a ground
//! station would stream to every unit's autopilot (docs/model.md, "Exports").
//!
//! One sender (system 255, component 191, a ground station) writes heartbeats at 1 Hz
//! and, at every tick, a `SET_POSITION_TARGET_LOCAL_NED` to each unit (position,
//! velocity, acceleration feed-forward, yaw and yaw rate), addressed to system
//! `sysid_base + i - 1`, component 1. Before the motion the start is held for `hold`
//! seconds of setpoints; with `arm`, the switch to offboard and arming follow that
//! hold (PX4 switches to offboard only after setpoints have streamed for a second).
//! From a flight that recorded its commands, `SET_ATTITUDE_TARGET` carries each unit's
//! commanded attitude and thrust over the unit's largest thrust.
//!
//! W is taken as ENU (x east, y north, z up) and every unit's body frame as FLU;
//! MAVLink's local frame is NED and its body frame FRD: `(x, y, z)_NED = (y, x, -z)`,
//! `yaw_NED = pi/2 - psi`. A `.tlog` record is the time in microseconds
//! (big-endian `u64`) followed by one MAVLink packet.

use mavlink::dialects::common::{
    AttitudeTargetTypemask, MavAutopilot, MavCmd, MavFrame, MavMessage, MavModeFlag, MavState,
    MavType, PositionTargetTypemask, COMMAND_LONG_DATA, HEARTBEAT_DATA, SET_ATTITUDE_TARGET_DATA,
    SET_POSITION_TARGET_LOCAL_NED_DATA,
};
use mavlink::MavHeader;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

use super::motion::{Command, Motion, Tick, UnitState};
use super::ExportError;
use crate::collision::verify::wrap;

/// The sender's system id: a ground station's.
pub const SENDER_SYSTEM: u8 = 255;
/// The sender's component id: `MAV_COMP_ID_MISSIONPLANNER`.
pub const SENDER_COMPONENT: u8 = 191;
/// The component every unit's messages go to: its autopilot (`MAV_COMP_ID_AUTOPILOT1`).
pub const TARGET_COMPONENT: u8 = 1;
/// Seconds of setpoints PX4 wants before it switches to offboard.
pub const PX4_MIN_HOLD_S: f64 = 1.0;
/// Longest hold before the motion (s): a pre-roll, not a flight of its own; the bound
/// keeps a log's size that of its motion.
pub const MAX_HOLD_S: f64 = 60.0;
/// PX4's custom main mode OFFBOARD (`px4_custom_mode.h`).
const PX4_OFFBOARD: f32 = 6.0;
/// ArduCopter's GUIDED mode number.
const ARDUCOPTER_GUIDED: f32 = 4.0;

/// The autopilot the mode switch is written for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Autopilot {
    /// PX4: `MAV_CMD_DO_SET_MODE` to OFFBOARD.
    #[default]
    Px4,
    /// ArduPilot (Copter): `MAV_CMD_DO_SET_MODE` to GUIDED.
    ArduPilot,
}

/// How the log is written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TlogOptions {
    /// System id of unit 1; unit i is `sysid_base + i - 1`.
    pub sysid_base: u8,
    /// Seconds of the start's setpoints before the motion.
    pub hold: f64,
    /// Write the switch to offboard and arming after the hold.
    pub arm: bool,
    /// Which autopilot's mode numbers the switch uses.
    pub autopilot: Autopilot,
    /// A unit's largest thrust (N), the 1 of `SET_ATTITUDE_TARGET.thrust`.
    pub thrust_max: f64,
}

impl Default for TlogOptions {
    fn default() -> Self {
        Self {
            sysid_base: 1,
            hold: PX4_MIN_HOLD_S,
            arm: false,
            autopilot: Autopilot::Px4,
            thrust_max: crate::sim::model::UnitModel::default().thrust_max,
        }
    }
}

impl TlogOptions {
    /// Checks the options against a chain of `units` units.
    pub fn check(&self, units: usize) -> Result<(), ExportError> {
        let last = self.sysid_base as usize + units - 1;
        if self.sysid_base == 0 || last >= SENDER_SYSTEM as usize {
            return Err(ExportError::Option(format!(
                "sysid_base = {}: the units' system ids {}..={last} must lie in 1..=254 \
                 (255 is the sender's)",
                self.sysid_base, self.sysid_base
            )));
        }
        if !(self.hold >= 0.0 && self.hold <= MAX_HOLD_S) {
            return Err(ExportError::Option(format!(
                "hold = {} s must be a number of seconds from 0 to {MAX_HOLD_S}",
                self.hold
            )));
        }
        if self.arm && self.hold < PX4_MIN_HOLD_S {
            return Err(ExportError::Option(format!(
                "hold = {} s: arming needs at least {PX4_MIN_HOLD_S} s of setpoints before \
                 the switch to offboard",
                self.hold
            )));
        }
        if !(self.thrust_max.is_finite() && self.thrust_max > 0.0) {
            return Err(ExportError::Option(format!(
                "thrust_max = {} N must be a positive number",
                self.thrust_max
            )));
        }
        Ok(())
    }
}

/// What a log holds: messages per kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TlogSummary {
    /// `HEARTBEAT`s.
    pub heartbeats: usize,
    /// `SET_POSITION_TARGET_LOCAL_NED`s.
    pub position_targets: usize,
    /// `SET_ATTITUDE_TARGET`s.
    pub attitude_targets: usize,
    /// `COMMAND_LONG`s (mode switches and arming).
    pub commands: usize,
}

/// A vector of W (ENU) in NED.
pub fn ned(v: &Vector3<f64>) -> [f32; 3] {
    [v.y as f32, v.x as f32, -v.z as f32]
}

/// The unit's heading in W: the yaw of its body x axis.
fn yaw_enu(q: &UnitQuaternion<f64>) -> f64 {
    let x = q * Vector3::x();
    x.y.atan2(x.x)
}

/// An attitude (FLU body into ENU) as MAVLink's (FRD body into NED), `[w, x, y, z]`.
pub fn attitude_ned(q: &UnitQuaternion<f64>) -> [f32; 4] {
    let enu_to_ned = Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0);
    let frd_to_flu = Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0);
    let r = enu_to_ned * q.to_rotation_matrix().into_inner() * frd_to_flu;
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    [q.w as f32, q.i as f32, q.j as f32, q.k as f32]
}

/// A log being written: records in time order and the packet sequence.
struct Log {
    bytes: Vec<u8>,
    sequence: u8,
    summary: TlogSummary,
}

impl Log {
    /// Appends `message` at `tau` seconds of the log.
    fn push(&mut self, tau: f64, message: &MavMessage) -> Result<(), ExportError> {
        let header = MavHeader {
            system_id: SENDER_SYSTEM.into(),
            component_id: SENDER_COMPONENT,
            sequence: self.sequence,
        };
        self.sequence = self.sequence.wrapping_add(1);
        let micros = (tau * 1e6).round() as u64;
        self.bytes.extend_from_slice(&micros.to_be_bytes());
        mavlink::write_v2_msg(&mut self.bytes, header, message)
            .map_err(|e| ExportError::Encode(format!("MAVLink: {e}")))?;
        let s = &mut self.summary;
        match message {
            MavMessage::HEARTBEAT(_) => s.heartbeats += 1,
            MavMessage::SET_POSITION_TARGET_LOCAL_NED(_) => s.position_targets += 1,
            MavMessage::SET_ATTITUDE_TARGET(_) => s.attitude_targets += 1,
            MavMessage::COMMAND_LONG(_) => s.commands += 1,
            _ => {}
        }
        Ok(())
    }
}

/// The ground station's heartbeat.
fn heartbeat() -> MavMessage {
    MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        custom_mode: 0,
        mavtype: MavType::MAV_TYPE_GCS,
        autopilot: MavAutopilot::MAV_AUTOPILOT_INVALID,
        base_mode: MavModeFlag::empty(),
        system_status: MavState::MAV_STATE_ACTIVE,
        mavlink_version: 3,
    })
}

/// Milliseconds since the log began, as MAVLink's `time_boot_ms`.
fn millis(tau: f64) -> u32 {
    (tau * 1e3).round().clamp(0.0, u32::MAX as f64) as u32
}

/// Unit `s`'s setpoint for system `target`.
fn position_target(tau: f64, target: u8, s: &UnitState) -> MavMessage {
    let [x, y, z] = ned(&s.p.coords);
    let [vx, vy, vz] = ned(&s.v);
    let [afx, afy, afz] = ned(&s.a);
    MavMessage::SET_POSITION_TARGET_LOCAL_NED(SET_POSITION_TARGET_LOCAL_NED_DATA {
        time_boot_ms: millis(tau),
        x,
        y,
        z,
        vx,
        vy,
        vz,
        afx,
        afy,
        afz,
        yaw: wrap(std::f64::consts::FRAC_PI_2 - yaw_enu(&s.q)) as f32,
        yaw_rate: -s.w.z as f32,
        type_mask: PositionTargetTypemask::empty(),
        target_system: target,
        target_component: TARGET_COMPONENT,
        coordinate_frame: MavFrame::MAV_FRAME_LOCAL_NED,
    })
}

/// A unit's commanded attitude and thrust for system `target`.
fn attitude_target(tau: f64, target: u8, c: &Command, thrust_max: f64) -> MavMessage {
    MavMessage::SET_ATTITUDE_TARGET(SET_ATTITUDE_TARGET_DATA {
        time_boot_ms: millis(tau),
        q: attitude_ned(&c.attitude),
        body_roll_rate: 0.0,
        body_pitch_rate: 0.0,
        body_yaw_rate: 0.0,
        thrust: (c.thrust / thrust_max).clamp(0.0, 1.0) as f32,
        target_system: target,
        target_component: TARGET_COMPONENT,
        type_mask: AttitudeTargetTypemask::ATTITUDE_TARGET_TYPEMASK_BODY_ROLL_RATE_IGNORE
            | AttitudeTargetTypemask::ATTITUDE_TARGET_TYPEMASK_BODY_PITCH_RATE_IGNORE
            | AttitudeTargetTypemask::ATTITUDE_TARGET_TYPEMASK_BODY_YAW_RATE_IGNORE,
    })
}

/// A `COMMAND_LONG` to system `target`.
fn command(target: u8, cmd: MavCmd, param1: f32, param2: f32) -> MavMessage {
    MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        param1,
        param2,
        param3: 0.0,
        param4: 0.0,
        param5: 0.0,
        param6: 0.0,
        param7: 0.0,
        command: cmd,
        target_system: target,
        target_component: TARGET_COMPONENT,
        confirmation: 0,
    })
}

/// The switch to offboard (PX4) or guided (ArduPilot), then arming, for `target`.
fn arm(target: u8, autopilot: Autopilot) -> [MavMessage; 2] {
    let mode = match autopilot {
        Autopilot::Px4 => PX4_OFFBOARD,
        Autopilot::ArduPilot => ARDUCOPTER_GUIDED,
    };
    let custom = MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED.bits() as f32;
    [
        command(target, MavCmd::MAV_CMD_DO_SET_MODE, custom, mode),
        command(target, MavCmd::MAV_CMD_COMPONENT_ARM_DISARM, 1.0, 0.0),
    ]
}

/// The log's ticks: `(tau, tick)`, the start held for `hold` s at the motion's rate,
/// then every tick of the motion `hold` s later.
fn schedule(motion: &Motion, hold: f64) -> Vec<(f64, &Tick)> {
    let first = &motion.ticks[0];
    let held = (0..)
        .map(|k| k as f64 / motion.rate)
        .take_while(|tau| *tau < hold - 1e-9)
        .map(|tau| (tau, first));
    let t0 = first.t;
    held.chain(motion.ticks.iter().map(|t| (hold + t.t - t0, t)))
        .collect()
}

/// The `.tlog` of `motion`: its bytes and what it holds.
pub fn tlog(motion: &Motion, options: &TlogOptions) -> Result<(Vec<u8>, TlogSummary), ExportError> {
    options.check(motion.units())?;
    let mut log = Log {
        bytes: Vec::new(),
        sequence: 0,
        summary: TlogSummary::default(),
    };
    let targets: Vec<u8> = (0..motion.units())
        .map(|i| options.sysid_base + i as u8)
        .collect();
    let mut next_heartbeat = 0.0;
    let mut armed = !options.arm;
    for (tau, tick) in schedule(motion, options.hold) {
        while next_heartbeat <= tau + 1e-9 {
            log.push(next_heartbeat, &heartbeat())?;
            next_heartbeat += 1.0;
        }
        if !armed && tau >= options.hold - 1e-9 {
            for &target in &targets {
                for m in arm(target, options.autopilot) {
                    log.push(tau, &m)?;
                }
            }
            armed = true;
        }
        for (s, &target) in tick.units.iter().zip(&targets) {
            log.push(tau, &position_target(tau, target, s))?;
        }
        for (c, &target) in tick.commands.iter().flatten().zip(&targets) {
            log.push(tau, &attitude_target(tau, target, c, options.thrust_max))?;
        }
    }
    Ok((log.bytes, log.summary))
}
