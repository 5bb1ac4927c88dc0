//! Chain simulation costs: `cargo bench -p aerial-chain --bench sim`.
//!
//! - `sim/flight_n6`: a whole N = 6 flight (a shape change, then a 2.2 m translation;
//!   about 20 simulated seconds at 500 Hz, every body recorded); the real-time factor
//!   (simulated seconds per wall-clock second) is printed before the measurement;
//! - `sim/controller_step_n6`: one step of the control stack without an MPC solve
//!   (link controllers, mixer, seven attitude loops);
//! - `sim/mpc_solve`: one head MPC solve (clarabel, 45 variables, 15 cones);
//! - `sim/dynamics_step_n6_{lumped,full}`: one physics step in each formulation.

use std::hint::black_box;
use std::time::Instant;

use aerial_chain::sim::{
    simulate, ChainController, ChainModel, ControllerConfig, Reference, ReferenceLimits, SimConfig,
    V3,
};
use aerial_chain::sim::{ChainDynamics, Formulation, UnitCommand};
use aerial_chain::sim::{HeadMpc, MpcConfig, MpcRef};
use aerial_chain_core::ChainParams;
use criterion::{criterion_group, criterion_main, Criterion};

const N: usize = 6;

fn zeta(xi: [f64; 3], eta: &[f64]) -> Vec<f64> {
    let mut z = xi.to_vec();
    z.extend_from_slice(eta);
    z
}

fn plan() -> Vec<Vec<f64>> {
    let line = vec![0.0; 2 * N - 1];
    let mut bent = line.clone();
    for k in 0..N - 1 {
        bent[1 + 2 * k] = if k % 2 == 0 { 0.4 } else { -0.3 };
        bent[2 + 2 * k] = 0.45 * k as f64 - 0.3;
    }
    vec![
        zeta([0.0, 0.0, 2.0], &line),
        zeta([0.0, 0.0, 2.0], &bent),
        zeta([2.0, 1.0, 2.5], &bent),
    ]
}

fn bench(c: &mut Criterion) {
    let params = ChainParams::new(N as u8);
    let cfg = SimConfig::default();
    let w = plan();
    // Real-time factor, best of 3 runs.
    let mut best = 0.0f64;
    let mut simulated = 0.0;
    for _ in 0..3 {
        let t = Instant::now();
        let f = simulate(&params, &w, &cfg, None).expect("flight");
        let wall = t.elapsed().as_secs_f64();
        simulated = f.report.simulated_time;
        best = best.max(simulated / wall);
        assert!(f.report.success());
    }
    eprintln!(
        "sim/flight_n6: {simulated:.1} simulated s at {} Hz, {best:.1}x real time (best of 3)",
        cfg.rate
    );

    let mut g = c.benchmark_group("sim");
    g.sample_size(10);
    g.bench_function("flight_n6", |b| {
        b.iter(|| simulate(&params, black_box(&w), &cfg, None).expect("flight"))
    });
    g.finish();

    let model = ChainModel::new(params);
    let reference = Reference::new(N, 0.5, &w, &ReferenceLimits::default()).unwrap();
    let dynamics = ChainDynamics::new(model, V3::new(0.0, 0.0, 2.0), &w[0][3..], 0.002).unwrap();
    let units = dynamics.unit_states();
    let mut ctl = ChainController::new(
        model,
        ControllerConfig {
            mpc_period: 1e9,
            ..Default::default()
        },
    )
    .unwrap();
    ctl.step(0.0, &units, &reference);
    let mut t = 0.0;
    c.bench_function("sim/controller_step_n6", |b| {
        b.iter(|| {
            t += 0.002;
            ctl.step(black_box(t), black_box(&units), &reference)
        })
    });

    let mut mpc = HeadMpc::new(MpcConfig::default()).unwrap();
    let refs: Vec<MpcRef> = (1..=15)
        .map(|k| MpcRef {
            p: V3::new(0.05 * k as f64, 0.0, 0.0),
            v: V3::new(0.5, 0.0, 0.0),
            a: V3::zeros(),
        })
        .collect();
    c.bench_function("sim/mpc_solve", |b| {
        b.iter(|| {
            mpc.solve(
                black_box(V3::zeros()),
                V3::new(0.4, 0.0, 0.0),
                &refs,
                V3::zeros(),
            )
            .unwrap()
        })
    });

    for (name, form) in [("lumped", Formulation::Lumped), ("full", Formulation::Full)] {
        let mut d =
            ChainDynamics::with_formulation(model, V3::new(0.0, 0.0, 2.0), &w[0][3..], 0.002, form)
                .unwrap();
        let hover = model.total_mass() * model.gravity / N as f64;
        let cmd = vec![
            UnitCommand {
                thrust: hover,
                moment: V3::zeros()
            };
            N
        ];
        c.bench_function(&format!("sim/dynamics_step_n6_{name}"), |b| {
            b.iter(|| d.step(black_box(&cmd)))
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
