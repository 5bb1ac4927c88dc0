//! The head's position controller: a linear MPC over a prediction horizon, solved as a
//! second-order-cone QP by clarabel at every controller update.
//!
//! Model: the head as a double integrator `p'' = a` sampled at `h` over `H` steps; the
//! decision is the acceleration sequence `a_0 .. a_{H-1}` (condensed form, `3H`
//! variables, axis-major). Cost over the horizon:
//! ```text
//! sum_{k=1..H} q_p |p_k - p_ref,k|^2 + q_v |v_k - v_ref,k|^2      (x q_terminal at k = H)
//!   + sum_{k=0..H-1} r_a |a_k - a_ref,k|^2 + r_j |a_k - a_{k-1}|^2   (a_{-1}: last command)
//! ```
//! Constraints on every `a_k`:
//! - acceleration box: `|a_x|, |a_y| <= a_xy_max`, `a_z_min <= a_z <= a_z_max`;
//! - tilt: `||(a_x, a_y)|| <= tan(tilt_max) (g + a_z)` (a second-order cone): the head
//!   can only push sideways by tilting its thrust.
//!
//! The Hessian and the constraint matrix do not change between solves, so one clarabel
//! solver is built once and only its linear term `q` is updated.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSolver, IPSolver, NonnegativeConeT, SecondOrderConeT, SolverStatus,
    SupportedConeT,
};

use super::dynamics::V3;
use super::model::GRAVITY;
use super::{all_non_negative, all_positive, SettingsError};

/// Tuning and limits of the head MPC.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MpcConfig {
    /// Number of prediction steps `H`.
    pub horizon: usize,
    /// Prediction step `h` (s).
    pub step: f64,
    /// Weight on position error (1/s^4 relative to `r_a`).
    pub q_pos: f64,
    /// Weight on velocity error.
    pub q_vel: f64,
    /// Extra factor on the last step's position and velocity weights.
    pub q_terminal: f64,
    /// Weight on the deviation from the reference acceleration.
    pub r_acc: f64,
    /// Weight on the change of acceleration between steps.
    pub r_jerk: f64,
    /// Largest horizontal acceleration per axis (m/s^2).
    pub a_xy_max: f64,
    /// Smallest vertical acceleration (m/s^2, negative: downwards).
    pub a_z_min: f64,
    /// Largest vertical acceleration (m/s^2).
    pub a_z_max: f64,
    /// Largest tilt of the head's acceleration from vertical (rad).
    pub tilt_max: f64,
}

impl Default for MpcConfig {
    fn default() -> Self {
        Self {
            horizon: 15,
            step: 0.1,
            q_pos: 40.0,
            q_vel: 8.0,
            q_terminal: 4.0,
            r_acc: 1.0,
            r_jerk: 2.0,
            a_xy_max: 3.0,
            a_z_min: -3.0,
            a_z_max: 3.0,
            tilt_max: 20f64.to_radians(),
        }
    }
}

impl MpcConfig {
    /// Checks the numbers.
    pub fn validate(&self) -> Result<(), SettingsError> {
        SettingsError::check(
            (1..=200).contains(&self.horizon) && all_positive(&[self.step]),
            "MPC horizon must be 1..=200 steps of positive length",
        )?;
        let weights = [self.q_pos, self.q_vel, self.q_terminal, self.r_jerk];
        SettingsError::check(
            all_non_negative(&weights) && all_positive(&[self.r_acc]),
            "MPC weights must be non-negative (r_acc positive)",
        )?;
        SettingsError::check(
            all_positive(&[self.a_xy_max, self.a_z_max, -self.a_z_min]),
            "MPC acceleration limits must bracket zero",
        )?;
        SettingsError::check(
            self.a_z_min > -GRAVITY,
            "MPC a_z_min must be above -g (the rotors cannot pull down)",
        )?;
        SettingsError::check(
            self.tilt_max > 0.0 && self.tilt_max < 1.4,
            "MPC tilt limit must lie in (0, 80) degrees",
        )
    }
}

/// What the reference asks for at one prediction step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MpcRef {
    /// Position (m).
    pub p: V3,
    /// Velocity (m/s).
    pub v: V3,
    /// Acceleration (m/s^2).
    pub a: V3,
}

