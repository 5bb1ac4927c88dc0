//! Checks of command-line values shared by every subcommand, and the budgets they are
//! held to (docs/promises.md lists them). Each check runs before any work, and its
//! error is one line naming the flag, the value and the limit.

use std::path::Path;
use std::time::Duration;

use super::CliError;
pub use aerial_chain::picture::PictureFormat;

/// Longest `--time-limit` (s): about 11.6 days. Beyond it a limit means nothing, and
/// far beyond it `Duration` cannot hold it.
pub const MAX_TIME_LIMIT_S: f64 = aerial_chain::planning::MAX_TIME_LIMIT_S;

/// Most head-roadmap vertices `arc plan` may ever hold, growth included
/// (`--vertices` times 2^`--max-growth`): about 1 GiB of roadmap at the default
/// neighbours.
pub const MAX_HEAD_VERTICES: usize = 2_000_000;

/// Most neighbours per roadmap vertex (`--max-neighbours`, `--k`).
pub const MAX_NEIGHBOURS: usize = 1000;

/// Most vertices of the full-state PRM (`arc bench prm --vertices`, `--prm-vertices`):
/// each holds a full configuration and its edges.
pub const MAX_PRM_VERTICES: usize = 1_000_000;

/// Most head edges the planner may drop without progress (`--max-replans`).
pub const MAX_REPLANS: usize = 1_000_000;

/// Longest length a flag may give in metres (`--goal-tol`, `--clearance`, `--r-t`):
/// 10 km, far beyond any map, so that sums and samplers stay finite.
pub const MAX_LENGTH_M: f64 = 1e4;

/// Longest link (`--link-length`, m).
pub const MAX_LINK_LENGTH_M: f32 = 100.0;

/// A length in metres: `>= 0` (or `> 0` when `positive`) and at most [`MAX_LENGTH_M`].
pub fn length(flag: &str, v: f64, positive: bool) -> Result<(), CliError> {
    let low_ok = if positive { v > 0.0 } else { v >= 0.0 };
    if low_ok && v <= MAX_LENGTH_M {
        Ok(())
    } else {
        let low = if positive { "positive" } else { ">= 0" };
        Err(bad(
            flag,
            v,
            &format!("a length {low} and at most {MAX_LENGTH_M:e} m"),
        ))
    }
}

/// The error for a flag whose value breaks its limit: `--flag VALUE: must be WANT`.
pub fn bad(flag: &str, value: impl std::fmt::Display, want: &str) -> CliError {
    CliError::input(format!("{flag} {value}: must be {want}"))
}

/// `--time-limit`: absent for none, else a positive number of seconds up to
/// [`MAX_TIME_LIMIT_S`].
pub fn time_limit(value: Option<f64>) -> Result<Option<Duration>, CliError> {
    let Some(t) = value else { return Ok(None) };
    if !(t.is_finite() && t > 0.0 && t <= MAX_TIME_LIMIT_S) {
        return Err(bad(
            "--time-limit",
            t,
            &format!("a positive number of seconds, at most {MAX_TIME_LIMIT_S:e}"),
        ));
    }
    Ok(Some(Duration::from_secs_f64(t)))
}

/// A number `>= 0` (and finite).
pub fn non_negative(flag: &str, v: f64) -> Result<(), CliError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(bad(flag, v, "a number >= 0"))
    }
}

/// A positive finite number.
pub fn positive(flag: &str, v: f64) -> Result<(), CliError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(bad(flag, v, "a positive number"))
    }
}

/// `--sensor-rate`: scans per second, positive and at most what a depth camera
/// delivers (`sensing::survey::MAX_RATE_HZ`).
pub fn sensor_rate(v: f64) -> Result<(), CliError> {
    let max = aerial_chain::sensing::survey::MAX_RATE_HZ;
    if v > 0.0 && v <= max {
        Ok(())
    } else {
        Err(bad(
            "--sensor-rate",
            v,
            &format!("a positive number of scans per second, at most {max}"),
        ))
    }
}

/// `--srs`: the number of random shapes, which the table indexes with 16 bits.
pub fn srs(v: usize) -> Result<(), CliError> {
    count(
        "--srs",
        v,
        0,
        u16::MAX as usize,
        "the table's index is 16 bits",
    )
}

/// A count within `lo..=hi`; `why` says where the upper limit comes from.
pub fn count(flag: &str, v: usize, lo: usize, hi: usize, why: &str) -> Result<(), CliError> {
    if (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(bad(flag, v, &format!("between {lo} and {hi} ({why})")))
    }
}

/// The output picture path of `flag`, checked before any work is done: its extension
/// must name a supported format.
pub fn picture(flag: &str, path: &Path) -> Result<PictureFormat, CliError> {
    PictureFormat::of(path).ok_or_else(|| {
        bad(
            flag,
            path.display(),
            &format!("a picture ending in {}", PictureFormat::extensions()),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_limits_are_positive_finite_and_bounded() {
        assert_eq!(time_limit(None).unwrap(), None);
        assert_eq!(
            time_limit(Some(0.5)).unwrap(),
            Some(Duration::from_millis(500))
        );
        for t in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e20] {
            let e = time_limit(Some(t)).unwrap_err();
            assert_eq!(e.code, crate::exit::BAD_INPUT);
            assert!(e.message.starts_with("--time-limit "), "{}", e.message);
            assert!(e.message.contains("1e6"), "{}", e.message);
        }
    }

    #[test]
    fn pictures_are_svg_or_png_in_any_case() {
        assert_eq!(
            picture("--out", Path::new("a.SVG")).unwrap(),
            PictureFormat::Svg
        );
        assert_eq!(
            picture("--out", Path::new("d/a.png")).unwrap(),
            PictureFormat::Png
        );
        for p in ["a.jpg", "a.gif", "a", "svg"] {
            let e = picture("--picture", Path::new(p)).unwrap_err();
            assert!(
                e.message.contains("--picture") && e.message.contains(".svg or .png"),
                "{}",
                e.message
            );
        }
    }
}
