//! `arc bench scale`: the ARCplanner's planning time and success against the number of
//! units N (scenario `window`) and against the map's size (`corridor:L`).
//!
//! Starts: a chain longer than about 11 links does not fit at `window`'s start as a
//! straight line (the first room is 5.6 m wide), so every N gets its start from
//! [`super::fitting_query`]: the scenario's start and LI when it fits, else the first
//! library shape and heading (then the nearest head position within 1.5 m) that does.
//! The chosen start is listed in the report. The goal is always the scenario's.
//!
//! Map size: `corridor:L` keeps its cross-section and door spacing and grows in length,
//! so the head roadmap keeps its density when `M_VT` grows with `L`
//! ([`ScaleOptions::corridor_vertices_per_m`]); a fixed `M_VT` is also possible.

use std::fmt::Write as _;

use aerial_chain::picture::{palette, Colour};
use aerial_chain::planner::Phases;
use aerial_chain_core::lsc::library;

use super::plot::{self, Chart, Curve};
use super::statistics::nearest_rank;
use super::{
    fitting_query, ArcMode, Budgets, Envs, Method, Query, RunKey, RunResult, RunSpec, StudyError,
    Summary,
};

/// What to run.
#[derive(Clone, Debug, PartialEq)]
pub struct ScaleOptions {
    /// Seeds, `M_VT` (for `window`), `N_SRS` and the time limit of every run.
    pub budgets: Budgets,
    /// Chain sizes for `window`.
    pub units: Vec<u8>,
    /// Corridor lengths (m).
    pub lengths: Vec<f64>,
    /// Chain size in the corridors.
    pub corridor_units: u8,
    /// Head roadmap vertices per metre of corridor (`None`: `vertices` for every length).
    pub corridor_vertices_per_m: Option<f64>,
}

impl ScaleOptions {
    /// The full study: N = 3..16, corridors 10..100 m every 10 m, 20 seeds,
    /// `M_VT = 1500` in `window` and 100 vertices per metre of corridor (2000 in the
    /// default 20 m corridor), `N_SRS = 500`, 60 s per run.
    pub fn full() -> Self {
        Self {
            budgets: Budgets::full(),
            units: (3..=16).collect(),
            lengths: (1..=10).map(|k| 10.0 * k as f64).collect(),
            corridor_units: 5,
            corridor_vertices_per_m: Some(100.0),
        }
    }

    /// A smoke run: two sizes, two corridors, one seed, small budgets.
    pub fn quick() -> Self {
        Self {
            budgets: Budgets::quick(1),
            units: vec![3, 4],
            lengths: vec![10.0, 20.0],
            corridor_units: 4,
            corridor_vertices_per_m: Some(30.0),
        }
    }

    fn corridor_vertices(&self, l: f64) -> usize {
        match self.corridor_vertices_per_m {
            Some(d) => (d * l).round().max(1.0) as usize,
            None => self.budgets.vertices,
        }
    }
}

/// The scenario name of a corridor of `l` metres.
pub fn corridor_name(l: f64) -> String {
    format!("corridor:{l}")
}

/// The start chosen for one N: N, the query, the library shape's name.
pub type StartChoice = (u8, Query, String);

/// Every run of the study (N first, then the corridors), and the start chosen per N.
pub fn specs(o: &ScaleOptions) -> Result<(Vec<RunSpec>, Vec<StartChoice>), StudyError> {
    let (follow, b) = (Method::Arc(ArcMode::Follow), &o.budgets);
    let by_units = |n| RunKey::new("scale-units", "window", n, follow, (b.vertices, b.srs));
    let window = vec![by_units(3).run(1, b.time_limit)];
    let envs = Envs::for_specs(&window)?;
    let env = envs
        .get("window")
        .ok_or_else(|| StudyError::NotBuilt("window".into()))?;
    let mut v = Vec::new();
    let mut starts = Vec::new();
    for &n in &o.units {
        let ctx = super::context(env, n)?;
        let q = fitting_query(&env.scenario, &ctx)?;
        let lib = library(ctx.params());
        let name = lib
            .entries
            .iter()
            .find(|e| {
                let d =
                    aerial_chain_core::angle::diff(e.shape.head_yaw(), q.start_shape.head_yaw());
                e.shape.rotated(d).max_angle_diff(&q.start_shape) < 1e-5
            })
            .map_or("?", |e| e.kind.name());
        starts.push((n, q, name.to_string()));
        let key = by_units(n);
        v.extend(b.runs(&key).map(|r| RunSpec {
            query: Some(q),
            ..r
        }));
    }
    for &l in &o.lengths {
        let (name, budgets) = (corridor_name(l), (o.corridor_vertices(l), b.srs));
        let key = RunKey::new("scale-map", &name, o.corridor_units, follow, budgets);
        v.extend(b.runs(&key));
    }
    Ok((v, starts))
}

