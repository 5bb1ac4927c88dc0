//! `arc bench paper`: the paper's Tables 1-3 on our `window` and `maze` scenarios.
//!
//! - Table 1 (Env 1, `window`): N = 4 and 5; the ARCplanner with library shapes only,
//!   random shapes only, and both; `M_VT = 1500`, `N_SRS = 500` (0 for LSC only).
//! - Table 2 (Env 2, `maze`): the same for N = 5 and 6.
//! - Table 3 (Env 1): the full-state lazy PRM with `M_F = 1500` and `15000` vertices
//!   against the ARCplanner (both shape sources; its runs are Table 1's, same batch).
//!
//! Every configuration runs for seeds `1..=K`.

use std::fmt::Write as _;

use super::{fmt_ms, ms, ArcMode, Budgets, Method, RunKey, RunSpec, Summary};

/// What to run.
#[derive(Clone, Debug, PartialEq)]
pub struct PaperOptions {
    /// Seeds, `M_VT`, `N_SRS` and the time limit of every run.
    pub budgets: Budgets,
    /// Vertex budgets `M_F` of the full-state PRM.
    pub prm_vertices: Vec<usize>,
    /// Chain sizes of Table 3 (window).
    pub prm_units: Vec<u8>,
    /// Which tables to run (1, 2, 3).
    pub tables: Vec<u8>,
    /// Also run Table 3 on `window-wide:W` for each of these `W` (the window widened to
    /// `W` x `W` m), where the full-state PRM can succeed.
    pub wide_windows: Vec<f64>,
}

impl PaperOptions {
    /// The paper's settings: 20 seeds, `M_VT = 1500`, `N_SRS = 500`, PRM with 1500 and
    /// 15000 vertices on N = 5 (and on windows widened to 1.0, 1.2, 1.4, 1.6 m), 60 s
    /// per run.
    pub fn full() -> Self {
        Self {
            budgets: Budgets::full(),
            prm_vertices: vec![1500, 15000],
            prm_units: vec![5],
            tables: vec![1, 2, 3],
            wide_windows: vec![1.0, 1.2, 1.4, 1.6],
        }
    }

    /// A smoke run: 2 seeds, small budgets, 2 s per run.
    pub fn quick() -> Self {
        Self {
            budgets: Budgets::quick(2),
            prm_vertices: vec![100, 300],
            prm_units: vec![4],
            tables: vec![1, 2, 3],
            wide_windows: vec![1.6],
        }
    }
}

/// The configurations of Tables 1 and 2: (table, scenario, N).
pub const ABLATION: [(&str, &str, u8); 4] = [
    ("table1", "window", 4),
    ("table1", "window", 5),
    ("table2", "maze", 5),
    ("table2", "maze", 6),
];

const MODES: [ArcMode; 4] = [ArcMode::Lsc, ArcMode::Srs, ArcMode::Both, ArcMode::Follow];

/// The ARCplanner's variants in Table 3: the paper's, and ours with follow-the-leader.
const TABLE3_ARC: [ArcMode; 2] = [ArcMode::Both, ArcMode::Follow];

/// Every run of the study: Tables 1 and 2 first, then Table 3's PRM runs.
pub fn specs(o: &PaperOptions) -> Vec<RunSpec> {
    let mut v = Vec::new();
    let table = |t: &str| {
        t.strip_prefix("table")
            .and_then(|n| n.parse::<u8>().ok())
            .is_some_and(|n| o.tables.contains(&n))
    };
    for (study, scenario, units) in ABLATION {
        if !table(study) {
            continue;
        }
        for mode in MODES {
            let b = &o.budgets;
            let srs = if mode == ArcMode::Lsc { 0 } else { b.srs };
            let key = RunKey::new(study, scenario, units, Method::Arc(mode), (b.vertices, srs));
            v.extend(b.runs(&key));
        }
    }
    if !o.tables.contains(&3) {
        return v;
    }
    for (study, scenario) in table3_scenarios(o) {
        for &units in &o.prm_units {
            // Table 3 compares against the full ARCplanner on the same problem: add its
            // runs when Table 1 does not have them.
            let in_table1 = scenario == "window"
                && o.tables.contains(&1)
                && ABLATION.contains(&("table1", "window", units));
            for mode in TABLE3_ARC.into_iter().filter(|_| !in_table1) {
                let budgets = (o.budgets.vertices, o.budgets.srs);
                let key = RunKey::new(study, &scenario, units, Method::Arc(mode), budgets);
                v.extend(o.budgets.runs(&key));
            }
            for &m in &o.prm_vertices {
                let key = RunKey::new(study, &scenario, units, Method::FullPrm, (m, 0));
                v.extend(o.budgets.runs(&key));
            }
        }
    }
    v
}