/// One MPC solution.
#[derive(Clone, Debug, PartialEq)]
pub struct MpcSolution {
    /// The acceleration to apply now (m/s^2).
    pub accel: V3,
    /// The whole planned acceleration sequence.
    pub plan: Vec<V3>,
    /// Interior-point iterations.
    pub iterations: u32,
}

/// Why a solve gave no usable answer.
#[derive(Debug, thiserror::Error)]
pub enum MpcError {
    /// The configuration is invalid.
    #[error("MPC configuration: {0}")]
    Config(SettingsError),
    /// Inputs of the wrong length or not finite.
    #[error("MPC input: {0}")]
    Input(String),
    /// clarabel did not solve the QP.
    #[error("MPC solver status {0}")]
    Solver(String),
}

/// The head MPC with its solver.
pub struct HeadMpc {
    cfg: MpcConfig,
    solver: DefaultSolver<f64>,
    /// Position and velocity sensitivities: p_k depends on a_j with `sp[k][j]`.
    sp: Vec<f64>,
    sv: Vec<f64>,
    /// Per-step weights on position and velocity (terminal factor applied).
    wp: Vec<f64>,
    wv: Vec<f64>,
    q: Vec<f64>,
}

impl HeadMpc {
    /// Builds the QP's fixed parts and its solver.
    pub fn new(cfg: MpcConfig) -> Result<Self, MpcError> {
        cfg.validate().map_err(MpcError::Config)?;
        let n = cfg.horizon;
        let h = cfg.step;
        // p_k (k = 1..n) = p0 + k h v0 + sum_{j<k} h^2 (k - j - 1/2) a_j ; row k-1.
        let mut sp = vec![0.0; n * n];
        let mut sv = vec![0.0; n * n];
        for k in 1..=n {
            for j in 0..k {
                sp[(k - 1) * n + j] = h * h * (k as f64 - j as f64 - 0.5);
                sv[(k - 1) * n + j] = h;
            }
        }
        let mut wp = vec![cfg.q_pos; n];
        let mut wv = vec![cfg.q_vel; n];
        wp[n - 1] *= cfg.q_terminal;
        wv[n - 1] *= cfg.q_terminal;
        // Hessian per axis: Sp' Wp Sp + Sv' Wv Sv + r_a I + r_j D'D.
        let mut hess = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let mut s = 0.0;
                for k in 0..n {
                    s += sp[k * n + i] * wp[k] * sp[k * n + j]
                        + sv[k * n + i] * wv[k] * sv[k * n + j];
                }
                hess[i * n + j] = s;
            }
            hess[i * n + i] += cfg.r_acc + 2.0 * cfg.r_jerk;
            if i + 1 < n {
                hess[i * n + i + 1] -= cfg.r_jerk;
                hess[(i + 1) * n + i] -= cfg.r_jerk;
            }
        }
        // The last a_k has only one jerk term (a_{n-1} - a_{n-2}).
        hess[(n - 1) * n + (n - 1)] -= cfg.r_jerk;
        // P = 2 blkdiag(hess, hess, hess), upper triangle, CSC (column by column).
        let nv = 3 * n;
        let mut colptr = Vec::with_capacity(nv + 1);
        let mut rowval = Vec::new();
        let mut nzval = Vec::new();
        colptr.push(0);
        for ax in 0..3 {
            for j in 0..n {
                for i in 0..=j {
                    rowval.push(ax * n + i);
                    nzval.push(2.0 * hess[i * n + j]);
                }
                colptr.push(rowval.len());
            }
        }
        let p = CscMatrix::new(nv, nv, colptr, rowval, nzval);
        // Constraints A x + s = b.
        // Rows 0..6n: boxes (s >= 0): per step k: +ax, -ax, +ay, -ay, +az, -az.
        // Rows 6n..9n: per step, the cone (tan(t)(g + az), ax, ay).
        let (mut ii, mut jj, mut vv) = (Vec::new(), Vec::new(), Vec::new());
        let mut b = vec![0.0; 9 * n];
        let tan = cfg.tilt_max.tan();
        for k in 0..n {
            let (x, y, z) = (k, n + k, 2 * n + k);
            let r = 6 * k;
            for (row, col, val, rhs) in [
                (r, x, 1.0, cfg.a_xy_max),
                (r + 1, x, -1.0, cfg.a_xy_max),
                (r + 2, y, 1.0, cfg.a_xy_max),
                (r + 3, y, -1.0, cfg.a_xy_max),
                (r + 4, z, 1.0, cfg.a_z_max),
                (r + 5, z, -1.0, -cfg.a_z_min),
            ] {
                ii.push(row);
                jj.push(col);
                vv.push(val);
                b[row] = rhs;
            }
            let c = 6 * n + 3 * k;
            // s0 = tan g + tan az  ->  A row: -tan on az, b = tan g.
            ii.push(c);
            jj.push(z);
            vv.push(-tan);
            b[c] = tan * GRAVITY;
            // s1 = ax, s2 = ay -> A rows: -1, b = 0.
            ii.push(c + 1);
            jj.push(x);
            vv.push(-1.0);
            ii.push(c + 2);
            jj.push(y);
            vv.push(-1.0);
        }
        let a = CscMatrix::new_from_triplets(9 * n, nv, ii, jj, vv);
        let mut cones: Vec<SupportedConeT<f64>> = vec![NonnegativeConeT(6 * n)];
        cones.extend((0..n).map(|_| SecondOrderConeT(3)));
        // A controller needs far less than clarabel's default 1e-8 accuracy: 1e-6 and no
        // iterative refinement halve the solve time (the KKT factorisation dominates).
        let settings = DefaultSettings {
            verbose: false,
            presolve_enable: false,
            max_iter: 50,
            tol_gap_abs: 1e-6,
            tol_gap_rel: 1e-6,
            tol_feas: 1e-6,
            iterative_refinement_enable: false,
            ..Default::default()
        };
        let q = vec![0.0; nv];
        let solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings)
            .map_err(|e| MpcError::Solver(format!("setup: {e:?}")))?;
        Ok(Self {
            cfg,
            solver,
            sp,
            sv,
            wp,
            wv,
            q,
        })
    }

    /// Solves for the head at position `p0` and velocity `v0`, tracking `refs` (one
    /// entry per prediction step `k = 1..H`: the reference at `t + k h`; the
    /// acceleration reference of entry `k` is used for `a_{k-1}`), with `a_prev` the
    /// acceleration applied until now.
    pub fn solve(
        &mut self,
        p0: V3,
        v0: V3,
        refs: &[MpcRef],
        a_prev: V3,
    ) -> Result<MpcSolution, MpcError> {
        let n = self.cfg.horizon;
        let h = self.cfg.step;
        if refs.len() != n {
            return Err(MpcError::Input(format!(
                "{} reference steps, expected {n}",
                refs.len()
            )));
        }
        let finite = |v: &V3| v.iter().all(|x| x.is_finite());
        if !finite(&p0)
            || !finite(&v0)
            || !finite(&a_prev)
            || !refs
                .iter()
                .all(|r| finite(&r.p) && finite(&r.v) && finite(&r.a))
        {
            return Err(MpcError::Input("non-finite state or reference".into()));
        }
        // Gradient per axis: Sp' Wp (p_free - p_ref) + Sv' Wv (v_free - v_ref)
        //                    - r_a a_ref - r_j e_0 a_prev ; q = 2 * that.
        for ax in 0..3 {
            let mut ep = vec![0.0; n];
            let mut ev = vec![0.0; n];
            for k in 0..n {
                let kk = (k + 1) as f64;
                ep[k] = p0[ax] + kk * h * v0[ax] - refs[k].p[ax];
                ev[k] = v0[ax] - refs[k].v[ax];
            }
            for (j, rj) in refs.iter().enumerate() {
                let mut g = 0.0;
                for k in 0..n {
                    g += self.sp[k * n + j] * self.wp[k] * ep[k]
                        + self.sv[k * n + j] * self.wv[k] * ev[k];
                }
                g -= self.cfg.r_acc * rj.a[ax];
                if j == 0 {
                    g -= self.cfg.r_jerk * a_prev[ax];
                }
                self.q[ax * n + j] = 2.0 * g;
            }
        }
        self.solver
            .update_q(&self.q)
            .map_err(|e| MpcError::Solver(format!("update: {e:?}")))?;
        self.solver.solve();
        let sol = &self.solver.solution;
        match sol.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => {}
            s => return Err(MpcError::Solver(format!("{s:?}"))),
        }
        let x = &sol.x;
        if x.iter().any(|v| !v.is_finite()) {
            return Err(MpcError::Solver("non-finite solution".into()));
        }
        let plan: Vec<V3> = (0..n)
            .map(|k| V3::new(x[k], x[n + k], x[2 * n + k]))
            .collect();
        Ok(MpcSolution {
            accel: plan[0],
            plan,
            iterations: sol.iterations,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn still(p: V3, n: usize) -> Vec<MpcRef> {
        vec![
            MpcRef {
                p,
                v: V3::zeros(),
                a: V3::zeros()
            };
            n
        ]
    }

    /// The plan from rest at the origin towards a reference held still at `p`.
    fn solve_from_rest(m: &mut HeadMpc, p: V3) -> MpcSolution {
        m.solve(V3::zeros(), V3::zeros(), &still(p, 15), V3::zeros())
            .unwrap()
    }

    #[test]
    fn at_the_reference_it_does_nothing() {
        let mut m = HeadMpc::new(MpcConfig::default()).unwrap();
        let p = V3::new(1.0, 2.0, 3.0);
        let s = m.solve(p, V3::zeros(), &still(p, 15), V3::zeros()).unwrap();
        assert!(s.accel.norm() < 1e-5, "{:?}", s.accel);
    }

    #[test]
    fn pushes_towards_the_reference_within_the_tilt_cone() {
        let cfg = MpcConfig::default();
        let mut m = HeadMpc::new(cfg).unwrap();
        let s = solve_from_rest(&mut m, V3::new(10.0, 0.0, 0.0));
        assert!(s.accel.x > 0.5);
        let tan = cfg.tilt_max.tan();
        for a in &s.plan {
            let horiz = (a.x * a.x + a.y * a.y).sqrt();
            assert!(horiz <= tan * (GRAVITY + a.z) + 1e-6, "tilt {a:?}");
            assert!(
                a.x.abs() <= cfg.a_xy_max + 1e-6
                    && a.z <= cfg.a_z_max + 1e-6
                    && a.z >= cfg.a_z_min - 1e-6
            );
        }
        // Far below: climbs at most a_z_max.
        let s = solve_from_rest(&mut m, V3::new(0.0, 0.0, 50.0));
        assert!((s.accel.z - cfg.a_z_max).abs() < 1e-3);
    }

    #[test]
    fn closed_loop_double_integrator_settles() {
        let mut m = HeadMpc::new(MpcConfig::default()).unwrap();
        let target = V3::new(1.0, -0.5, 0.3);
        let (mut p, mut v, mut a) = (V3::zeros(), V3::zeros(), V3::zeros());
        let dt = 0.02;
        for _ in 0..400 {
            a = m.solve(p, v, &still(target, 15), a).unwrap().accel;
            v += a * dt;
            p += v * dt;
        }
        assert!((p - target).norm() < 1e-3 && v.norm() < 1e-3, "{p:?} {v:?}");
    }

    #[test]
    fn bad_input_is_an_error() {
        let mut m = HeadMpc::new(MpcConfig::default()).unwrap();
        assert!(m
            .solve(
                V3::zeros(),
                V3::zeros(),
                &still(V3::zeros(), 3),
                V3::zeros()
            )
            .is_err());
        assert!(m
            .solve(
                V3::new(f64::NAN, 0.0, 0.0),
                V3::zeros(),
                &still(V3::zeros(), 15),
                V3::zeros()
            )
            .is_err());
        assert!(HeadMpc::new(MpcConfig {
            horizon: 0,
            ..Default::default()
        })
        .is_err());
        assert!(HeadMpc::new(MpcConfig {
            a_z_min: -20.0,
            ..Default::default()
        })
        .is_err());
    }
}
