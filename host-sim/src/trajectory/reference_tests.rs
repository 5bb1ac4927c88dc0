//! The timing core's tests.

use super::*;
use crate::collision::verify::wrap;
use std::f64::consts::PI;

fn zeta(xi: [f64; 3], eta: &[f64]) -> Vec<f64> {
    let mut z = xi.to_vec();
    z.extend_from_slice(eta);
    z
}

#[test]
fn a_motion_joins_another_where_it_ends_and_no_earlier() {
    let limits = ReferenceLimits::default();
    let a = zeta([0.0, 0.0, 1.0], &[0.0, 0.0, 0.0]);
    let b = zeta([1.0, 0.0, 1.0], &[0.0, 0.0, 0.0]);
    let c = zeta([1.0, 1.0, 1.0], &[0.0, 0.0, 0.0]);
    let first = Reference::new(2, 0.5, &[a.clone(), b.clone()], &limits).unwrap();
    let second = Reference::new(2, 0.5, &[b.clone(), c.clone()], &limits).unwrap();
    let at = first.duration() + 0.5;
    let joined = first.then(at, &second).unwrap();
    assert!((joined.duration() - (at + second.duration())).abs() < 1e-9);
    // At rest at the join until `at`, then the second motion.
    assert_eq!(joined.zeta(first.duration() + 0.25), b);
    let mid = second.duration() / 2.0;
    let (p, q) = (joined.zeta(at + mid), second.zeta(mid));
    assert!(p.iter().zip(&q).all(|(x, y)| (x - y).abs() < 1e-12));
    assert_eq!(joined.end(), &c[..]);
    // Too early, or from elsewhere: refused.
    assert!(first.then(first.duration() - 0.1, &second).is_err());
    let elsewhere = Reference::new(2, 0.5, &[c.clone(), a], &limits).unwrap();
    assert!(first.then(at, &elsewhere).is_err());
}

#[test]
fn scaling_cruises_at_the_limit_or_ramps_straight_down() {
    for (rate, accel) in [(0.1, 0.1), (2.0, 0.5), (0.5, 100.0)] {
        let sc = Scaling::fastest(rate, accel);
        let (mut vmax, mut amax, mut t, mut prev) = (0.0f64, 0.0f64, 0.0, (0.0, 0.0, 0.0));
        while t <= sc.duration + 0.01 {
            let now = sc.at(t);
            assert!(now.0 >= prev.0 - 1e-12, "progress never goes back");
            assert!(
                (now.1 - prev.1).abs() < 0.02 * rate.max(1.0),
                "speed is continuous"
            );
            (vmax, amax, prev) = (vmax.max(now.1), amax.max(now.2.abs()), now);
            t += 1e-4;
        }
        assert!(
            vmax <= rate + 1e-9 && amax <= accel + 1e-9,
            "{rate} {accel}"
        );
        assert_eq!(sc.at(sc.duration), (1.0, 0.0, 0.0));
        // Where the cruise is reached, the edge takes one ramp longer than at the
        // cruise rate throughout: the quintic took 1.875 times as long.
        if 1.5 * rate * rate / accel <= 1.0 {
            assert!((sc.duration - (1.0 / rate + 1.5 * rate / accel)).abs() < 1e-12);
            assert!((vmax - rate).abs() < 1e-9);
        }
    }
}

#[test]
fn translation_respects_speed_and_acceleration() {
    let lim = ReferenceLimits::default();
    let eta = [0.0; 5];
    let r = Reference::new(
        3,
        0.5,
        &[zeta([0.0; 3], &eta), zeta([3.0, 4.0, 0.0], &eta)],
        &lim,
    )
    .unwrap();
    assert_eq!(r.segments().len(), 2);
    let mut vmax = 0.0f64;
    let mut amax = 0.0f64;
    let mut t = 0.0;
    while t < r.duration() + 1.0 {
        let s = r.sample(t);
        vmax = vmax.max(s.v.norm());
        amax = amax.max(s.a.norm());
        t += 0.001;
    }
    assert!(vmax <= lim.speed + 1e-9 && vmax > 0.9 * lim.speed, "{vmax}");
    assert!(amax <= lim.accel + 1e-6, "{amax}");
    let end = r.sample(r.duration() + 5.0);
    assert!((end.p - V3::new(3.0, 4.0, 0.0)).norm() < 1e-12 && end.v.norm() == 0.0);
    assert!((r.sample(0.5).p).norm() == 0.0, "held at the start");
}

