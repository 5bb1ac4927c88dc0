//! `arc map export|info|picture`: built-in scenarios as OctoMap files, facts about a
//! map file, and pictures of maps.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, Subcommand};

use super::{CliError, CliResult};
use aerial_chain::map::Grid;
use aerial_chain::map::OcTree;
use aerial_chain::picture::{map_figure, MapPictureOptions};
use aerial_chain::problem::scenarios::{self, Scenario};

/// `arc map ...`
#[derive(Subcommand, Debug)]
pub enum MapCommand {
    /// Write a built-in scenario's map as an OctoMap file: binary (.bt) or full (.ot).
    #[command(after_help = "Example:\n  arc map export --scenario window --out window.bt")]
    Export(ExportArgs),
    /// Print a map file's resolution, bounds and voxel counts.
    #[command(after_help = "Example:\n  arc map info maps/geb079.bt")]
    Info(InfoArgs),
    /// Draw a map (file or scenario): a top view and horizontal slices, SVG or PNG.
    #[command(after_help = "Example:\n  arc map picture maps/geb079.bt --out geb079.png")]
    Picture(PictureArgs),
}

/// `arc map export`
#[derive(Args, Debug)]
pub struct ExportArgs {
    /// Scenario: window, maze, silos, corridor, or corridor:LENGTH (10 to 100 m).
    #[arg(long)]
    pub scenario: String,
    /// Output file: .bt (OctoMap binary, max-likelihood) or .ot (full, log-odds).
    #[arg(long)]
    pub out: PathBuf,
}

/// `arc map info`
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// The map (.bt or .ot).
    pub file: PathBuf,
}

/// `arc map picture`
#[derive(Args, Debug)]
pub struct PictureArgs {
    /// The map (.bt or .ot); or give --scenario.
    #[arg(required_unless_present = "scenario", conflicts_with = "scenario")]
    pub file: Option<PathBuf>,
    /// A built-in scenario instead of a file (window, maze, silos, corridor or corridor:LENGTH).
    #[arg(long)]
    pub scenario: Option<String>,
    /// Output picture: .svg or .png.
    #[arg(long)]
    pub out: PathBuf,
    /// Lowest height of the top view's band (m); default: a quarter up the box.
    #[arg(long, allow_negative_numbers = true)]
    pub band_min: Option<f64>,
    /// Highest height of the top view's band (m); default: three quarters up the box.
    #[arg(long, allow_negative_numbers = true)]
    pub band_max: Option<f64>,
    /// Heights of the horizontal slices (m), comma-separated; default: 1/4, 1/2, 3/4 up.
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub slices: Vec<f64>,
}

/// Runs `arc map ...`.
pub fn run(c: MapCommand) -> CliResult {
    match c {
        MapCommand::Export(a) => export(a),
        MapCommand::Info(a) => info(a),
        MapCommand::Picture(a) => picture(a),
    }
}

fn scenario(name: &str) -> Result<Scenario, CliError> {
    scenarios::build(name).map_err(|e| CliError::input(format!("--scenario: {e}")))
}

fn read_tree(path: &Path) -> Result<OcTree, CliError> {
    OcTree::read_bt(path).map_err(|e| CliError::input(e.to_string()))
}

fn grid_of(tree: &OcTree, path: &Path) -> Result<Grid, CliError> {
    Grid::from_octree(tree, true).map_err(|e| CliError::input(format!("{}: {e}", path.display())))
}

/// The OctoMap file kinds `arc map export` writes.
#[derive(Clone, Copy)]
enum MapFormat {
    /// `.bt`: OctoMap's binary, max-likelihood format.
    Binary,
    /// `.ot`: OctoMap's full format, a log-odds value per node.
    Full,
}

/// The format `path`'s extension names, or a bad-input error naming the path.
fn map_format(path: &Path) -> Result<MapFormat, CliError> {
    let table = [("bt", MapFormat::Binary), ("ot", MapFormat::Full)];
    crate::fsutil::by_extension(path, &table).ok_or_else(|| {
        CliError::input(format!(
            "--out {}: a map file must end in .bt or .ot",
            path.display()
        ))
    })
}