fn corridor_length(s: &Summary) -> f64 {
    s.key
        .scenario
        .strip_prefix("corridor:")
        .and_then(|l| l.parse().ok())
        .unwrap_or(f64::NAN)
}

/// The markdown report.
pub fn markdown(
    sums: &[Summary],
    results: &[RunResult],
    o: &ScaleOptions,
    starts: &[StartChoice],
    meta: &str,
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# ARC benchmark: scaling\n\n{meta}\n");
    let _ = writeln!(
        s,
        "The full ARCplanner (LSC and SRS), N_SRS = {}, {} seeds per row, time limit {} s per run. \
         Times in ms, median [first-third quartile]; `t_P` over successful runs. `t_G` is the \
         planner's setup before the query: with the head lattice (the default) it builds nothing, and \
         the labelled regions and the uniform roadmap a query needs are built, and timed, in `t_P`.\n",
        o.budgets.srs,
        o.budgets.seeds,
        o.budgets.time_limit_text()
    );
    let _ = writeln!(
        s,
        "## Against the number of units (`window`, M_VT = {})\n\n\
         Start: the scenario's (2.0, 4.5, 1.5) with LI at 90 deg where that fits; otherwise the first \
         library shape, heading (90 deg + k 45 deg) and head position (0.1 m lattice, nearest first) \
         that is valid. Goal: (6.6, 3.0, 1.5), tolerance 0.3 m.\n",
        o.budgets.vertices
    );
    let _ = writeln!(
        s,
        "| N | start (m) | start shape, yaw (deg) | success | verified | t_G (ms) | t_P (ms) | t_P CPU (ms) | shape changes | replans | time-limited |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|");
    for g in sums.iter().filter(|g| g.key.study == "scale-units") {
        let st = starts.iter().find(|x| x.0 == g.key.units);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} |",
            g.key.units,
            st.map_or("-".into(), |x| format!(
                "({:.1}, {:.1}, {:.1})",
                x.1.start[0], x.1.start[1], x.1.start[2]
            )),
            st.map_or("-".into(), |x| format!(
                "{}, {:.0}",
                x.2,
                (x.1.start_shape.head_yaw() as f64).to_degrees()
            )),
            g.outcome_cells(),
            g.time_limited
        );
    }
    let _ = writeln!(
        s,
        "\n## Against the map's size (`corridor:L`, N = {}, M_VT = {})\n",
        o.corridor_units,
        match o.corridor_vertices_per_m {
            Some(d) => format!("{d} per metre of corridor"),
            None => o.budgets.vertices.to_string(),
        }
    );
    let _ = writeln!(
        s,
        "| L (m) | M_VT | success | verified | t_G (ms) | t_P (ms) | t_P CPU (ms) | shape changes | replans | time-limited |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for g in sums.iter().filter(|g| g.key.study == "scale-map") {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} |",
            corridor_length(g),
            g.key.vertices,
            g.outcome_cells(),
            g.time_limited
        );
    }
    s += &phases_table(results);
    s
}

