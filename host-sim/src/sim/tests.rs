//! Closed-loop flights on hand-made plans: the whole stack (MPC, link controllers,
//! mixer, unit attitude loops) on the multibody dynamics.

use aerial_chain_core::ChainParams;

use super::dynamics::V3;
use super::flight::{simulate, Gust, SimConfig};
use super::{ChainModel, FlightRun, Reference, ReferenceError};

fn zeta(xi: [f64; 3], eta: &[f64]) -> Vec<f64> {
    let mut z = xi.to_vec();
    z.extend_from_slice(eta);
    z
}

/// The default simulation, `min_time` seconds at least, with one `gust`.
/// The default settings, flying at least `min_time` s.
fn flying_for(min_time: f64) -> SimConfig {
    SimConfig {
        min_time,
        ..Default::default()
    }
}

/// The default settings with one gust, flying at least `min_time` s: from `start`
/// for `duration` s, `force` on `unit` (`None`: on every unit).
fn with_gust(
    (start, duration): (f64, f64),
    unit: Option<usize>,
    force: V3,
    min_time: f64,
) -> SimConfig {
    let gust = Gust {
        start,
        duration,
        unit,
        force,
    };
    SimConfig {
        min_time,
        gusts: vec![gust],
        ..Default::default()
    }
}

fn line(n: usize) -> Vec<f64> {
    vec![0.0; 2 * n - 1]
}

/// A bent shape within the limits: alternating pitches, fanning yaws.
fn bent(n: usize) -> Vec<f64> {
    let mut e = line(n);
    e[0] = 0.3;
    for k in 0..n - 1 {
        e[1 + 2 * k] = if k % 2 == 0 { 0.4 } else { -0.3 };
        e[2 + 2 * k] = 0.45 * k as f64 - 0.3;
    }
    e
}

#[test]
fn hover_equilibrium_holds() {
    let p = ChainParams::new(5);
    let cfg = flying_for(5.0);
    let f = simulate(&p, &[zeta([1.0, 2.0, 3.0], &bent(5))], &cfg, None).unwrap();
    let r = &f.report;
    assert!(r.success(), "{r:?}");
    assert!(r.simulated_time >= 5.0);
    // Started in trim: nothing moves by more than a millimetre or a tenth of a degree.
    assert!(r.head_max < 1e-3, "head moved {} m", r.head_max);
    assert!(r.link_max_deg < 0.1, "links moved {} deg", r.link_max_deg);
}

#[test]
fn a_step_in_head_position_settles() {
    let p = ChainParams::new(4);
    let w = [
        zeta([0.0, 0.0, 2.0], &line(4)),
        zeta([1.0, -0.5, 2.4], &line(4)),
    ];
    let f = simulate(&p, &w, &SimConfig::default(), None).unwrap();
    let r = &f.report;
    assert!(r.success(), "{r:?}");
    let done = r.time_to_complete.unwrap();
    assert!(
        done <= r.planned_duration + 1.0,
        "settled at {done} s, plan ends at {}",
        r.planned_duration
    );
    assert!(
        r.head_max < 0.05,
        "head strayed {} m from its reference",
        r.head_max
    );
    let last = f.samples.last().unwrap();
    let head = V3::new(
        last.units[0].p[0] as f64,
        last.units[0].p[1] as f64,
        last.units[0].p[2] as f64,
    );
    assert!((head - V3::new(1.0, -0.5, 2.4)).norm() < 0.02);
}

#[test]
fn a_shape_change_settles() {
    let p = ChainParams::new(5);
    let w = [
        zeta([0.0, 0.0, 2.0], &line(5)),
        zeta([0.0, 0.0, 2.0], &bent(5)),
    ];
    let f = simulate(&p, &w, &SimConfig::default(), None).unwrap();
    let r = &f.report;
    assert!(r.success(), "{r:?}");
    assert!(
        r.link_max_deg < 3.0,
        "a link strayed {} deg",
        r.link_max_deg
    );
    assert!(
        r.head_max < 0.02,
        "the head moved {} m during a shape change",
        r.head_max
    );
    assert_eq!(r.limits.time_beyond, 0.0);
    let last = f.samples.last().unwrap();
    for (k, (m, rf)) in last.links_meas.iter().zip(&last.links_ref).enumerate() {
        assert!(
            (m[0] - rf[0]).abs() < 0.02 && (m[1] - rf[1]).abs() < 0.02,
            "link {k}: {m:?} vs {rf:?}"
        );
    }
}

