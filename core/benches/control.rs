//! Cost of the geometric attitude controller and of its helpers (ns per call).
//! `cargo bench -p aerial-chain-core --bench control`.

use std::hint::black_box;

use aerial_chain_core::control::{
    desired_attitude, from_euler_zyx, link_attitude, orthonormalize, step_attitude,
    AttitudeController, AttitudeGains, AttitudeSetpoint, AttitudeState, Mat3, Vec3,
};
use criterion::{criterion_group, criterion_main, Criterion};

fn controller() -> AttitudeController {
    let jd = Vec3::new(0.0082, 0.0082, 0.0149);
    let gains = AttitudeGains::from_bandwidth(jd, Vec3::new(15.0, 15.0, 8.0), 0.9);
    AttitudeController::new(gains, Mat3::from_diagonal(&jd), Vec3::new(1.0, 1.0, 0.15))
}

fn bench(c: &mut Criterion) {
    let ctl = controller();
    let state = AttitudeState {
        r: from_euler_zyx(0.3, -0.2, 1.0),
        w: Vec3::new(0.5, -0.3, 0.2),
    };
    let sp = AttitudeSetpoint {
        r_d: from_euler_zyx(0.1, 0.1, 0.8),
        w_d: Vec3::new(0.1, 0.0, 0.3),
        dw_d: Vec3::new(0.0, 0.2, 0.0),
    };
    c.bench_function("control/attitude_controller_step", |b| {
        b.iter(|| black_box(&ctl).control(black_box(&state), black_box(&sp)))
    });
    c.bench_function("control/desired_attitude_plus_controller_step", |b| {
        b.iter(|| {
            let r_d = desired_attitude(black_box(&Vec3::new(0.5, -0.3, 9.0)), black_box(0.8));
            black_box(&ctl).control(black_box(&state), &AttitudeSetpoint::hold(r_d))
        })
    });
    c.bench_function("control/link_attitude", |b| {
        b.iter(|| link_attitude(black_box(0.4), black_box(-1.2)))
    });
    c.bench_function("control/orthonormalize", |b| {
        b.iter(|| orthonormalize(black_box(&state.r)))
    });
    c.bench_function("control/step_attitude_rk4", |b| {
        b.iter(|| {
            step_attitude(
                black_box(&state),
                black_box(&Vec3::new(0.1, -0.2, 0.01)),
                black_box(&ctl.inertia),
                1e-3,
            )
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