#[test]
fn shape_change_takes_the_short_way_and_respects_the_rate() {
    let lim = ReferenceLimits {
        start_hold: 0.0,
        ..Default::default()
    };
    let a = zeta([1.0, 1.0, 1.0], &[3.0, 0.0, 3.0, 0.0, 0.0]);
    let b = zeta([1.0, 1.0, 1.0], &[-3.0, 0.2, -3.0, 0.0, 0.0]);
    let r = Reference::new(3, 0.5, &[a, b], &lim).unwrap();
    assert_eq!(r.segments()[0].kind, SegmentKind::ShapeChange);
    // 3 -> -3 the short way is +0.283.., not -6.
    let d = r.segments()[0].delta[3];
    assert!((d - (2.0 * PI - 6.0)).abs() < 1e-12);
    let mut t = 0.0;
    while t < r.duration() {
        let s = r.sample(t);
        for l in &s.links {
            assert!(
                l.pitch_rate.abs() <= lim.angular_rate + 1e-9
                    && l.yaw_rate.abs() <= lim.angular_rate + 1e-9
            );
        }
        assert!(s.v.norm() == 0.0);
        t += 0.001;
    }
    assert!((wrap(r.sample(r.duration()).links[0].yaw - (-3.0))).abs() < 1e-12);
}

/// A turn of the head yaw alone moves no body: it is timed at the head yaw's own
/// limits, within them at every instant and as fast as they allow.
#[test]
fn a_head_yaw_turn_is_timed_at_the_head_yaws_own_limits() {
    let lim = ReferenceLimits {
        start_hold: 0.0,
        ..Default::default()
    };
    assert!(lim.yaw_rate > lim.angular_rate && lim.yaw_accel > lim.angular_accel);
    let a = zeta([1.0, 1.0, 1.0], &[0.0, 0.1, 0.2, 0.0, 0.0]);
    let b = zeta([1.0, 1.0, 1.0], &[2.5, 0.1, 0.2, 0.0, 0.0]);
    let r = Reference::new(3, 0.5, &[a, b], &lim).unwrap();
    let (mut wmax, mut t) = (0.0f64, 0.0);
    let mut last = r.sample(0.0).head_yaw_rate;
    while t < r.duration() {
        let s = r.sample(t);
        wmax = wmax.max(s.head_yaw_rate.abs());
        assert!((s.head_yaw_rate - last).abs() <= lim.yaw_accel * 1e-3 * (1.0 + 1e-6) + 1e-12);
        last = s.head_yaw_rate;
        assert!(s
            .links
            .iter()
            .all(|l| l.yaw_rate == 0.0 && l.pitch_rate == 0.0));
        t += 0.001;
    }
    assert!(
        wmax <= lim.yaw_rate + 1e-9 && wmax > 0.99 * lim.yaw_rate,
        "{wmax}"
    );
    // Cruise at the rate, smoothstep ramps at 1.5 rate / accel: 2.5 / rate + 1.5 rate /
    // accel in all; at the link limits it would take 2.5 / 0.4 s and more.
    let expected = 2.5 / lim.yaw_rate + 1.5 * lim.yaw_rate / lim.yaw_accel;
    assert!((r.duration() - expected).abs() < 1e-9, "{}", r.duration());
    assert!(r.duration() < 2.5 / lim.angular_rate);
}

