//! `arc tables build|inspect` and `arc shapes`.

use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

use aerial_chain_core::kinematics::offsets;
use aerial_chain_core::lsc::library;
use aerial_chain_core::table::TableView;
use clap::{Args, Subcommand};

use super::checks;
use super::common::ChainArgs;
use super::{CliError, CliResult};
use aerial_chain::picture::{palette, Figure, Mark, Panel};
use aerial_chain::tables::{ShapeTables, TableSettings};

/// `arc tables ...`
#[derive(Subcommand, Debug)]
pub enum TablesCommand {
    /// Build the shape table of a chain (LSC, SRS, G_SRS) and write it atomically.
    #[command(
        after_help = "Example:\n  arc tables build --units 6 --srs 500 --seed 1 --out n6.arct"
    )]
    Build(BuildArgs),
    /// Check a table file and print its header, counts, LSC names and CRC verdict.
    #[command(after_help = "Example:\n  arc tables inspect n6.arct")]
    Inspect {
        /// The table file.
        file: PathBuf,
    },
}

/// `arc tables build`
#[derive(Args, Debug)]
pub struct BuildArgs {
    #[command(flatten)]
    chain: ChainArgs,
    /// Number of random shapes N_SRS.
    #[arg(long, default_value_t = 500)]
    srs: usize,
    /// Seed of the SRS sampler.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Roadmap radius r_S (C_T metric) [default: 1.8 N N_SRS^(-1/(2N-1))].
    #[arg(long)]
    r_s: Option<f32>,
    /// Output file.
    #[arg(long)]
    out: PathBuf,
}

/// `arc shapes`
#[derive(Args, Debug)]
#[command(after_help = "Example:\n  arc shapes --units 6 --out lsc.svg")]
pub struct ShapesArgs {
    #[command(flatten)]
    chain: ChainArgs,
    /// Output picture (.svg or .png).
    #[arg(long)]
    out: PathBuf,
}

/// Runs `arc tables ...`.
pub fn run(c: TablesCommand) -> CliResult {
    match c {
        TablesCommand::Build(a) => build(a),
        TablesCommand::Inspect { file } => inspect(&file),
    }
}

