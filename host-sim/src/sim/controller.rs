//! The chain's control stack (paper Fig. 3):
//!
//! 1. the head's position MPC ([`super::mpc::HeadMpc`]) gives the head's acceleration;
//! 2. N - 1 link angular controllers (the core's geometric SO(3) controller,
//!    [`aerial_chain_core::control::AttitudeController`]) track the planned link pitch and yaw
//!    and give each link's angular acceleration;
//! 3. the mixer turns these into one force per unit: the desired accelerations of all
//!    unit centres follow from the head's and the links' by the chain's kinematics,
//!    and the forces that produce them from the chain's inverse dynamics (units as
//!    point masses at the joints, links as uniform rods); the forces along the links
//!    that do not move anything (one per link) are chosen to minimise the sum of
//!    squared unit forces. Each force becomes a thrust and a desired attitude (roll
//!    and pitch from its direction, yaw held at the head's planned yaw), with the tilt
//!    limited;
//! 4. each unit's own low-level attitude controller (the same core controller) turns
//!    its desired attitude into body moments.
//!
//! The link controller works in the link's twist-free frame `Rz(psi) Ry(theta)`
//! ([`aerial_chain_core::control::link_attitude`]), built from the measured unit positions; a
//! link cannot be twisted by forces at its ends, so its x gains and x inertia are
//! zero and the output is the angular acceleration across the link.

use aerial_chain_core::control::{
    desired_attitude, euler_zyx, link_attitude, AttitudeController, AttitudeGains,
    AttitudeSetpoint, AttitudeState, Mat3, Vec3,
};
use nalgebra::{DMatrix, DVector};

use super::dynamics::{BodyState, UnitCommand, V3};
use super::model::ChainModel;
use super::mpc::{HeadMpc, MpcConfig, MpcError, MpcRef};
use super::{all_non_negative, all_positive, SettingsError};
use crate::trajectory::reference::{RefPoint, Reference};

/// Tuning of the control stack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerConfig {
    /// The head MPC.
    pub mpc: MpcConfig,
    /// Time between MPC solves (s); the other loops run at every step.
    pub mpc_period: f64,
    /// Closed-loop natural frequency of each link's angle (rad/s).
    pub link_bandwidth: f64,
    /// Damping ratio of each link's angle.
    pub link_damping: f64,
    /// Largest angular acceleration a link controller asks for (rad/s^2).
    pub link_max_angular_accel: f64,
    /// Closed-loop natural frequency of each unit's roll, pitch and yaw (rad/s).
    pub unit_bandwidth: V3,
    /// Damping ratio of each unit's attitude.
    pub unit_damping: f64,
    /// Largest tilt of any unit's thrust from vertical (rad).
    pub tilt_max: f64,
    /// Gain of the head's disturbance observer (1/s; 0 disables it): the difference
    /// between the measured and the commanded head acceleration, low-passed, is
    /// subtracted from the command, which gives the MPC offset-free tracking under
    /// steady forces (a wind, a mass mismatch).
    pub disturbance_gain: f64,
}

impl Default for ControllerConfig {
    fn default() -> Self {
        Self {
            mpc: MpcConfig::default(),
            mpc_period: 0.02,
            link_bandwidth: 3.0,
            link_damping: 1.0,
            link_max_angular_accel: 8.0,
            unit_bandwidth: V3::new(14.0, 14.0, 6.0),
            unit_damping: 0.9,
            tilt_max: 35f64.to_radians(),
            disturbance_gain: 5.0,
        }
    }
}

impl ControllerConfig {
    /// Checks the numbers.
    pub fn validate(&self) -> Result<(), SettingsError> {
        self.mpc.validate()?;
        let link = [
            self.link_bandwidth,
            self.link_damping,
            self.link_max_angular_accel,
        ];
        SettingsError::check(
            all_positive(&[self.mpc_period]) && all_positive(&link),
            "controller periods, link bandwidth, damping and acceleration limit must be positive",
        )?;
        SettingsError::check(
            all_positive(self.unit_bandwidth.as_slice()) && all_positive(&[self.unit_damping]),
            "unit attitude bandwidths and damping must be positive",
        )?;
        SettingsError::check(
            self.tilt_max > 0.0 && self.tilt_max < 1.4,
            "tilt limit must lie in (0, 80) degrees",
        )?;
        SettingsError::check(
            all_non_negative(&[self.disturbance_gain]),
            "disturbance observer gain must be non-negative",
        )
    }
}

