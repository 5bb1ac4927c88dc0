//! Benchmark reports: runs and summaries as CSV, times and counts for markdown tables,
//! and writing them into the output directory.

use std::fmt::Write as _;

use super::{RunKey, RunResult, Spread, StudyError, Summary};

pub(super) fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// A column of a table of `T`s: its name and a row's cell.
pub(super) type Column<T> = (&'static str, fn(&T) -> String);

/// `rows` as CSV, under a line of the column names.
pub(super) fn csv_table<T>(columns: &[Column<T>], rows: &[T]) -> String {
    let names: Vec<&str> = columns.iter().map(|(name, _)| *name).collect();
    let mut out = names.join(",") + "\n";
    for r in rows {
        let cells: Vec<String> = columns.iter().map(|(_, cell)| cell(r)).collect();
        out += &cells.join(",");
        out.push('\n');
    }
    out
}

/// `rows` as a markdown table: the column names, the separator line, a line a row.
pub(super) fn markdown_table<T>(columns: &[Column<T>], rows: &[&T]) -> String {
    let line = |cells: Vec<String>| format!("| {} |\n", cells.join(" | "));
    let mut out = line(columns.iter().map(|(name, _)| name.to_string()).collect());
    out += &format!("|{}\n", "---|".repeat(columns.len()));
    for r in rows {
        out += &line(columns.iter().map(|(_, cell)| cell(r)).collect());
    }
    out
}

/// The table of the `rows` that `kept` does not keep under the line `title`, or
/// nothing where it keeps every one.
pub(super) fn missed<T>(
    title: &str,
    columns: &[Column<T>],
    rows: &[T],
    kept: fn(&T) -> bool,
) -> String {
    let missed: Vec<&T> = rows.iter().filter(|r| !kept(r)).collect();
    match missed.is_empty() {
        true => String::new(),
        false => format!("\n{title}:\n\n{}", markdown_table(columns, &missed)),
    }
}

fn opt<T: ToString>(v: Option<T>) -> String {
    v.map(|x| x.to_string()).unwrap_or_default()
}

/// The columns `study,scenario,units,method,vertices,srs` of both CSV files.
fn key_cells(k: &RunKey) -> String {
    let (study, scenario) = (csv_field(&k.study), csv_field(&k.scenario));
    let (units, method) = (k.units, k.method.label());
    format!(
        "{study},{scenario},{units},{method},{},{}",
        k.vertices, k.srs
    )
}

/// One line per run.
pub fn runs_csv(results: &[RunResult]) -> String {
    let mut s = String::from(
        "study,scenario,units,method,vertices,srs,seed,time_limit_s,start_x,start_y,start_z,success,outcome,\
         tables_s,roadmap_s,planning_s,roadmap_cpu_s,planning_cpu_s,collision_s,search_s,shape_changes,edges,replans,srs_connects,\
         iterations,collision_checks,roadmap_vertices,build_capped,waypoints,verified,post_s,openings,\
         regions_s,head_roadmap_s,lattice_s,shape_search_s,message\n",
    );
    for r in results {
        let p = &r.spec;
        let start = p.query.map(|q| q.start);
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{:.6},{:.6},{:.6},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            key_cells(&p.key),
            p.seed,
            opt(p.time_limit),
            opt(start.map(|s| s[0])),
            opt(start.map(|s| s[1])),
            opt(start.map(|s| s[2])),
            r.success,
            r.outcome,
            r.tables_s,
            r.roadmap_s,
            r.planning_s,
            opt(r.roadmap_cpu_s.map(|x| format!("{x:.6}"))),
            opt(r.planning_cpu_s.map(|x| format!("{x:.6}"))),
            opt(r.collision_s.map(|x| format!("{x:.6}"))),
            opt(r.search_s.map(|x| format!("{x:.6}"))),
            opt(r.shape_changes),
            opt(r.edges),
            opt(r.replans),
            opt(r.srs_connects),
            opt(r.iterations),
            opt(r.collision_checks),
            r.roadmap_vertices,
            r.build_capped,
            opt(r.waypoints),
            opt(r.verified),
            opt(r.passage.as_ref().map(|p| format!("{:.6}", p.post_s))),
            r.passage.as_ref().map_or(String::new(), openings_cell),
            r.phases.map_or(",,,".into(), |p| format!(
                "{:.6},{:.6},{:.6},{:.6}",
                p.regions_s, p.roadmap_s, p.lattice_s, p.shapes_s
            )),
            csv_field(&r.message)
        );
    }
    s
}