/// Table 3's (study, scenario) pairs: `window`, then `window-wide:W` for each `W` asked for.
pub fn table3_scenarios(o: &PaperOptions) -> Vec<(&'static str, String)> {
    let mut v = vec![("table3", "window".to_string())];
    for w in &o.wide_windows {
        v.push(("table3-wide", format!("{}{w}", super::WIDE_WINDOW)));
    }
    v
}

/// The paper's planning times `t_P` (s) for Tables 1 and 2: (scenario, N, `t_P` of
/// LSC, SRS and Both).
pub const PAPER_TP: [(&str, u8, [f64; 3]); 4] = [
    ("window", 4, [11.3, 23.0, 4.4]),
    ("window", 5, [46.1, 54.4, 4.4]),
    ("maze", 5, [1.5, 9.5, 1.27]),
    ("maze", 6, [32.7, 14.2, 7.9]),
];

/// The paper's head roadmap build times `t_GT` (s): Env 1 and Env 2.
pub const PAPER_TGT: [(&str, f64); 2] = [("window", 25.6), ("maze", 9.4)];

/// The paper's Table 3 rows: (label, `M_F` or 0 for the ARCplanner, t_G, t_P, success).
pub const PAPER_TABLE3: [(&str, usize, f64, f64, f64); 3] = [
    ("full-state PRM", 1500, 48.1, 20.8, 0.20),
    ("full-state PRM", 15000, 3712.8, 127.3, 1.00),
    ("ARCplanner", 0, 26.5, 15.4, 1.00),
];

fn paper_tp(scenario: &str, units: u8, mode: ArcMode) -> Option<f64> {
    let column = match mode {
        ArcMode::Lsc => 0,
        ArcMode::Srs => 1,
        ArcMode::Both => 2,
        ArcMode::Follow => return None,
    };
    PAPER_TP
        .iter()
        .find(|r| r.0 == scenario && r.1 == units)
        .map(|r| r.2[column])
}

fn find<'a>(
    sums: &'a [Summary],
    scenario: &str,
    units: u8,
    method: Method,
    vertices: Option<usize>,
) -> Option<&'a Summary> {
    sums.iter().find(|s| {
        let k = &s.key;
        k.scenario == scenario
            && k.units == units
            && k.method == method
            && vertices.is_none_or(|v| k.vertices == v)
    })
}

/// The speed-up of the ARCplanner over the full-state PRM for one chain size.
#[derive(Clone, Debug, PartialEq)]
pub struct Speedup {
    /// Scenario.
    pub scenario: String,
    /// The ARCplanner's variant.
    pub arc: ArcMode,
    /// N.
    pub units: u8,
    /// The PRM budget with the best success rate (the smaller on ties).
    pub prm_vertices: usize,
    /// Its success rate.
    pub prm_success: f64,
    /// The ARCplanner's success rate.
    pub arc_success: f64,
    /// Median build + query time of the PRM (all runs, s).
    pub prm_total_s: f64,
    /// The same for the ARCplanner (s).
    pub arc_total_s: f64,
    /// `prm_total_s / arc_total_s`.
    pub ratio: f64,
    /// Median build + query time of the PRM's successful runs (s), if any.
    pub prm_success_total_s: Option<f64>,
    /// Median CPU time of build + query of the PRM (all runs, s; NaN if unmeasured).
    pub prm_total_cpu_s: f64,
    /// The same for the ARCplanner.
    pub arc_total_cpu_s: f64,
    /// Whether some PRM runs were stopped by the time limit (so its times are lower
    /// bounds).
    pub prm_capped: bool,
}

/// Speed-ups for every Table 3 chain size.
pub fn speedups(sums: &[Summary], o: &PaperOptions) -> Vec<Speedup> {
    let mut out = Vec::new();
    for (((_, scenario), &units), mode) in table3_scenarios(o)
        .iter()
        .flat_map(|sc| o.prm_units.iter().map(move |u| (sc, u)))
        .flat_map(|x| TABLE3_ARC.into_iter().map(move |m| (x, m)))
    {
        let arc = find(sums, scenario, units, Method::Arc(mode), None);
        let prm = sums
            .iter()
            .filter(|s| {
                let k = &s.key;
                &k.scenario == scenario && k.units == units && k.method == Method::FullPrm
            })
            .max_by(|a, b| {
                a.success_rate()
                    .total_cmp(&b.success_rate())
                    .then(b.key.vertices.cmp(&a.key.vertices))
            });
        if let (Some(a), Some(p)) = (arc, prm) {
            let ok_total = (p.successes > 0).then_some(p.total_ok.median);
            out.push(Speedup {
                scenario: scenario.clone(),
                arc: mode,
                units,
                prm_vertices: p.key.vertices,
                prm_success: p.success_rate(),
                arc_success: a.success_rate(),
                prm_total_s: p.total_all.median,
                arc_total_s: a.total_all.median,
                ratio: p.total_all.median / a.total_all.median,
                prm_success_total_s: ok_total,
                prm_total_cpu_s: p.total_cpu_all.median,
                arc_total_cpu_s: a.total_cpu_all.median,
                prm_capped: p.time_limited > 0 || p.runs == 0,
            });
        }
    }
    out
}