/// Where the queries' time went, per row of both studies: the median over successful
/// runs of each phase `arc plan` reports (ms).
fn phases_table(results: &[RunResult]) -> String {
    let mut s = String::from(
        "\n## Where the query's time goes\n\nMedians over successful runs (ms), the phases `arc plan` prints.\n\n\
         | study | row | free regions | head roadmap | head route (lattice) | shape search |\n|---|---|---|---|---|---|\n",
    );
    // Rows in the order their first run comes.
    let mut rows: Vec<(String, String)> = Vec::new();
    for r in results {
        let row = (r.spec.key.study.clone(), row_name(r));
        if !rows.contains(&row) {
            rows.push(row);
        }
    }
    for (study, row) in rows {
        let at: Vec<Phases> = results
            .iter()
            .filter(|r| r.spec.key.study == study && row_name(r) == row)
            .filter_map(|r| r.phases)
            .collect();
        let med = |f: fn(&Phases) -> f64| {
            let v: Vec<f64> = at.iter().map(f).collect();
            nearest_rank(&v, 0.5) * 1e3
        };
        let _ = writeln!(
            s,
            "| {study} | {row} | {:.2} | {:.2} | {:.2} | {:.2} |",
            med(|p| p.regions_s),
            med(|p| p.roadmap_s),
            med(|p| p.lattice_s),
            med(|p| p.shapes_s)
        );
    }
    s
}

/// A row of the phases table: `N = n` for the units study, the corridor otherwise.
fn row_name(r: &RunResult) -> String {
    match r.spec.key.study.as_str() {
        "scale-units" => format!("N = {}", r.spec.key.units),
        _ => r.spec.key.scenario.clone(),
    }
}

const BLUE: Colour = palette::PATH;
const ORANGE: Colour = palette::GOAL;
const GREEN: Colour = palette::LSC;

/// The figure: time and success against N (left) and against corridor length (right).
pub fn figure(sums: &[Summary], corridor_units: u8) -> String {
    let by_n: Vec<&Summary> = sums
        .iter()
        .filter(|g| g.key.study == "scale-units")
        .collect();
    let by_l: Vec<&Summary> = sums.iter().filter(|g| g.key.study == "scale-map").collect();
    let n = |g: &Summary| g.key.units as f64;
    let times = |v: &[&Summary]| {
        v.iter()
            .flat_map(|g| [g.planning.q3, g.roadmap.q3, g.planning.q1, g.roadmap.q1])
            .filter(|x| x.is_finite() && *x > 0.0)
            .map(|x| x * 1e3)
            .fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)))
    };
    let range = |r: (f64, f64)| {
        if r.0.is_finite() && r.1 > 0.0 {
            (r.0 / 2.0, r.1 * 2.0)
        } else {
            (0.1, 1000.0)
        }
    };
    let time_chart =
        |title: String, x_label: &str, v: &[&Summary], x: &dyn Fn(&Summary) -> f64| Chart {
            title,
            x_label: x_label.into(),
            y_label: "ms".into(),
            log_y: true,
            y_range: range(times(v)),
            curves: vec![
                Curve {
                    label: "t_P, query (successful runs)".into(),
                    colour: BLUE,
                    points: plot::planning_ms(v, x),
                },
                Curve {
                    label: "t_G, setup (the queries build what they need)".into(),
                    colour: ORANGE,
                    points: plot::roadmap_ms(v, x),
                },
            ],
        };
    let success_chart =
        |title: &str, x_label: &str, v: &[&Summary], x: &dyn Fn(&Summary) -> f64| Chart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: "success (%)".into(),
            log_y: false,
            y_range: (0.0, 105.0),
            curves: vec![Curve {
                label: "success".into(),
                colour: GREEN,
                points: plot::success_pct(v, x),
            }],
        };
    let charts = vec![
        time_chart(
            "window: time against N (median, IQR)".into(),
            "units N",
            &by_n,
            &n,
        ),
        time_chart(
            format!("corridor:L: time against length (N = {corridor_units})"),
            "corridor length L (m)",
            &by_l,
            &corridor_length,
        ),
        success_chart("window: success against N", "units N", &by_n, &n),
        success_chart(
            "corridor:L: success against length",
            "corridor length L (m)",
            &by_l,
            &corridor_length,
        ),
    ];
    plot::svg(&charts, 2, 2, (1200, 800))
}