fn export(a: ExportArgs) -> CliResult {
    // Refuse a wrong name before the work, not after.
    let format = map_format(&a.out)?;
    let s = scenario(&a.scenario)?;
    let tree = s.octree().map_err(|e| CliError::input(e.to_string()))?;
    match format {
        MapFormat::Binary => tree.write_bt(&a.out),
        MapFormat::Full => tree.write_ot(&a.out),
    }
    .map_err(|e| CliError::input(e.to_string()))?;
    let c = s.grid.counts();
    println!(
        "{}: wrote {} ({} x {} x {} voxels at {} m: {} occupied, {} free; {} tree nodes)",
        s.name,
        a.out.display(),
        s.grid.dims()[0],
        s.grid.dims()[1],
        s.grid.dims()[2],
        s.grid.resolution(),
        c.occupied,
        c.free,
        tree.node_count()
    );
    println!(
        "start ({:.2}, {:.2}, {:.2}) yaw {:.1} deg, goal ({:.2}, {:.2}, {:.2}), {} units",
        s.start[0],
        s.start[1],
        s.start[2],
        s.start_yaw.to_degrees(),
        s.goal[0],
        s.goal[1],
        s.goal[2],
        s.default_units
    );
    Ok(())
}

fn info(a: InfoArgs) -> CliResult {
    let t0 = Instant::now();
    let tree = read_tree(&a.file)?;
    let t1 = Instant::now();
    let grid = grid_of(&tree, &a.file)?;
    let t2 = Instant::now();
    let (lo, hi) = grid.bounds();
    let c = grid.counts();
    let d = grid.dims();
    let (occ_leaves, free_leaves) = tree.counts();
    println!("file        {}", a.file.display());
    println!("resolution  {} m", grid.resolution());
    println!(
        "bounds      ({:.3}, {:.3}, {:.3}) .. ({:.3}, {:.3}, {:.3}) m",
        lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
    );
    println!(
        "size        {:.2} x {:.2} x {:.2} m",
        hi[0] - lo[0],
        hi[1] - lo[1],
        hi[2] - lo[2]
    );
    println!(
        "voxels      {} x {} x {} = {}",
        d[0],
        d[1],
        d[2],
        d[0] * d[1] * d[2]
    );
    println!("occupied    {}", c.occupied);
    println!("free        {}", c.free);
    println!("unknown     {}", c.unknown);
    println!(
        "tree        {} nodes, {} occupied and {} free leaves",
        tree.node_count(),
        occ_leaves,
        free_leaves
    );
    println!(
        "timing      read {:.1} ms, grid {:.1} ms",
        (t1 - t0).as_secs_f64() * 1e3,
        (t2 - t1).as_secs_f64() * 1e3
    );
    Ok(())
}