/// What the controller decided at one step, for the log.
#[derive(Clone, Debug, PartialEq)]
pub struct ControlOutput {
    /// One command per unit.
    pub commands: Vec<UnitCommand>,
    /// The head acceleration asked for (MPC, minus the disturbance estimate) (m/s^2).
    pub head_accel: V3,
    /// The force asked of each unit (world, N), after the tilt limit.
    pub forces: Vec<V3>,
    /// Each unit's commanded `[roll, pitch, yaw]` (rad).
    pub attitude_cmd: Vec<V3>,
    /// Each link's measured `(pitch, yaw)` (rad).
    pub link_angles: Vec<(f64, f64)>,
    /// Whether the last MPC solve succeeded (false: a fallback PD law was used).
    pub mpc_ok: bool,
}

/// Measured state of link `k` from its two unit centres.
#[derive(Clone, Copy, Debug, PartialEq)]
struct LinkMeasure {
    d: V3,
    omega: V3,
    pitch: f64,
    yaw: f64,
    pitch_rate: f64,
    yaw_rate: f64,
}

fn measure_link(front: &BodyState, back: &BodyState) -> LinkMeasure {
    let diff = front.p - back.p;
    let len = diff.norm();
    let d = if len > 1e-9 && len.is_finite() {
        diff / len
    } else {
        V3::x()
    };
    // The rate of the direction: relative velocity across the link, over its length.
    let dv = front.v - back.v;
    let ddot = if len > 1e-9 {
        (dv - d * d.dot(&dv)) / len
    } else {
        V3::zeros()
    };
    let omega = d.cross(&ddot);
    // docs/model.md's angles of d (as aerial_chain_core::control::direction_angles, in f64).
    let pitch = (-d.z).clamp(-1.0, 1.0).asin();
    let yaw = if d.x.abs() + d.y.abs() > 1e-12 {
        d.y.atan2(d.x)
    } else {
        0.0
    };
    let (sp, cp) = pitch.sin_cos();
    let (sy, cy) = yaw.sin_cos();
    let e_theta = V3::new(-cy * sp, -sy * sp, -cp);
    let e_psi = V3::new(-sy * cp, cy * cp, 0.0);
    let pitch_rate = ddot.dot(&e_theta);
    let yaw_rate = ddot.dot(&e_psi) / (cp * cp).max(1e-2);
    LinkMeasure {
        d,
        omega,
        pitch,
        yaw,
        pitch_rate,
        yaw_rate,
    }
}

/// Body rate of the twist-free frame `Rz(psi) Ry(theta)` and its derivative.
fn twist_free_rates(
    pitch: f64,
    pitch_rate: f64,
    yaw_rate: f64,
    pitch_acc: f64,
    yaw_acc: f64,
) -> (V3, V3) {
    let (s, c) = pitch.sin_cos();
    let w = V3::new(-yaw_rate * s, pitch_rate, yaw_rate * c);
    let dw = V3::new(
        -yaw_acc * s - yaw_rate * pitch_rate * c,
        pitch_acc,
        yaw_acc * c - yaw_rate * pitch_rate * s,
    );
    (w, dw)
}

/// The control stack of one chain.
pub struct ChainController {
    cfg: ControllerConfig,
    model: ChainModel,
    mpc: HeadMpc,
    unit_ctl: AttitudeController,
    link_ctl: AttitudeController,
    mpc_accel: V3,
    last_head_accel: V3,
    next_mpc: f64,
    mpc_ok: bool,
    mpc_failures: usize,
    mpc_solves: usize,
    disturbance: V3,
    last_head_v: Option<(f64, V3)>,
}

