//! `arc bench robust`: the ARCplanner with `arc plan`'s defaults on random instances of
//! the hard-case family ([`aerial_chain::problem::passages`]), N = 4..8.
//!
//! Each instance is drawn from a seeded generator; it is kept only when its witness
//! (follow-the-leader along the hand-made centre line, checked by the exact verifier,
//! no planner involved) proves it solvable for its N, and redrawn otherwise; the count
//! of redraws is reported. Every plan is verified exactly. Maps are built in chunks so
//! that memory stays bounded.

use rand::{Rng, SeedableRng};

use super::statistics::nearest_rank;
use super::{plot, run_all, ArcMode, Envs, Method, RunKey, RunResult, RunSpec, Spread, StudyError};
use aerial_chain::problem::passages::PassageSpec;
use aerial_chain::witness::witness;

/// Which instances of the family the study draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// Windows, tunnels and doors ([`PassageSpec::random`]).
    Openings,
    /// A window, then a door far to the side ([`PassageSpec::random_turn`]).
    Turns,
}

impl Family {
    /// One random instance.
    fn draw(self, rng: &mut rand_pcg::Pcg64) -> PassageSpec {
        match self {
            Family::Openings => PassageSpec::random(rng),
            Family::Turns => PassageSpec::random_turn(rng),
        }
    }

    /// The study's name, and the stem of its files.
    pub fn stem(self) -> &'static str {
        match self {
            Family::Openings => "robust",
            Family::Turns => "turns",
        }
    }

    /// The title and what the instances are, for the markdown.
    fn words(self) -> (&'static str, &'static str) {
        match self {
            Family::Openings => (
                "Robustness: the hard-case family (`arc bench robust`)",
                "windows 0.45-0.6 m in walls of 0.1-0.3 m, or one in five a tunnel 0.5-0.6 m square and 0.6-1.5 m long; approach 0-60 degrees either way, \
                 offsets up to 0.3 m, a second wall with a door in half",
            ),
            Family::Turns => (
                "An opening, then a turn (`arc bench robust --turns`)",
                "a window 0.45-0.6 m in a wall of 0.1-0.3 m, approached 0-45 degrees off its normal either way, then a door 0.6-0.9 m wide in a second wall \
                 1-3 m on and 1-3 m to either side: the head turns while the tail is still in the window",
            ),
        }
    }
}

/// Options of the study.
#[derive(Clone, Debug)]
pub struct RobustOptions {
    /// Which instances.
    pub family: Family,
    /// Instances.
    pub instances: usize,
    /// Seed of the instance generator (the planner's seed is the instance index + 1).
    pub seed: u64,
    /// Head roadmap vertices.
    pub vertices: usize,
    /// Random shapes.
    pub srs: usize,
    /// Time limit per query (s).
    pub time_limit: Option<f64>,
}

impl RobustOptions {
    /// The full study: 200 instances.
    pub fn full() -> Self {
        Self {
            family: Family::Openings,
            instances: 200,
            seed: 1,
            vertices: 1500,
            srs: 500,
            time_limit: Some(30.0),
        }
    }
}

/// The drawn instances and how many draws were redrawn for lack of a witness.
pub fn draw(o: &RobustOptions) -> (Vec<RunSpec>, usize) {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(o.seed);
    let mut specs = Vec::with_capacity(o.instances);
    let mut redrawn = 0;
    while specs.len() < o.instances {
        let p = o.family.draw(&mut rng);
        let units: u8 = rng.gen_range(4..=8);
        let ok = p.build().ok().is_some_and(|sc| {
            aerial_chain_core::ChainParams::new(units)
                .validate()
                .is_ok_and(|params| witness(&sc, &params).is_ok())
        });
        if !ok {
            redrawn += 1;
            continue;
        }
        let method = Method::Arc(ArcMode::Follow);
        let key = RunKey::new("robust", &p.name(), units, method, (o.vertices, o.srs));
        specs.push(key.run(specs.len() as u64 + 1, o.time_limit));
    }
    (specs, redrawn)
}

/// Runs the specs in chunks of `chunk` maps.
pub fn run(
    specs: &[RunSpec],
    threads: Option<usize>,
    chunk: usize,
) -> Result<Vec<RunResult>, StudyError> {
    let mut out = Vec::with_capacity(specs.len());
    let bar = indicatif::ProgressBar::new(specs.len() as u64);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "arc bench robust [{bar:40}] {pos}/{len} instances ({elapsed}, eta {eta})",
    ) {
        bar.set_style(style.progress_chars("=> "));
    }
    for part in specs.chunks(chunk.max(1)) {
        let envs = Envs::for_specs(part)?;
        out.extend(run_all(&envs, part, threads, "arc bench robust", false)?);
        bar.inc(part.len() as u64);
    }
    bar.finish_and_clear();
    Ok(out)
}