/// Per opening of a `passage:` instance: `name:width:target:raw:post` (m), joined by
/// spaces.
fn openings_cell(p: &super::PassageResult) -> String {
    p.openings
        .iter()
        .map(|(r, q)| {
            format!(
                "{}:{:.3}:{:.4}:{:.4}:{:.4}",
                r.name, r.width, r.target, r.clearance, q.clearance
            )
        })
        .collect::<Vec<_>>()
        .join(" ")
}

fn spread_cols(s: &Spread) -> String {
    format!(
        "{:.6},{:.6},{:.6},{:.6},{:.6}",
        s.median, s.q1, s.q3, s.min, s.max
    )
}

/// The spreads of the summary CSV, in column order: the name and where it is.
type SpreadColumn = (&'static str, fn(&Summary) -> &Spread);

const SPREAD_COLUMNS: [SpreadColumn; 10] = [
    ("roadmap_s", |g| &g.roadmap),
    ("planning_s", |g| &g.planning),
    ("planning_all_s", |g| &g.planning_all),
    ("total_all_s", |g| &g.total_all),
    ("roadmap_cpu_s", |g| &g.roadmap_cpu),
    ("planning_cpu_s", |g| &g.planning_cpu),
    ("total_cpu_all_s", |g| &g.total_cpu_all),
    ("collision_s", |g| &g.collision),
    ("search_s", |g| &g.search),
    ("shape_changes", |g| &g.shape_changes),
];

/// One line per group.
pub fn summary_csv(sums: &[Summary]) -> String {
    let mut s = String::from("study,scenario,units,method,vertices,srs,time_limit_s,runs,successes,success_rate,verified,time_limited");
    for (name, _) in SPREAD_COLUMNS {
        for q in ["median", "q1", "q3", "min", "max"] {
            let _ = write!(s, ",{name}_{q}");
        }
    }
    s.push('\n');
    for g in sums {
        let (key, limit) = (key_cells(&g.key), opt(g.time_limit));
        let (runs, ok, rate) = (g.runs, g.successes, g.success_rate());
        let _ = write!(
            s,
            "{key},{limit},{runs},{ok},{rate:.3},{},{}",
            g.verified, g.time_limited
        );
        for (_, spread) in SPREAD_COLUMNS {
            let _ = write!(s, ",{}", spread_cols(spread(g)));
        }
        s.push('\n');
    }
    s
}

/// `median [q1-q3]` in milliseconds, or `-` without values.
pub fn ms(s: &Spread) -> String {
    if s.n == 0 {
        "-".into()
    } else {
        format!("{} [{}-{}]", fmt_ms(s.median), fmt_ms(s.q1), fmt_ms(s.q3))
    }
}

/// A duration in milliseconds with 3 significant digits.
pub fn fmt_ms(sec: f64) -> String {
    let m = sec * 1e3;
    if m >= 100.0 {
        format!("{m:.0}")
    } else if m >= 10.0 {
        format!("{m:.1}")
    } else {
        format!("{m:.2}")
    }
}

/// `median [min-max]` of a count, or `-`.
pub fn count(s: &Spread) -> String {
    if s.n == 0 {
        "-".into()
    } else {
        format!("{} [{}-{}]", s.median, s.min, s.max)
    }
}

/// Writes `name` under `dir` atomically (creating `dir`).
pub fn write_out(
    dir: &std::path::Path,
    name: &str,
    bytes: &[u8],
) -> Result<std::path::PathBuf, StudyError> {
    let failed = |path: &std::path::Path| {
        let path = path.to_path_buf();
        move |source| StudyError::Write { path, source }
    };
    std::fs::create_dir_all(dir).map_err(failed(dir))?;
    let p = dir.join(name);
    crate::fsutil::write_atomic(&p, bytes).map_err(failed(&p))?;
    Ok(p)
}