fn pct(x: f64) -> String {
    format!("{:.0}%", 100.0 * x)
}

/// The markdown report; `meta` is printed under the title (machine, threads, ...).
pub fn markdown(sums: &[Summary], o: &PaperOptions, meta: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# ARC benchmark: the paper's evaluation (Tables 1-3)\n");
    let _ = writeln!(s, "{meta}\n");
    let _ = writeln!(
        s,
        "Paper times are seconds (Gazebo/ROS, 2020 hardware); ours are milliseconds, wall-clock per run. \
         `t_G`: roadmap build, all runs; `t_P`: query time of the successful runs; spreads are \
         median [first-third quartile]; shape changes median [min-max]. `verified`: successful \
         plans that pass the exact checker (`arc verify`).\n"
    );
    ablation_tables(&mut s, sums, o);
    table3(&mut s, sums, o);
    speedup_lines(&mut s, sums, o);
    profile_table(&mut s, sums);
    s
}

/// Tables 1 and 2: the ablation (LSC, SRS, both) per chain size, paper beside ours.
fn ablation_tables(s: &mut String, sums: &[Summary], o: &PaperOptions) {
    for (table, scenario, title) in [
        (
            "table1",
            "window",
            "Table 1: Environment 1, room with a window (`window`)",
        ),
        (
            "table2",
            "maze",
            "Table 2: Environment 2, maze-like room (`maze`)",
        ),
    ] {
        let _ = writeln!(
            s,
            "## {title}\n\nM_VT = {}, N_SRS = {} (0 for LSC only), {} seeds, time limit {} s per run. \
             Paper: t_GT = {} s.\n",
            o.budgets.vertices,
            o.budgets.srs,
            o.budgets.seeds,
            o.budgets.time_limit_text(),
            PAPER_TGT
                .iter()
                .find(|r| r.0 == scenario)
                .map_or(f64::NAN, |r| r.1)
        );
        let _ = writeln!(
            s,
            "| N | shapes | paper t_P (s) | success | verified | t_G (ms) | t_P (ms) | t_P CPU (ms) | shape changes | replans | SRS table build (ms) |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|");
        for (t, sc, units) in super::paper::ABLATION {
            if t != table {
                continue;
            }
            for mode in MODES {
                let Some(g) = find(sums, sc, units, Method::Arc(mode), None) else {
                    continue;
                };
                let _ = writeln!(
                    s,
                    "| {units} | {} | {} | {} | {} |",
                    mode.name(),
                    paper_tp(sc, units, mode).map_or("-".into(), |x| x.to_string()),
                    g.outcome_cells(),
                    if mode == ArcMode::Lsc {
                        "-".into()
                    } else {
                        fmt_ms(g.tables.median)
                    }
                );
            }
        }
        s.push('\n');
    }
}