/// The markdown summary.
pub fn markdown(results: &[RunResult], family: Family, redrawn: usize, meta: &str) -> String {
    let n = results.len();
    let solved: Vec<&RunResult> = results.iter().filter(|r| r.success).collect();
    let verified = solved.iter().filter(|r| r.verified == Some(true)).count();
    let ms =
        |f: &dyn Fn(&RunResult) -> f64| -> Vec<f64> { solved.iter().map(|r| f(r) * 1e3).collect() };
    let road = ms(&|r| r.roadmap_s);
    let plan = ms(&|r| r.planning_s);
    let total = ms(&|r| r.roadmap_s + r.planning_s);
    let mut s = String::new();
    let (title, what) = family.words();
    s += &format!("# {title}\n\n");
    s += &format!(
        "{n} random instances of `passage:` ({what}), N = 4..8, `arc plan`'s defaults. \
         Every instance has a witness checked by the exact verifier; {redrawn} draws without one were redrawn.\n\n"
    );
    s += "Setup is the planner's `setup` before the query (with the head lattice it builds nothing); \
          the labelled free regions and the uniform roadmap that a query needs are built in it and count as planning.\n\n";
    s += "| instances | solved | verified | setup median / p95 (ms) | planning median / p95 (ms) | total median / p95 (ms) |\n|---|---|---|---|---|---|\n";
    s += &format!(
        "| {n} | {} ({:.1} %) | {verified} | {:.1} / {:.1} | {:.1} / {:.1} | {:.1} / {:.1} |\n\n",
        solved.len(),
        100.0 * solved.len() as f64 / n.max(1) as f64,
        nearest_rank(&road, 0.5),
        nearest_rank(&road, 0.95),
        nearest_rank(&plan, 0.5),
        nearest_rank(&plan, 0.95),
        nearest_rank(&total, 0.5),
        nearest_rank(&total, 0.95),
    );
    s += "| N | instances | solved | planning median (ms) |\n|---|---|---|---|\n";
    for u in 4..=8u8 {
        let all: Vec<&RunResult> = results.iter().filter(|r| r.spec.key.units == u).collect();
        let ok: Vec<f64> = all
            .iter()
            .filter(|r| r.success)
            .map(|r| r.planning_s * 1e3)
            .collect();
        s += &format!(
            "| {u} | {} | {} | {:.1} |\n",
            all.len(),
            ok.len(),
            Spread::of(ok.iter().copied()).median
        );
    }
    s += &openings_markdown(&solved);
    let failed: Vec<&RunResult> = results.iter().filter(|r| !r.success).collect();
    if !failed.is_empty() {
        s += "\nFailures:\n\n";
        for r in failed {
            s += &format!(
                "- `{}` N = {}: {} ({})\n",
                r.spec.key.scenario, r.spec.key.units, r.outcome, r.message
            );
        }
    }
    s += &format!("\n{meta}\n");
    s
}

/// What the plans keep through the openings, raw and post-processed.
fn openings_markdown(solved: &[&RunResult]) -> String {
    let with: Vec<&super::PassageResult> =
        solved.iter().filter_map(|r| r.passage.as_ref()).collect();
    if with.is_empty() {
        return String::new();
    }
    let post_ms: Vec<f64> = with.iter().map(|p| p.post_s * 1e3).collect();
    let verified = with.iter().filter(|p| p.verified).count();
    let ratios = |post: bool| -> Vec<f64> {
        with.iter()
            .map(|p| {
                let (r, q) = p.worst_ratio();
                if post {
                    q
                } else {
                    r
                }
            })
            .collect()
    };
    let mut s = format!(
        "\nThrough the openings: the smallest clearance a plan keeps from each wall with an opening \
         (window or door) against what the passages issue asks, 0.9 (w - 2 r_u) / 2 for an opening w wide; \
         the worst opening of each instance counts. Post-processed as `arc plan` does: median {:.1} ms, \
         p95 {:.1} ms; {verified} of {} post-processed plans verified.\n\n\
         | plan | at or above the target | worst ratio | median ratio |\n|---|---|---|---|\n",
        nearest_rank(&post_ms, 0.5),
        nearest_rank(&post_ms, 0.95),
        with.len()
    );
    for (name, post) in [("raw", false), ("post-processed", true)] {
        let v = ratios(post);
        let ok = v.iter().filter(|&&x| x >= 1.0 - 1e-9).count();
        s += &format!(
            "| {name} | {ok} of {} | {:.2} | {:.2} |\n",
            v.len(),
            v.iter().copied().fold(f64::INFINITY, f64::min),
            nearest_rank(&v, 0.5)
        );
    }
    s
}

/// The figure: sorted setup + query times of the solved instances (and setup alone
/// when a planner spent any).
pub fn figure(results: &[RunResult]) -> String {
    let sorted = |f: &dyn Fn(&RunResult) -> f64| -> Vec<(f64, f64, f64, f64)> {
        let mut v: Vec<f64> = results
            .iter()
            .filter(|r| r.success)
            .map(|r| (f(r) * 1e3).max(1e-3))
            .collect();
        v.sort_by(f64::total_cmp);
        let n = v.len().max(1) as f64;
        v.iter()
            .enumerate()
            .map(|(i, &t)| (100.0 * (i + 1) as f64 / n, t, t, t))
            .collect()
    };
    let mut curves = vec![plot::Curve {
        label: "setup + query".into(),
        colour: aerial_chain::picture::palette::SRS,
        points: sorted(&|r| r.roadmap_s + r.planning_s),
    }];
    // With the head lattice, setup builds nothing (microseconds, below the chart).
    if results.iter().any(|r| r.success && r.roadmap_s >= 1e-4) {
        curves.push(plot::Curve {
            label: "setup (before the query)".into(),
            colour: aerial_chain::picture::palette::PATH,
            points: sorted(&|r| r.roadmap_s),
        });
    }
    let hi = curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.1))
        .fold(1.0f64, f64::max);
    let chart = plot::Chart {
        title: "arc bench robust: times of the solved instances, sorted".into(),
        x_label: "instances (%)".into(),
        y_label: "time (ms)".into(),
        log_y: true,
        y_range: (0.1, hi * 2.0),
        curves,
    };
    plot::svg(&[chart], 1, 1, (900, 500))
}
