//! Chart axes: a named data range, linear or logarithmic, and where its ticks go
//! and how they read.

/// Labelled ticks of an axis: `(value, label)`.
pub(crate) type Ticks = Vec<(f64, String)>;

/// One axis of a chart: its name and the data range it shows.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    /// Name and unit, e.g. `t (s)`.
    pub label: String,
    /// Smallest value shown.
    pub min: f64,
    /// Largest value shown.
    pub max: f64,
    /// Logarithmic (base 10); `min` must then be positive.
    pub log: bool,
    /// Counts (units, metres of a size): ticks at whole numbers only.
    pub whole: bool,
}

impl Axis {
    /// A linear axis over `min..max`.
    pub fn linear(label: &str, (min, max): (f64, f64)) -> Self {
        Self {
            label: label.to_string(),
            min,
            max,
            log: false,
            whole: false,
        }
    }

    /// A logarithmic axis over `min..max` (a non-positive `min` becomes a thousandth
    /// of `max`).
    pub fn log(label: &str, (min, max): (f64, f64)) -> Self {
        let max = if max > 0.0 { max } else { 1.0 };
        let min = if min > 0.0 && min < max {
            min
        } else {
            max * 1e-3
        };
        Self {
            label: label.to_string(),
            min,
            max,
            log: true,
            whole: false,
        }
    }

    /// The same axis with ticks at whole numbers only.
    pub fn whole(self) -> Self {
        Self {
            whole: true,
            ..self
        }
    }

    /// A linear axis around `values` with a little room on both sides; `(-1, 1)`
    /// when there is no finite value.
    pub fn around(label: &str, values: impl Iterator<Item = f64>) -> Self {
        let (lo, hi) = finite_range(values).unwrap_or((-1.0, 1.0));
        let pad = ((hi - lo) * 0.06).max(0.05);
        Self::linear(label, (lo - pad, hi + pad))
    }

    /// `v` where the axis is uniform: itself, or its logarithm on a log axis.
    pub(crate) fn warp(&self, v: f64) -> f64 {
        if self.log {
            v.max(f64::MIN_POSITIVE).log10()
        } else {
            v
        }
    }

    /// Length of the range where the axis is uniform.
    pub(crate) fn span(&self) -> f64 {
        (self.warp(self.max) - self.warp(self.min)).max(1e-9)
    }

    /// Labelled ticks for an axis drawn `pixels` long: `(value, label)`.
    pub(crate) fn ticks(&self, pixels: f64) -> Ticks {
        if self.log {
            return decades(self.min, self.max);
        }
        let wanted = (pixels / TICK_SPACING).clamp(MIN_TICKS as f64, 10.0);
        let step = nice_step((self.max - self.min) / wanted);
        let floor = if self.whole { 1.0 } else { 0.0 };
        at_least(self.min, self.max, step.max(floor), floor)
    }

    /// Unlabelled ticks between the labelled ones: 2..9 times each power of ten on a
    /// log axis, none on a linear one.
    pub(crate) fn minor_ticks(&self) -> Vec<f64> {
        if !self.log {
            return Vec::new();
        }
        let (a, b) = (
            self.min.log10().floor() as i32,
            self.max.log10().ceil() as i32,
        );
        (a..b)
            .flat_map(|e| (2..10).map(move |m| m as f64 * 10f64.powi(e)))
            .filter(|v| *v >= self.min && *v <= self.max)
            .collect()
    }
}

/// Smallest and largest finite value, if any.
pub fn finite_range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    lo.is_finite().then_some((lo, hi))
}

/// Pixels wanted between labelled ticks.
pub(crate) const TICK_SPACING: f64 = 70.0;

/// Fewest labelled ticks on a linear axis, however short or long its range, unless
/// whole-number ticks cannot give that many.
pub(crate) const MIN_TICKS: usize = 4;

/// Ticks at multiples of `step` within `lo..=hi`, the step made finer (1, 2, 5 times
/// a power of ten, and never below `floor`) until there are [`MIN_TICKS`]: a short axis
/// beside a long one on a map still reads.
pub(crate) fn at_least(lo: f64, hi: f64, step: f64, floor: f64) -> Ticks {
    let mut step = step;
    loop {
        let finer = finer_step(step);
        let count = ((hi / step).floor() - (lo / step).ceil() + 1.0).max(0.0) as usize;
        if count >= MIN_TICKS || finer < floor || finer < (hi - lo).abs() * 1e-6 {
            return labelled(lo, hi, step);
        }
        step = finer;
    }
}

/// The next nice step below `step` (itself 1, 2 or 5 times a power of ten).
fn finer_step(step: f64) -> f64 {
    let p = 10f64.powf(step.log10().floor());
    let m = (step / p).round();
    if m >= 5.0 {
        2.0 * p
    } else if m >= 2.0 {
        p
    } else {
        0.5 * p
    }
}

