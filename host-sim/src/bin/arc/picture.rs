//! `--picture` of `arc plan` and `arc sim`: a still picture (`.svg`, `.png`) or, for
//! a name ending in `.gif`, an animation with one frame per `--frame-step` seconds.

use std::path::{Path, PathBuf};

use super::checks;
use super::CliError;
use aerial_chain::map::Grid;
use aerial_chain::picture::Animation;
use aerial_chain::plan_picture::{animate, AnimationError, AnimationOptions, Motion};

/// Whether `path` names an animation (ends in `.gif`, any case).
pub fn is_animation(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gif"))
}

/// Checks `--picture` and `--frame-step` before any work: a still picture's format,
/// or an animation with a positive step; a step without an animation is refused.
pub fn check(picture: Option<&PathBuf>, frame_step: Option<f64>) -> Result<(), CliError> {
    match picture {
        Some(p) if is_animation(p) => {
            if let Some(s) = frame_step {
                checks::positive("--frame-step", s)?;
            }
            Ok(())
        }
        Some(p) => {
            checks::picture("--picture", p).map_err(|_| {
                checks::bad(
                    "--picture",
                    p.display(),
                    &format!(
                        "a picture ending in {}, or an animation ending in .gif",
                        checks::PictureFormat::extensions()
                    ),
                )
            })?;
            match frame_step {
                Some(_) => Err(CliError::input(
                    "--frame-step: only with an animation (--picture ending in .gif)",
                )),
                None => Ok(()),
            }
        }
        None if frame_step.is_some() => Err(CliError::input(
            "--frame-step: only with an animation (--picture ending in .gif)",
        )),
        None => Ok(()),
    }
}

/// Writes the animation of `motion` on `grid` to `path`, atomically: on any error no
/// file is left behind. Returns its frames and their time step (s).
pub fn write_animation(
    path: &Path,
    grid: &Grid,
    motion: &Motion,
    opts: &AnimationOptions,
) -> Result<(usize, f64), CliError> {
    let gif = animate(grid, motion, opts).map_err(|e| match e {
        AnimationError::Step(_) | AnimationError::TooManyFrames { .. } => {
            CliError::input(format!("--frame-step: {e}"))
        }
        _ => CliError::input(format!("{}: {e}", path.display())),
    })?;
    Animation::save(&gif.bytes, path).map_err(|e| CliError::input(e.to_string()))?;
    Ok((gif.frames, gif.step))
}
