//! The generator's stages (`super::build`), in the one order every round runs them
//! ([`Stage::ROUND`]), and what each did over a trajectory's rounds: the rounds it ran
//! in, its wall time, and its work in its own unit. A round groups the plan's edges,
//! fits their timing, samples and checks the result exactly, and, where the check
//! fails, gives way a step before the next round; a round that passes ends the
//! generator.

use std::time::Instant;

/// A stage of the trajectory generator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// The plan's edges cut into motions, runs and pairs merged (`super::group`).
    Group,
    /// The motions timed: cruise rates lowered, round by round, until every edge's
    /// ramps fit (`Settings::fit_rounds` per pass), corners unblended where they never
    /// do.
    Fit,
    /// The timed motion sampled and checked exactly (`super::check_samples`), from
    /// the first sample a change since the last round can reach.
    Check,
    /// Where the check failed: a blended corner unblended, or a merged motion giving
    /// way a step (`super::group`); where it failed on the clearance a blend keeps,
    /// first the plan's own edges there measured (a blend keeps no more than they do).
    GiveWay,
}

impl Stage {
    /// The stages in the order every round runs them (the order lives here; the
    /// generator's loop follows it).
    pub const ROUND: [Stage; 4] = [Stage::Group, Stage::Fit, Stage::Check, Stage::GiveWay];

    /// Its name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Group => "group",
            Stage::Fit => "fit",
            Stage::Check => "check",
            Stage::GiveWay => "give-way",
        }
    }

    /// What its work counts.
    pub fn unit(self) -> &'static str {
        match self {
            Stage::Group => "motions assembled",
            Stage::Fit => "fit rounds",
            Stage::Check => "configurations checked",
            Stage::GiveWay => "steps given way",
        }
    }
}

/// What one stage did over a trajectory's rounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StageReport {
    /// The stage.
    pub stage: Stage,
    /// Rounds it ran in.
    pub rounds: usize,
    /// Its work, in [`Stage::unit`].
    pub used: u64,
    /// Wall time over every round (s).
    pub time_s: f64,
}

/// Every stage's report, in [`Stage::ROUND`]'s order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stages([StageReport; 4]);

impl Default for Stages {
    fn default() -> Self {
        Self(Stage::ROUND.map(|stage| StageReport {
            stage,
            rounds: 0,
            used: 0,
            time_s: 0.0,
        }))
    }
}

impl Stages {
    /// The reports, in [`Stage::ROUND`]'s order.
    pub fn reports(&self) -> &[StageReport] {
        &self.0
    }

    /// Runs `work` as one round of `stage`: its result, the work it did (in the
    /// stage's unit) counted and its time added.
    pub(super) fn run<T>(&mut self, stage: Stage, work: impl FnOnce() -> (T, u64)) -> T {
        let began = Instant::now();
        let (out, used) = work();
        let r = &mut self.0[stage as usize];
        r.rounds += 1;
        r.used += used;
        r.time_s += began.elapsed().as_secs_f64();
        out
    }

    /// Adds `other`'s rounds, work and time (legs timed one after the other).
    pub(super) fn add(&mut self, other: &Stages) {
        for (r, o) in self.0.iter_mut().zip(&other.0) {
            r.rounds += o.rounds;
            r.used += o.used;
            r.time_s += o.time_s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_stage_counts_its_own_rounds_and_work_in_round_order() {
        let mut s = Stages::default();
        assert_eq!(s.run(Stage::Fit, || ("fitted", 3)), "fitted");
        s.run(Stage::Fit, || ((), 2));
        s.run(Stage::Check, || ((), 40));
        let mut legs = Stages::default();
        legs.add(&s);
        legs.add(&s);
        let got: Vec<_> = legs
            .reports()
            .iter()
            .map(|r| (r.stage, r.rounds, r.used))
            .collect();
        assert_eq!(
            got,
            [
                (Stage::Group, 0, 0),
                (Stage::Fit, 4, 10),
                (Stage::Check, 2, 80),
                (Stage::GiveWay, 0, 0)
            ]
        );
    }
}