#[test]
fn samples_are_flown_through_in_time() {
    let lim = ReferenceLimits::default();
    let w = [
        zeta([0.0; 3], &[3.0, 0.0, 3.0, 0.0, 0.0]),
        zeta([0.0; 3], &[-3.0, 0.2, -3.0, 0.0, 0.0]),
        zeta([1.0, -1.0, 0.5], &[-3.0, 0.2, -3.0, 0.0, 0.0]),
    ];
    let r = Reference::new(3, 0.5, &w, &lim).unwrap();
    let times: Vec<f64> = (0..=200)
        .map(|j| 5.0 + j as f64 * r.duration() / 200.0)
        .collect();
    let zetas: Vec<Vec<f64>> = times.iter().map(|t| r.zeta(t - 5.0)).collect();
    let s = Reference::from_samples(3, &times, &zetas).unwrap();
    assert!((s.duration() - r.duration()).abs() < 1e-9);
    for (t, z) in times.iter().zip(&zetas) {
        let got = s.zeta(t - 5.0);
        for (a, b) in got.iter().zip(z) {
            assert!(wrap(a - b).abs() < 1e-9, "{t}: {a} vs {b}");
        }
    }
    let mid = s.sample(0.5 * (times[100] + times[101]) - 5.0);
    let dt = times[101] - times[100];
    let (a, b) = (&zetas[100], &zetas[101]);
    let chord = V3::new(b[0] - a[0], b[1] - a[1], b[2] - a[2]) / dt;
    assert!(
        (mid.v - chord).norm() < 1e-9,
        "constant velocity between samples"
    );
    assert!(Reference::from_samples(3, &[], &[]).is_err());
    let back = [times[1], times[0]];
    assert!(Reference::from_samples(3, &back, &zetas[..2]).is_err());
    assert!(Reference::from_samples(4, &times, &zetas).is_err());
}

#[test]
fn edges_changing_both_are_refused_and_bad_waypoints_too() {
    let lim = ReferenceLimits::default();
    let a = zeta([0.0; 3], &[0.0; 5]);
    let b = zeta([1.0, 0.0, 0.0], &[0.0, 0.1, 0.0, 0.0, 0.0]);
    assert!(Reference::new(3, 0.5, &[a.clone(), b], &lim).is_err());
    assert!(Reference::new(3, 0.5, &[a[..5].to_vec()], &lim).is_err());
    assert!(Reference::new(3, 0.5, &[], &lim).is_err());
    let mut nan = a.clone();
    nan[2] = f64::NAN;
    assert!(Reference::new(3, 0.5, &[nan], &lim).is_err());
    let bad = ReferenceLimits { speed: 0.0, ..lim };
    assert!(Reference::new(3, 0.5, &[a], &bad).is_err());
}

#[test]
fn velocity_is_the_derivative_of_position() {
    let lim = ReferenceLimits::default();
    let w = [
        zeta([0.0; 3], &[0.0; 7]),
        zeta([0.0; 3], &[0.5, 0.3, 0.5, -0.2, 0.1, 0.0, -0.4]),
        zeta([1.0, -1.0, 0.5], &[0.5, 0.3, 0.5, -0.2, 0.1, 0.0, -0.4]),
    ];
    let r = Reference::new(4, 0.5, &w, &lim).unwrap();
    let h = 1e-5;
    let mut t = 0.3;
    while t < r.duration() {
        let (a, b, c) = (r.sample(t - h), r.sample(t), r.sample(t + h));
        assert!(((c.p - a.p) / (2.0 * h) - b.v).norm() < 1e-5);
        assert!(((c.v - a.v) / (2.0 * h) - b.a).norm() < 1e-4);
        for k in 0..3 {
            assert!(
                ((c.links[k].yaw - a.links[k].yaw) / (2.0 * h) - b.links[k].yaw_rate).abs() < 1e-5
            );
            assert!(
                ((c.links[k].pitch_rate - a.links[k].pitch_rate) / (2.0 * h)
                    - b.links[k].pitch_acc)
                    .abs()
                    < 1e-4
            );
        }
        t += 0.0937;
    }
}