/// 1, 2 or 5 times a power of ten, at least `raw`.
pub(crate) fn nice_step(raw: f64) -> f64 {
    let raw = raw.max(1e-9);
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * p)
}

/// Multiples of `step` within `lo..=hi`, labelled with as many decimals as `step` needs.
pub(crate) fn labelled(lo: f64, hi: f64, step: f64) -> Ticks {
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    (first..=last)
        .map(|i| {
            let v = i as f64 * step;
            (v, format!("{v:.decimals$}"))
        })
        .collect()
}

/// Powers of ten within `lo..=hi`, and 2 and 5 times them too when that would be
/// fewer than three labels.
fn decades(lo: f64, hi: f64) -> Ticks {
    let (a, b) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let within = |v: &(f64, String)| v.0 >= lo * (1.0 - 1e-9) && v.0 <= hi * (1.0 + 1e-9);
    let with = |multiples: &[u32]| -> Ticks {
        (a..=b)
            .flat_map(|e| multiples.iter().map(move |&m| log_tick(m, e)))
            .filter(within)
            .collect()
    };
    let plain = with(&[1]);
    if plain.len() >= 3 {
        plain
    } else {
        with(&[1, 2, 5])
    }
}

/// `m` times ten to the `e`, labelled plainly (`0.02`, `1`, `5000`) or as `2e6`
/// when that is shorter.
fn log_tick(m: u32, e: i32) -> (f64, String) {
    let v = m as f64 * 10f64.powi(e);
    let label = match e {
        -3..=-1 => format!("{v:.*}", (-e) as usize),
        0..=4 => format!("{v:.0}"),
        _ => format!("{m}e{e}"),
    };
    (v, label)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_linear_ticks() {
        let a = Axis::linear("t (s)", (0.0, 9.3));
        let t = a.ticks(400.0);
        assert_eq!(t.first().unwrap().1, "0");
        assert!(t.iter().all(|(v, _)| *v >= 0.0 && *v <= 9.3));
        let n = Axis::linear("N", (2.9, 5.1)).whole();
        let labels: Vec<String> = n.ticks(500.0).into_iter().map(|t| t.1).collect();
        assert_eq!(labels, ["3", "4", "5"]);
        let b = Axis::linear("m", (-0.13, 0.42));
        let labels: Vec<String> = b.ticks(300.0).into_iter().map(|t| t.1).collect();
        assert_eq!(labels, ["-0.1", "0.0", "0.1", "0.2", "0.3", "0.4"]);
    }

    #[test]
    fn every_linear_axis_gets_enough_ticks() {
        // Short axes beside long ones (a corridor's y and z), long and tiny ranges.
        for (lo, hi, px) in [
            (0.0, 100.0, 1000.0),
            (-0.7, 2.3, 60.0),
            (3.1, 3.4, 400.0),
            (-2500.0, 12.0, 90.0),
            (0.0, 1e-3, 200.0),
        ] {
            let t = Axis::linear("m", (lo, hi)).ticks(px);
            assert!(t.len() >= MIN_TICKS, "{lo}..{hi}: {t:?}");
            assert!(t.len() <= 40, "{lo}..{hi}: {} ticks", t.len());
            let labels: std::collections::HashSet<&String> = t.iter().map(|x| &x.1).collect();
            assert_eq!(labels.len(), t.len(), "{lo}..{hi}: labels repeat: {t:?}");
        }
        assert_eq!(at_least(0.0, 10.0, 10.0, 0.0).len(), 6, "10 -> 5 -> 2");
    }

    #[test]
    fn log_ticks_are_decades() {
        let a = Axis::log("ms", (0.5, 2000.0));
        let labels: Vec<String> = a.ticks(300.0).into_iter().map(|t| t.1).collect();
        assert_eq!(labels, ["1", "10", "100", "1000"]);
        let narrow = Axis::log("ms", (0.65, 15.0));
        let labels: Vec<String> = narrow.ticks(300.0).into_iter().map(|t| t.1).collect();
        assert_eq!(labels, ["1", "2", "5", "10"]);
        assert!(a.minor_ticks().contains(&0.5) && a.minor_ticks().contains(&2000.0));
        let small = Axis::log("ms", (0.001, 1e6));
        let labels: Vec<String> = small.ticks(300.0).into_iter().map(|t| t.1).collect();
        assert_eq!(labels.first().unwrap(), "0.001");
        assert_eq!(labels.last().unwrap(), "1e6");
    }

    #[test]
    fn log_axis_survives_bad_ranges() {
        let a = Axis::log("ms", (0.0, 0.0));
        assert!(a.min > 0.0 && a.max > a.min);
        assert!(a.span() > 0.0);
    }
}