fn picture(a: PictureArgs) -> CliResult {
    super::checks::picture("--out", &a.out)?;
    let (grid, sc, title) = match (&a.file, &a.scenario) {
        (Some(f), None) => {
            let tree = read_tree(f)?;
            (grid_of(&tree, f)?, None, format!("map {}", f.display()))
        }
        (None, Some(n)) => {
            let s = scenario(n)?;
            let t = format!("scenario {}: {} units", s.name, s.default_units);
            (s.grid.clone(), Some(s), t)
        }
        _ => {
            return Err(CliError::input(
                "give a map file or --scenario NAME, not both",
            ))
        }
    };
    let (lo, hi) = grid.bounds();
    let band = match (a.band_min, a.band_max) {
        (None, None) => None,
        (b0, b1) => {
            let h = hi[2] - lo[2];
            let b0 = b0.unwrap_or(lo[2] + 0.25 * h);
            let b1 = b1.unwrap_or(hi[2] - 0.25 * h);
            for (flag, v) in [("--band-min", b0), ("--band-max", b1)] {
                if !v.is_finite() {
                    return Err(super::checks::bad(flag, v, "a finite height (m)"));
                }
            }
            if b0 > b1 {
                return Err(super::checks::bad(
                    "--band-min",
                    b0,
                    &format!("at most --band-max {b1}"),
                ));
            }
            Some((b0, b1))
        }
    };
    if let Some(z) = a.slices.iter().find(|z| !z.is_finite()) {
        return Err(super::checks::bad("--slices", z, "finite heights (m)"));
    }
    let opts = MapPictureOptions {
        band,
        slices: a.slices.clone(),
        title,
    };
    let fig = map_figure(&grid, sc.as_ref(), &opts);
    fig.save(&a.out)
        .map_err(|e| CliError::input(e.to_string()))?;
    println!("wrote {}", a.out.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::CliResult;

    /// Runs `arc map` with `args`.
    fn map(args: &[&str]) -> CliResult {
        crate::run(["arc", "map"].iter().chain(args).copied())
    }

    #[test]
    fn export_info_picture_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let bt = dir.path().join("w.bt");
        let bt_s = bt.to_str().unwrap();
        map(&["export", "--scenario", "window", "--out", bt_s]).unwrap();
        map(&["info", bt_s]).unwrap();
        // A full .ot holds the same map.
        let ot = dir.path().join("w.ot");
        map(&[
            "export",
            "--scenario",
            "window",
            "--out",
            ot.to_str().unwrap(),
        ])
        .unwrap();
        let (from_ot, from_bt) = (
            aerial_chain::map::OcTree::read_bt(&ot).unwrap(),
            aerial_chain::map::OcTree::read_bt(&bt).unwrap(),
        );
        assert!(std::fs::read(&ot)
            .unwrap()
            .starts_with(b"# Octomap OcTree file\n"));
        assert_eq!(from_ot, from_bt);
        let svg = dir.path().join("w.svg");
        map(&[
            "picture",
            bt_s,
            "--out",
            svg.to_str().unwrap(),
            "--slices",
            "1.5",
        ])
        .unwrap();
        assert!(std::fs::read_to_string(&svg).unwrap().starts_with("<svg"));
        let svg2 = dir.path().join("c.svg");
        map(&[
            "picture",
            "--scenario",
            "corridor:12",
            "--out",
            svg2.to_str().unwrap(),
        ])
        .unwrap();
        assert!(svg2.exists());
    }

    #[test]
    fn bad_input_exits_with_2() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("x.bt");
        let out_s = out.to_str().unwrap();
        // A wrong file name: refused, naming the formats, and nothing is written.
        let txt = dir.path().join("x.txt");
        let txt_s = txt.to_str().unwrap();
        let e = map(&["export", "--scenario", "window", "--out", txt_s]).unwrap_err();
        assert_eq!(e.code, 2);
        assert!(e.message.contains(".bt or .ot"), "{}", e.message);
        assert!(!txt.exists(), "nothing written under a wrong name");
        // A file that is no octomap: the error names it.
        let junk = dir.path().join("junk.bt");
        std::fs::write(&junk, b"not an octomap").unwrap();
        let e = map(&["info", junk.to_str().unwrap()]).unwrap_err();
        assert_eq!(e.code, 2);
        assert!(e.message.contains("junk.bt"), "{}", e.message);
        let pic = dir.path().join("p.jpg");
        let svg = dir.path().join("p.svg");
        let cases: [&[&str]; 7] = [
            &["export", "--scenario", "nope", "--out", out_s],
            &["export", "--scenario", "corridor:500", "--out", out_s],
            &["info", "/nonexistent/map.bt"],
            &[
                "picture",
                "--scenario",
                "maze",
                "--out",
                pic.to_str().unwrap(),
            ],
            &["picture", "--out", "x.svg"],
            &[
                "picture",
                "--scenario",
                "maze",
                "--out",
                svg.to_str().unwrap(),
                "--band-min",
                "2",
                "--band-max",
                "1",
            ],
            &[
                "export",
                "--scenario",
                "maze",
                "--out",
                "/nonexistent-dir/x.bt",
            ],
        ];
        for args in cases {
            assert_eq!(map(args).unwrap_err().code, 2, "arc map {args:?}");
        }
    }
}