#[test]
fn a_gust_is_rejected() {
    // 2 N sideways and 1 N down on every unit for 0.5 s (about a fifth of each unit's
    // weight): the chain is pushed, then returns.
    let p = ChainParams::new(4);
    let cfg = with_gust((2.0, 0.5), None, V3::new(2.0, 1.0, -1.0), 8.0);
    let f = simulate(&p, &[zeta([0.0, 0.0, 2.0], &bent(4))], &cfg, None).unwrap();
    let r = &f.report;
    assert!(r.success(), "{r:?}");
    assert!(r.head_max > 0.005, "the gust did push ({} m)", r.head_max);
    assert!(r.head_max < 0.3, "but not far ({} m)", r.head_max);
    // Back within 2 cm and 2 degrees two seconds after the gust.
    for s in f.samples.iter().filter(|s| s.t > 4.5) {
        let h = s.units[0].p;
        let e = ((h[0] - s.head_ref[0]).powi(2)
            + (h[1] - s.head_ref[1]).powi(2)
            + (h[2] - s.head_ref[2]).powi(2))
        .sqrt();
        assert!(e < 0.02, "t = {}: head {e} m off", s.t);
        for (m, rf) in s.links_meas.iter().zip(&s.links_ref) {
            assert!(
                (m[0] - rf[0]).abs() < 0.035 && (m[1] - rf[1]).abs() < 0.035,
                "t = {}: {m:?} vs {rf:?}",
                s.t
            );
        }
    }
}

#[test]
fn a_steady_wind_is_rejected_without_offset() {
    // A constant 1.5 N push on the head from t = 1 s: the disturbance observer removes
    // the steady-state error the MPC alone would keep.
    let p = ChainParams::new(3);
    let cfg = with_gust((1.0, 100.0), Some(0), V3::new(1.5, 0.0, 0.0), 10.0);
    let f = simulate(&p, &[zeta([0.0, 0.0, 2.0], &line(3))], &cfg, None).unwrap();
    let last = f.samples.last().unwrap();
    assert!(f.report.success(), "{:?}", f.report);
    assert!(
        (last.units[0].p[0] - last.head_ref[0]).abs() < 0.01,
        "offset {}",
        last.units[0].p[0]
    );
}

#[test]
fn a_translation_with_a_bent_shape_keeps_the_shape() {
    let p = ChainParams::new(6);
    let b = bent(6);
    let w = [
        zeta([0.0, 0.0, 2.0], &line(6)),
        zeta([0.0, 0.0, 2.0], &b),
        zeta([2.0, 1.0, 2.5], &b),
    ];
    let f = simulate(&p, &w, &SimConfig::default(), None).unwrap();
    let r = &f.report;
    assert!(r.success(), "{r:?}");
    assert!(r.head_max < 0.05 && r.link_max_deg < 3.0, "{r:?}");
}

#[test]
fn unflyable_plans_are_errors_not_panics() {
    let p = ChainParams::new(3);
    let cfg = SimConfig::default();
    assert!(simulate(&p, &[], &cfg, None).is_err());
    assert!(simulate(&p, &[vec![0.0; 5]], &cfg, None).is_err());
    let both = [zeta([0.0; 3], &line(3)), zeta([1.0, 0.0, 0.0], &bent(3))];
    assert!(simulate(&p, &both, &cfg, None).is_err());
    let bad = SimConfig {
        rate: 100.0,
        ..Default::default()
    };
    assert!(simulate(&p, &[zeta([0.0; 3], &line(3))], &bad, None).is_err());
}

#[test]
fn progress_counts_the_steps_flown() {
    use super::flight::{simulate_with_progress, Progress};
    use std::sync::atomic::Ordering;
    let p = ChainParams::new(3);
    let cfg = flying_for(1.0);
    let progress = Progress::default();
    let f = simulate_with_progress(
        &p,
        &[zeta([0.0, 0.0, 2.0], &line(3))],
        &cfg,
        None,
        &progress,
    )
    .unwrap();
    let (done, total) = (
        progress.done.load(Ordering::Relaxed),
        progress.total.load(Ordering::Relaxed),
    );
    // One sample per step: the last step's index is the count less one.
    assert_eq!(done + 1, f.samples.len() as u64);
    let longest = (cfg.min_time + cfg.settle_time) * cfg.rate;
    assert!(
        total as f64 >= longest && done <= total,
        "{done} of {total}"
    );
}