impl ChainController {
    /// The stack for `model` tuned by `cfg`.
    pub fn new(model: ChainModel, cfg: ControllerConfig) -> Result<Self, MpcError> {
        cfg.validate().map_err(MpcError::Config)?;
        model.validate().map_err(MpcError::Config)?;
        let mpc = HeadMpc::new(cfg.mpc)?;
        let ui = model.unit.inertia;
        let jd = Vec3::new(ui[0] as f32, ui[1] as f32, ui[2] as f32);
        let w = cfg.unit_bandwidth;
        let unit_gains = AttitudeGains::from_bandwidth(
            jd,
            Vec3::new(w[0] as f32, w[1] as f32, w[2] as f32),
            cfg.unit_damping as f32,
        );
        let mm = model.unit.max_moment;
        let unit_ctl = AttitudeController::new(
            unit_gains,
            Mat3::from_diagonal(&jd),
            Vec3::new(mm[0] as f32, mm[1] as f32, mm[2] as f32),
        );
        // Links: unit "inertia" across the link, none about it, so the controller's
        // moment is the angular acceleration asked for.
        let lj = Vec3::new(0.0, 1.0, 1.0);
        let wl = cfg.link_bandwidth as f32;
        let link_gains =
            AttitudeGains::from_bandwidth(lj, Vec3::new(0.0, wl, wl), cfg.link_damping as f32);
        let amax = cfg.link_max_angular_accel as f32;
        let link_ctl = AttitudeController::new(
            link_gains,
            Mat3::from_diagonal(&lj),
            Vec3::new(0.0, amax, amax),
        );
        Ok(Self {
            cfg,
            model,
            mpc,
            unit_ctl,
            link_ctl,
            mpc_accel: V3::zeros(),
            last_head_accel: V3::zeros(),
            next_mpc: f64::NEG_INFINITY,
            mpc_ok: true,
            mpc_failures: 0,
            mpc_solves: 0,
            disturbance: V3::zeros(),
            last_head_v: None,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &ControllerConfig {
        &self.cfg
    }

    /// How many MPC solves ran and how many failed (fallback used).
    pub fn mpc_counts(&self) -> (usize, usize) {
        (self.mpc_solves, self.mpc_failures)
    }

    /// The head's disturbance estimate (m/s^2).
    pub fn disturbance(&self) -> V3 {
        self.disturbance
    }

    /// One control step at time `t` for the measured unit states `units`.
    pub fn step(&mut self, t: f64, units: &[BodyState], reference: &Reference) -> ControlOutput {
        let r = reference.sample(t);
        let head = units[0];
        self.observe_disturbance(t, &head);
        self.last_head_v = Some((t, head.v));
        // 1. Head MPC.
        self.update_head_mpc(t, &head, &r, reference);
        let head_accel = self.mpc_accel - self.disturbance;
        self.last_head_accel = head_accel;
        // 2. Link controllers -> angular accelerations (world), and measured links.
        let (meas, alpha) = self.control_links(units, &r);
        // 3. Mixer: unit accelerations, then inverse dynamics.
        let l = self.model.link_length();
        let mut acc = Vec::with_capacity(units.len());
        acc.push(head_accel);
        for (k, m) in meas.iter().enumerate() {
            let ddd = alpha[k].cross(&m.d) + m.omega.cross(&m.omega.cross(&m.d));
            let next = acc[k] - l * ddd;
            acc.push(next);
        }
        let forces = self.mix(&acc, &meas, &alpha);
        // 4. Each unit: tilt limit, thrust, attitude.
        let (commands, limited, attitude_cmd) = self.command_units(units, &forces, r.head_yaw);
        ControlOutput {
            commands,
            head_accel,
            forces: limited,
            attitude_cmd,
            link_angles: meas.iter().map(|m| (m.pitch, m.yaw)).collect(),
            mpc_ok: self.mpc_ok,
        }
    }

    /// Disturbance observer on the head: measured acceleration vs commanded.
    fn observe_disturbance(&mut self, t: f64, head: &BodyState) {
        if let Some((t_prev, v_prev)) = self.last_head_v {
            let dt = t - t_prev;
            if dt > 0.0 {
                let a_meas = (head.v - v_prev) / dt;
                let err = a_meas - self.last_head_accel;
                let k = (self.cfg.disturbance_gain * dt).min(1.0);
                self.disturbance += k * (err - self.disturbance);
                // Bound it: the observer must not wind up while saturated.
                let lim = self.cfg.mpc.a_xy_max;
                self.disturbance = self.disturbance.map(|x| {
                    if x.is_finite() {
                        x.clamp(-lim, lim)
                    } else {
                        0.0
                    }
                });
            }
        }
    }

    /// Re-solves the head MPC when its period is up; a saturated PD law on the
    /// reference stands in when the solver fails.
    fn update_head_mpc(&mut self, t: f64, head: &BodyState, r: &RefPoint, reference: &Reference) {
        if t >= self.next_mpc {
            self.next_mpc = t + self.cfg.mpc_period;
            let h = self.cfg.mpc.step;
            let refs: Vec<MpcRef> = (1..=self.cfg.mpc.horizon)
                .map(|k| {
                    let s = reference.sample(t + k as f64 * h);
                    // a_{k-1} is held over [t + (k-1) h, t + k h]: use the mid-step reference.
                    let a_mid = reference.sample(t + (k as f64 - 0.5) * h).a;
                    MpcRef {
                        p: s.p,
                        v: s.v,
                        a: a_mid,
                    }
                })
                .collect();
            self.mpc_solves += 1;
            match self.mpc.solve(head.p, head.v, &refs, self.mpc_accel) {
                Ok(sol) => {
                    self.mpc_accel = sol.accel;
                    self.mpc_ok = true;
                }
                Err(_) => {
                    // Fallback: a saturated PD law on the reference.
                    self.mpc_failures += 1;
                    self.mpc_ok = false;
                    let a = r.a + 4.0 * (r.p - head.p) + 4.0 * (r.v - head.v);
                    let lim = self.cfg.mpc.a_xy_max;
                    self.mpc_accel = a.map(|x| {
                        if x.is_finite() {
                            x.clamp(-lim, lim)
                        } else {
                            0.0
                        }
                    });
                }
            }
        }
    }

    /// The link controllers: each link's measured angles and the angular acceleration
    /// (world) its controller asks for, across the link.
    fn control_links(&self, units: &[BodyState], r: &RefPoint) -> (Vec<LinkMeasure>, Vec<V3>) {
        let n = units.len();
        let mut meas = Vec::with_capacity(n - 1);
        let mut alpha = Vec::with_capacity(n - 1);
        for k in 0..n - 1 {
            let m = measure_link(&units[k], &units[k + 1]);
            let lr = r.links.get(k).copied().unwrap_or_default();
            let (w_meas, _) = twist_free_rates(m.pitch, m.pitch_rate, m.yaw_rate, 0.0, 0.0);
            let (w_d, dw_d) = twist_free_rates(
                lr.pitch,
                lr.pitch_rate,
                lr.yaw_rate,
                lr.pitch_acc,
                lr.yaw_acc,
            );
            let r_meas = link_attitude(m.pitch as f32, m.yaw as f32);
            let r_d = link_attitude(lr.pitch as f32, lr.yaw as f32);
            let out = self.link_ctl.control(
                &AttitudeState {
                    r: r_meas,
                    w: w_meas.cast::<f32>(),
                },
                &AttitudeSetpoint {
                    r_d,
                    w_d: w_d.cast::<f32>(),
                    dw_d: dw_d.cast::<f32>(),
                },
            );
            let a_world = r_meas.cast::<f64>() * out.moment.cast::<f64>();
            // Only the part across the link acts.
            alpha.push(a_world - m.d * m.d.dot(&a_world));
            meas.push(m);
        }
        (meas, alpha)
    }

    /// Each unit's force within the tilt limit, its thrust and its attitude loop's
    /// moment; returns the commands, the limited forces and the attitude commands.
    fn command_units(
        &mut self,
        units: &[BodyState],
        forces: &[V3],
        head_yaw: f64,
    ) -> (Vec<UnitCommand>, Vec<V3>, Vec<V3>) {
        let n = units.len();
        let g = self.model.gravity;
        let unit = self.model.unit;
        let tan = self.cfg.tilt_max.tan();
        let mut commands = Vec::with_capacity(n);
        let mut limited = Vec::with_capacity(n);
        let mut attitude_cmd = Vec::with_capacity(n);
        for (i, f) in forces.iter().enumerate() {
            let mut f = if f.iter().all(|x| x.is_finite()) {
                *f
            } else {
                V3::new(0.0, 0.0, unit.mass * g)
            };
            f.z = f.z.max(unit.thrust_min);
            let horiz = (f.x * f.x + f.y * f.y).sqrt();
            let hmax = f.z * tan;
            if horiz > hmax {
                f.x *= hmax / horiz;
                f.y *= hmax / horiz;
            }
            let s = &units[i];
            let b3 = s.r.column(2).into_owned();
            let thrust = f.dot(&b3).clamp(unit.thrust_min, unit.thrust_max);
            let r_d = desired_attitude(&f.cast::<f32>(), head_yaw as f32);
            let out = self.unit_ctl.control(
                &AttitudeState {
                    r: s.r.cast::<f32>(),
                    w: s.w_body().cast::<f32>(),
                },
                &AttitudeSetpoint::hold(r_d),
            );
            let rpy = euler_zyx(&r_d);
            attitude_cmd.push(V3::new(rpy[0] as f64, rpy[1] as f64, rpy[2] as f64));
            commands.push(UnitCommand {
                thrust,
                moment: out.moment.cast::<f64>(),
            });
            limited.push(f);
        }
        (commands, limited, attitude_cmd)
    }

    /// Inverse dynamics: the unit forces that give the unit accelerations `acc`
    /// (consistent with the links' angular accelerations `alpha`), with the internal
    /// force of each link chosen to minimise the sum of squared unit forces.
    fn mix(&self, acc: &[V3], meas: &[LinkMeasure], alpha: &[V3]) -> Vec<V3> {
        let n = acc.len();
        let g = V3::new(0.0, 0.0, self.model.gravity);
        let mu = self.model.unit.mass;
        let ml = self.model.link.mass;
        let l = self.model.link_length();
        let i_rod = ml * l * l / 12.0;
        let mut f0: Vec<V3> = acc.iter().map(|a| mu * (a + g)).collect();
        for k in 0..n - 1 {
            let d = meas[k].d;
            let sum = ml * (0.5 * (acc[k] + acc[k + 1]) + g);
            let diff = (2.0 * i_rod / l) * alpha[k].cross(&d);
            f0[k] += 0.5 * (sum + diff); // the rod's front end pushes on unit k
            f0[k + 1] += 0.5 * (sum - diff);
        }
        // Internal forces tau_k along each link: f_k += tau_k d_k / 2, f_{k+1} -= tau_k d_k / 2.
        let m = n - 1;
        let mut btb = DMatrix::<f64>::zeros(m, m);
        let mut rhs = DVector::<f64>::zeros(m);
        for k in 0..m {
            let d = meas[k].d;
            btb[(k, k)] = 0.5 + 1e-6;
            if k + 1 < m {
                let c = -0.25 * d.dot(&meas[k + 1].d);
                btb[(k, k + 1)] = c;
                btb[(k + 1, k)] = c;
            }
            rhs[k] = -0.5 * (d.dot(&f0[k]) - d.dot(&f0[k + 1]));
        }
        let tau = btb
            .cholesky()
            .map(|c| c.solve(&rhs))
            .unwrap_or_else(|| DVector::zeros(m));
        let mut f = f0;
        for k in 0..m {
            let d = meas[k].d;
            f[k] += 0.5 * tau[k] * d;
            f[k + 1] -= 0.5 * tau[k] * d;
        }
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::dynamics::M3;
    use aerial_chain_core::ChainParams;

    fn state(p: V3) -> BodyState {
        BodyState {
            p,
            v: V3::zeros(),
            r: M3::identity(),
            w: V3::zeros(),
        }
    }

    #[test]
    fn hover_forces_carry_each_unit_and_half_its_links() {
        let model = ChainModel::new(ChainParams::new(4));
        let c = ChainController::new(model, ControllerConfig::default()).unwrap();
        let units: Vec<BodyState> = (0..4)
            .map(|i| state(V3::new(-0.5 * i as f64, 0.0, 2.0)))
            .collect();
        let meas: Vec<LinkMeasure> = (0..3)
            .map(|k| measure_link(&units[k], &units[k + 1]))
            .collect();
        let f = c.mix(&[V3::zeros(); 4], &meas, &[V3::zeros(); 3]);
        let g = model.gravity;
        for (i, fi) in f.iter().enumerate() {
            let links = if i == 0 || i == 3 { 1.0 } else { 2.0 };
            assert!(
                (fi - V3::new(0.0, 0.0, (1.0 + 0.05 * links) * g)).norm() < 1e-9,
                "{i}: {fi:?}"
            );
        }
    }

    #[test]
    fn forces_balance_the_chain_momentum() {
        // Whatever the internal forces, the sum of unit forces must equal the total
        // mass times the centre-of-mass acceleration plus weight.
        let model = ChainModel::new(ChainParams::new(3));
        let c = ChainController::new(model, ControllerConfig::default()).unwrap();
        let units = [
            state(V3::zeros()),
            state(V3::new(-0.4, 0.3, 0.0)),
            state(V3::new(-0.4, 0.3, 0.0) + V3::new(-0.3, -0.2, 0.3464)),
        ];
        let meas: Vec<LinkMeasure> = (0..2)
            .map(|k| measure_link(&units[k], &units[k + 1]))
            .collect();
        let acc = [
            V3::new(1.0, 0.5, -0.2),
            V3::new(0.3, 0.2, 0.1),
            V3::new(-0.1, 0.4, 0.3),
        ];
        let alpha: Vec<V3> = (0..2)
            .map(|k| V3::new(0.2, -0.3, 0.5) - meas[k].d * meas[k].d.dot(&V3::new(0.2, -0.3, 0.5)))
            .collect();
        let f = c.mix(&acc, &meas, &alpha);
        let total: V3 = f.iter().sum();
        let g = V3::new(0.0, 0.0, model.gravity);
        let expected: V3 = acc.iter().map(|a| 1.0 * (a + g)).sum::<V3>()
            + (0..2)
                .map(|k| 0.1 * (0.5 * (acc[k] + acc[k + 1]) + g))
                .sum::<V3>();
        assert!((total - expected).norm() < 1e-9);
    }

    #[test]
    fn link_measure_and_twist_free_rates_agree() {
        // A link turning at yaw rate 0.5 and pitch rate -0.2 at pitch 0.3.
        let (pitch, yaw, pr, yr) = (0.3f64, 1.0f64, -0.2, 0.5);
        let dir = |p: f64, y: f64| V3::new(y.cos() * p.cos(), y.sin() * p.cos(), -p.sin());
        let h = 1e-6;
        let ddot =
            (dir(pitch + pr * h, yaw + yr * h) - dir(pitch - pr * h, yaw - yr * h)) / (2.0 * h);
        let front = BodyState {
            p: 0.5 * dir(pitch, yaw),
            v: 0.5 * ddot,
            r: M3::identity(),
            w: V3::zeros(),
        };
        let back = state(V3::zeros());
        let m = measure_link(&front, &back);
        assert!((m.pitch - pitch).abs() < 1e-9 && (m.yaw - yaw).abs() < 1e-9);
        assert!((m.pitch_rate - pr).abs() < 1e-6 && (m.yaw_rate - yr).abs() < 1e-6);
        // The twist-free frame's rate, mapped to the world, moves d like omega does.
        let (w, _) = twist_free_rates(pitch, pr, yr, 0.0, 0.0);
        let rw = super::super::dynamics::link_rotation(pitch, yaw) * w;
        assert!((rw.cross(&m.d) - m.omega.cross(&m.d)).norm() < 1e-6);
    }
}
