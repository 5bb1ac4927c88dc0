//! What a benchmark runs: the planner and its mode, the group a run belongs to
//! ([`RunKey`]), the budgets of a study ([`Budgets`]) and one run ([`RunSpec`]).

use aerial_chain::planner::{Mode, Settings};

use super::Query;

/// Which planner a run uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Method {
    /// The ARCplanner with these shape sources.
    Arc(ArcMode),
    /// The full-state lazy PRM.
    FullPrm,
}

/// The ARCplanner's shape sources (the paper's ablation), orderable for grouping.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ArcMode {
    /// Library shapes only ("LSC").
    Lsc,
    /// Random shapes only ("SRS").
    Srs,
    /// Both ("Both", the paper's full ARCplanner: rigid shapes only).
    Both,
    /// Both plus follow-the-leader steps ("Both+follow", `arc plan`'s default).
    Follow,
}

impl ArcMode {
    /// The planner's mode.
    pub fn mode(self) -> Mode {
        match self {
            ArcMode::Lsc => Mode::Lsc,
            ArcMode::Srs => Mode::Srs,
            ArcMode::Both | ArcMode::Follow => Mode::Both,
        }
    }

    /// The planner's follow-the-leader step (0: off, the paper's planner).
    pub fn follow_step(self) -> f64 {
        match self {
            ArcMode::Follow => Settings::default().follow_step,
            _ => 0.0,
        }
    }

    /// Row label in the tables.
    pub fn name(self) -> &'static str {
        match self {
            ArcMode::Lsc => "LSC",
            ArcMode::Srs => "SRS",
            ArcMode::Both => "Both",
            ArcMode::Follow => "Both+follow",
        }
    }
}

impl Method {
    /// Short label: `ARC-lsc`, `ARC-srs`, `ARC-both`, `ARC-follow`, `PRM`.
    pub fn label(self) -> &'static str {
        match self {
            Method::Arc(ArcMode::Lsc) => "ARC-lsc",
            Method::Arc(ArcMode::Srs) => "ARC-srs",
            Method::Arc(ArcMode::Both) => "ARC-both",
            Method::Arc(ArcMode::Follow) => "ARC-follow",
            Method::FullPrm => "PRM",
        }
    }
}

/// What names a group of runs (a row of a results table): the runs of a group share
/// their key and differ in their seeds.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct RunKey {
    /// Which study it belongs to (`table1`, `scale-units`, ...).
    pub study: String,
    /// Built-in scenario name.
    pub scenario: String,
    /// Chain size N.
    pub units: u8,
    /// Planner.
    pub method: Method,
    /// Roadmap vertices: `M_VT` for the ARCplanner, `M_F` for the PRM.
    pub vertices: usize,
    /// Random shapes `N_SRS` (ARCplanner; 0 for LSC only).
    pub srs: usize,
}

impl RunKey {
    /// The group of `study` on `scenario` with N = `units`, `method` and its budgets
    /// (roadmap vertices, `N_SRS`).
    pub fn new(
        study: &str,
        scenario: &str,
        units: u8,
        method: Method,
        (vertices, srs): (usize, usize),
    ) -> Self {
        Self {
            study: study.into(),
            scenario: scenario.into(),
            units,
            method,
            vertices,
            srs,
        }
    }

    /// The run of this group with `seed` under `time_limit`, on the scenario's own query.
    pub fn run(&self, seed: u64, time_limit: Option<f64>) -> RunSpec {
        RunSpec {
            key: self.clone(),
            seed,
            time_limit,
            query: None,
        }
    }
}

/// What every row of a study gets: seeds, roadmap size, random shapes, time limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budgets {
    /// Seeds per row (`1..=seeds`).
    pub seeds: u64,
    /// Head roadmap vertices `M_VT`.
    pub vertices: usize,
    /// Random shapes `N_SRS`.
    pub srs: usize,
    /// Time limit per run (s).
    pub time_limit: Option<f64>,
}

impl Budgets {
    /// The paper's: 20 seeds, `M_VT = 1500`, `N_SRS = 500`, 60 s per run.
    pub fn full() -> Self {
        Self {
            seeds: 20,
            vertices: 1500,
            srs: 500,
            time_limit: Some(60.0),
        }
    }

    /// A smoke run's: `seeds` seeds, `M_VT = 300`, `N_SRS = 100`, 2 s per run.
    pub fn quick(seeds: u64) -> Self {
        Self {
            seeds,
            vertices: 300,
            srs: 100,
            time_limit: Some(2.0),
        }
    }

    /// The time limit as the reports print it.
    pub fn time_limit_text(&self) -> String {
        self.time_limit.map_or("none".into(), |t| t.to_string())
    }

    /// The runs of the group `key`, one per seed.
    pub fn runs<'a>(&self, key: &'a RunKey) -> impl Iterator<Item = RunSpec> + 'a {
        let time_limit = self.time_limit;
        (1..=self.seeds).map(move |seed| key.run(seed, time_limit))
    }
}

/// One benchmark run.
#[derive(Clone, Debug, PartialEq)]
pub struct RunSpec {
    /// Its group.
    pub key: RunKey,
    /// Seed of the roadmap (and of the SRS).
    pub seed: u64,
    /// Time limit of the query, and of the PRM's roadmap build (s).
    pub time_limit: Option<f64>,
    /// Start and goal; `None`: the scenario's own (LI at its start yaw).
    pub query: Option<Query>,
}