/// A wall: the plane `y = y0`, obstacles below it. The clearance of the chain is its
/// lowest unit's distance above the plane less `r_u` (a link is thinner than a unit
/// and lies between two units, so it is never nearer).
struct Wall {
    y0: f64,
    unit_radius: f64,
}

impl super::flight::Obstacles for Wall {
    fn clearance(&self, units: &[V3]) -> (f64, String) {
        let low = units.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
        (low - self.y0 - self.unit_radius, "the wall".into())
    }
    fn check_spacing(&self) -> f64 {
        // r_v / 4 of a 0.1 m map, as `MapClearance` has it.
        0.025
    }
}

/// The wall's clearance at every recorded step, from the recorded unit centres.
fn every_step_minimum(f: &super::flight::Flight, wall: &Wall) -> f64 {
    f.samples
        .iter()
        .map(|s| {
            let low = s
                .units
                .iter()
                .map(|u| u.p[1] as f64)
                .fold(f64::INFINITY, f64::min);
            low - wall.y0 - wall.unit_radius
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn the_reported_clearance_is_the_every_step_minimum() {
    let p = ChainParams::new(3);
    let start = zeta([0.0, 0.0, 2.0], &line(3));
    let wall = Wall {
        y0: -(p.unit_radius as f64) - 0.008,
        unit_radius: p.unit_radius as f64,
    };
    // 1. Only the head's yaw turns (no unit centre moves by itself) while a gust pushes
    //    the chain 8 mm into the wall: a check scheduled by motion alone never fires.
    let mut turned = line(3);
    turned[0] = 1.0;
    let cfg = with_gust((1.0, 5.0), None, V3::new(0.0, -0.2, 0.0), 6.0);
    // 2. An ordinary flight along the wall, drifting towards it.
    let along = zeta([3.0, -0.004, 2.0], &line(3));
    let flights = [
        (
            vec![start.clone(), zeta([0.0, 0.0, 2.0], &turned)],
            cfg,
            true,
        ),
        (vec![start, along], SimConfig::default(), false),
    ];
    for (w, cfg, touches) in flights {
        let f = simulate(&p, &w, &cfg, Some(&wall)).unwrap();
        let exact = every_step_minimum(&f, &wall);
        let r = &f.report;
        let reported = r.min_clearance.unwrap();
        // f32 recording of positions near 3 m: a few micrometres.
        assert!(
            (reported - exact).abs() <= 1e-3,
            "reported {reported} m, every step {exact} m"
        );
        assert_eq!(r.contact, exact <= 0.0, "every-step minimum {exact} m");
        // The cases are what they claim: the gust pushes into the wall, the drift not.
        assert_eq!(r.contact, touches, "every-step minimum {exact} m");
    }
}

/// A flight follows a new reference only where it is where the one followed is now:
/// a reference that differs ahead of the chain is taken, one that would move the chain
/// now is refused.
#[test]
fn a_flight_follows_a_reference_that_changes_only_ahead_of_it() {
    let params = ChainParams::new(3);
    let cfg = SimConfig::default();
    let start = vec![1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let ahead = vec![2.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let l = params.link_length as f64;
    let rest = Reference::new(3, l, std::slice::from_ref(&start), &cfg.limits).unwrap();
    let mut run = FlightRun::start(ChainModel::new(params), rest.clone(), &cfg, None, 0).unwrap();
    for _ in 0..10 {
        assert!(run.advance(false).is_none());
    }
    let go = Reference::new(3, l, &[start.clone(), ahead.clone()], &cfg.limits).unwrap();
    // Starting to move now, from where the chain rests: the start hold keeps it still.
    run.follow(go.clone()).unwrap();
    assert_eq!(run.reference(), &go);
    let elsewhere = Reference::new(3, l, &[ahead.clone(), start], &cfg.limits).unwrap();
    let refused = run.follow(elsewhere).unwrap_err();
    assert!(matches!(refused, ReferenceError::Join { .. }), "{refused}");
    assert_eq!(run.reference(), &go);
}