fn build(a: BuildArgs) -> CliResult {
    let params = a.chain.params(
        a.chain
            .units
            .ok_or_else(|| CliError::input("--units is required"))?,
    )?;
    checks::srs(a.srs)?;
    if let Some(r) = a.r_s {
        checks::positive("--r-s", r as f64)?;
    }
    let settings = TableSettings {
        srs: a.srs,
        seed: a.seed,
        r_s: a.r_s,
    };
    let started = std::time::Instant::now();
    let tables = with_progress(a.srs as u64, "sampling SRS", |progress| {
        ShapeTables::build(params, &settings, progress)
    })
    .map_err(|e| CliError::failed(e.to_string()))?;
    let len = tables
        .write(&a.out)
        .map_err(|e| CliError::input(e.to_string()))?;
    println!(
        "{}: N={} LSC={} SRS={} G_SRS edges={} size={} bytes, built in {:.3} s",
        a.out.display(),
        params.units,
        tables.lsc.len(),
        tables.srs.len(),
        tables.edge_count(),
        len,
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Runs `job` on a worker thread; shows a progress bar only if it takes over a second.
pub fn with_progress<T: Send>(
    total: u64,
    what: &str,
    job: impl FnOnce(&AtomicUsize) -> T + Send,
) -> T {
    let counter = AtomicUsize::new(0);
    std::thread::scope(|s| {
        let handle = s.spawn(|| job(&counter));
        let mut bar: Option<indicatif::ProgressBar> = None;
        let started = std::time::Instant::now();
        while !handle.is_finished() {
            std::thread::sleep(Duration::from_millis(50));
            if bar.is_none() && started.elapsed() > Duration::from_secs(1) {
                let b = indicatif::ProgressBar::new(total);
                b.set_style(
                    indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({eta})")
                        .expect("static template")
                        .progress_chars("=> "),
                );
                b.set_message(what.to_string());
                bar = Some(b);
            }
            if let Some(b) = &bar {
                b.set_position(counter.load(Ordering::Relaxed) as u64);
            }
        }
        if let Some(b) = bar {
            b.finish_and_clear();
        }
        handle
            .join()
            .unwrap_or_else(|p| std::panic::resume_unwind(p))
    })
}

fn inspect(file: &std::path::Path) -> CliResult {
    let bytes =
        std::fs::read(file).map_err(|e| CliError::input(format!("{}: {e}", file.display())))?;
    let view = TableView::open(&bytes, None)
        .map_err(|e| CliError::input(format!("{}: {e}", file.display())))?;
    let h = view.header();
    let p = h.params;
    println!(
        "{}: valid shape table, CRC-32 {:#010x} OK",
        file.display(),
        view.crc()
    );
    println!("  format version {}, {} bytes", h.version, bytes.len());
    println!(
        "  chain: N={} l={} m r_u={} m r_l={} m theta_max={:.1} deg beta_max={:.1} deg",
        p.units,
        p.link_length,
        p.unit_radius,
        p.link_radius,
        p.theta_max.to_degrees(),
        p.beta_max.to_degrees()
    );
    let names: Vec<&str> = (0..h.lsc_count as usize)
        .filter_map(|i| view.lsc(i).ok())
        .map(|e| e.kind.name())
        .collect();
    println!("  LSC ({}): {}", names.len(), names.join(" "));
    for (kind, why) in library(&p)
        .excluded
        .iter()
        .filter(|(k, _)| !names.contains(&k.name()))
    {
        println!("    {} left out: {why}", kind.name());
    }
    let mut edges = 0;
    view.for_each_adjacency(|_, nb| edges += nb.len())
        .map_err(|e| CliError::input(format!("{}: {e}", file.display())))?;
    println!(
        "  SRS: {} shapes, G_SRS: {} edges, max degree {}",
        h.srs_count,
        edges / 2,
        h.max_degree
    );
    Ok(())
}

/// Runs `arc shapes`: every LSC shape in top view (x-y) and side view (x-z).
pub fn run_shapes(a: ShapesArgs) -> CliResult {
    checks::picture("--out", &a.out)?;
    let params = a.chain.params(
        a.chain
            .units
            .ok_or_else(|| CliError::input("--units is required"))?,
    )?;
    let lib = library(&params);
    let cols = lib.entries.len().max(1);
    let (cw, ch) = (260.0, 250.0);
    let mut fig = Figure::new(
        cw * cols as f64,
        2.0 * ch + 50.0,
        &format!("Shape library (LSC), N = {}", params.units),
    );
    let r = params.reach() as f64 + params.unit_radius as f64;
    for (c, e) in lib.entries.iter().enumerate() {
        let p = offsets(&params, &e.shape);
        let pts: Vec<[f64; 3]> = p
            .iter()
            .take(params.n())
            .map(|q| [q.x as f64, q.y as f64, q.z as f64])
            .collect();
        for (row, (axes, label)) in [((0, 1), "y (m)"), ((0, 2), "z (m)")]
            .into_iter()
            .enumerate()
        {
            let view = if row == 0 { "top" } else { "side" };
            let mut panel = Panel::new(
                (c as f64 * cw, 26.0 + row as f64 * ch, cw, ch),
                (-r, -r / 2.0),
                (params.unit_radius as f64 * 2.0, r / 2.0),
                &format!("{} ({view})", e.kind.name()),
                ("x (m)", label),
            );
            let xy = |q: &[f64; 3]| (q[axes.0], q[axes.1]);
            for w in pts.windows(2) {
                panel.line(xy(&w[0]), xy(&w[1]), palette::INK, 2.0);
            }
            for (i, q) in pts.iter().enumerate() {
                let fill = if i == 0 { palette::START } else { palette::LSC };
                panel.circle(xy(q), params.unit_radius as f64, fill, palette::INK, 0.6);
            }
            if row == 0 {
                let headings: Vec<f64> = match &e.headings {
                    Some(h) => h.iter().take(params.n()).map(|&a| a as f64).collect(),
                    None => vec![e.shape.head_yaw() as f64],
                };
                for (q, h) in pts.iter().zip(headings) {
                    panel.arrow(xy(q), h, 0.3, palette::SENSOR);
                }
            }
            fig.add(panel);
        }
    }
    fig.legend(palette::START, "head (unit 1)");
    fig.legend(palette::LSC, "units");
    fig.legend_mark(Mark::Line, palette::SENSOR, "sensor heading");
    for (kind, why) in &lib.excluded {
        fig.legend(
            palette::UNKNOWN,
            &format!("{} left out: {why}", kind.name()),
        );
    }
    fig.save(&a.out)
        .map_err(|e| CliError::input(e.to_string()))?;
    println!("{}: {} shapes drawn", a.out.display(), lib.entries.len());
    Ok(())
}