/// Table 3: the full-state PRM against the ARCplanner, paper beside ours.
fn table3(s: &mut String, sums: &[Summary], o: &PaperOptions) {
    let _ = writeln!(
        s,
        "## Table 3: full-state lazy PRM against the ARCplanner\n\n\
         Same batch, same machine, same collision checks and edge semantics. Time limit {} s per \
         run (the PRM's roadmap build and its query are each capped by it; a capped run counts \
         as a failure and its time as spent). `window` is Table 1's room (0.8 m x 0.8 m window); \
         `{}W` is the same room with the window widened to W x W m (bench-only variant), \
         where the full-state PRM can pass.\n",
        o.budgets.time_limit_text(),
        super::WIDE_WINDOW
    );
    let _ = writeln!(
        s,
        "| scenario | N | planner | budget | paper t_G (s) | paper t_P (s) | paper success | success | verified | t_G (ms) | t_P (ms), successful | t_P (ms), all runs | t_G + t_P CPU (ms), all runs | time-limited |"
    );
    let _ = writeln!(
        s,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    let num = |x: f64| {
        if x.is_nan() {
            "-".to_string()
        } else {
            x.to_string()
        }
    };
    for (_, scenario) in table3_scenarios(o) {
        for &units in &o.prm_units {
            let mut rows: Vec<(&Summary, (f64, f64, f64))> = Vec::new();
            for &m in &o.prm_vertices {
                if let Some(g) = find(sums, &scenario, units, Method::FullPrm, Some(m)) {
                    let p = PAPER_TABLE3
                        .iter()
                        .find(|r| r.1 == m)
                        .map_or((f64::NAN, f64::NAN, f64::NAN), |r| (r.2, r.3, r.4));
                    rows.push((g, p));
                }
            }
            for mode in TABLE3_ARC {
                if let Some(g) = find(sums, &scenario, units, Method::Arc(mode), None) {
                    let r = PAPER_TABLE3[2];
                    let nan = (f64::NAN, f64::NAN, f64::NAN);
                    rows.push((
                        g,
                        if mode == ArcMode::Both {
                            (r.2, r.3, r.4)
                        } else {
                            nan
                        },
                    ));
                }
            }
            for (g, p) in rows {
                let (name, budget) = match g.key.method {
                    Method::FullPrm => ("full-state PRM", format!("M_F = {}", g.key.vertices)),
                    Method::Arc(ArcMode::Follow) => (
                        "ARCplanner + follow",
                        format!("M_VT = {}, N_SRS = {}", g.key.vertices, g.key.srs),
                    ),
                    Method::Arc(_) => (
                        "ARCplanner",
                        format!("M_VT = {}, N_SRS = {}", g.key.vertices, g.key.srs),
                    ),
                };
                let _ = writeln!(
                    s,
                    "| {scenario} | {units} | {name} | {budget} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    num(p.0),
                    num(p.1),
                    if p.2.is_nan() { "-".into() } else { pct(p.2) },
                    g.success_cells(),
                    ms(&g.roadmap),
                    ms(&g.planning),
                    ms(&g.planning_all),
                    ms(&g.total_cpu_all),
                    g.time_limited
                );
            }
        }
    }
    s.push('\n');
}

/// One line per scenario and chain size: how much faster the ARCplanner is.
fn speedup_lines(s: &mut String, sums: &[Summary], o: &PaperOptions) {
    for sp in speedups(sums, o) {
        let head = format!(
            "**{}, N = {}, {}:** the full-state PRM's best success rate is {} (M_F = {}), the ARCplanner's {}.",
            sp.scenario,
            sp.units,
            sp.arc.name(),
            pct(sp.prm_success),
            sp.prm_vertices,
            pct(sp.arc_success)
        );
        let body = match sp.prm_success_total_s {
            Some(t) => format!(
                " Median build + query: PRM {} ms over all its runs ({} ms over its successful runs){}, \
                 ARCplanner {} ms: the ARCplanner is **{:.0}x** faster ({:.0}x against the PRM's \
                 successful runs). In CPU time: PRM {} ms, ARCplanner {} ms, **{:.0}x**.",
                fmt_ms(sp.prm_total_s),
                fmt_ms(t),
                if sp.prm_capped { ", some runs cut by the time limit" } else { "" },
                fmt_ms(sp.arc_total_s),
                sp.ratio,
                t / sp.arc_total_s,
                fmt_ms(sp.prm_total_cpu_s),
                fmt_ms(sp.arc_total_cpu_s),
                sp.prm_total_cpu_s / sp.arc_total_cpu_s
            ),
            None => format!(
                " The PRM solved none of its runs, so there is no speed-up to state: it spent a \
                 median {} ms (build + query) before giving up{}, the ARCplanner {} ms to solve.",
                fmt_ms(sp.prm_total_s),
                if sp.prm_capped { " or being cut by the time limit" } else { "" },
                fmt_ms(sp.arc_total_s)
            ),
        };
        let _ = writeln!(s, "{head}{body}\n");
    }
}

/// Where the ARCplanner's time goes: collision checks against the rest of the query.
fn profile_table(s: &mut String, sums: &[Summary]) {
    let _ = writeln!(
        s,
        "## Profile: where the ARCplanner's time goes (successful runs, medians)\n\n\
         `collision` is the time in full-chain collision checks inside the query (placement, \
         translation, shape change); `search` is the rest of the query: the head's lazy route \
         (its own sphere checks included), candidate ordering, G_Val, SRSConnect's graph search.\n"
    );
    let _ = writeln!(
        s,
        "| scenario | N | shapes | t_G (ms) | t_P (ms) | collision (ms) | search (ms) | collision share |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    for g in sums
        .iter()
        .filter(|g| matches!(g.key.method, Method::Arc(_)))
    {
        let share = g.collision.median / (g.collision.median + g.search.median);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            g.key.scenario,
            g.key.units,
            g.key.method.label(),
            fmt_ms(g.roadmap.median),
            if g.planning.n > 0 {
                fmt_ms(g.planning.median)
            } else {
                "-".into()
            },
            if g.collision.n > 0 {
                fmt_ms(g.collision.median)
            } else {
                "-".into()
            },
            if g.search.n > 0 {
                fmt_ms(g.search.median)
            } else {
                "-".into()
            },
            if share.is_finite() {
                pct(share)
            } else {
                "-".into()
            }
        );
    }
}
