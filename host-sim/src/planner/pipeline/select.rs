//! The selections of post-processing: which of two plans made side by side is kept,
//! each by its stated rule.

use super::{Context, Draft, Select};
use crate::planner::numeric::TIE;
use crate::planner::plan_ops::Quality;
use crate::planner::widen::Widening;

fn motion(d: &Draft) -> f64 {
    Quality::of(&d.steps).shape_motion_rad
}

/// Between the widened lane (shortcut at the margin the first widening won) and the
/// plain one (shortcut at the search's margin). **Rule:** the widened lane's plan,
/// unless it was given up or its shape motion exceeds the plain plan's by more than
/// the factor `RefineSettings::keep_motion` (a door that keeps the margin up can
/// refuse shortcuts elsewhere). Either way the first widening stays noted.
pub(super) struct KeepMotion;

impl Select for KeepMotion {
    fn name(&self) -> &'static str {
        "keep-motion"
    }

    fn choose(&self, widened: Draft, plain: Draft, cx: &Context) -> (Draft, usize) {
        let first = widened.notes.first_widening.clone();
        let kept =
            !widened.notes.withdrawn && motion(&widened) <= motion(&plain) * cx.s.keep_motion + TIE;
        let (mut chosen, k) = match kept {
            true => (widened, 0),
            false => (plain, 1),
        };
        if kept {
            chosen.notes.kept_moves = first.as_ref().map(|f| f.1.moves);
        }
        chosen.notes.first_widening = first;
        (chosen, k)
    }
}

/// Between the main lane's plan and the threaded one. **Rule:** the threaded plan is
/// kept when it moves the angles less than the main plan by more than
/// `ThreadSettings::motion` per link and keeps at least the main plan's narrowest
/// clearance (a long route the main plan snakes along). Else, where the main plan
/// passes every pinch of the search's route at a share of its middle of
/// `WidenSettings::centred` or more, it stays; and the threaded plan is kept when
/// its share is at least `ThreadSettings::share`, larger than the main plan's by
/// more than `ThreadSettings::gain`, and its shape motion exceeds the main plan's by
/// at most `ThreadSettings::motion` per link. The threaded plan is not widened: its
/// units already pass in the middle (widening it gained one instance of 200 in `arc
/// bench robust`, for a third more time).
pub(super) struct ThreadedIfBetter;

impl Select for ThreadedIfBetter {
    fn name(&self) -> &'static str {
        "threaded-if-better"
    }

    fn choose(&self, mut main: Draft, threaded: Draft, cx: &Context) -> (Draft, usize) {
        let Some(t) = threaded
            .notes
            .threading
            .as_ref()
            .filter(|_| !threaded.notes.withdrawn)
        else {
            return (main, 0);
        };
        let (threading, passing) = (&t.0, &t.1);
        let th = &cx.s.thread;
        let links = cx.ctx.params().links() as f64;
        // Less shape motion by more than the allowance, at no less clearance: the
        // chain bends less on its way (a long route the main plan snakes along).
        let calmer = motion(&threaded) + links * th.motion < motion(&main)
            && passing.narrowest >= main.notes.widening.after;
        let share = threading.measure(cx.ctx, &main.steps, false).share;
        if share >= cx.s.widen.centred && !calmer {
            return (main, 0);
        }
        let affordable = motion(&threaded) <= motion(&main) + links * th.motion;
        let centred = passing.share >= th.share && passing.share > share + th.gain;
        if !(calmer || centred && affordable) {
            return (main, 0);
        }
        // The main lane's notes stay for the report, with the threaded plan's figures.
        main.notes.widening = Widening {
            before: main.notes.widening.before,
            after: passing.narrowest,
            in_passages: None,
            moves: 0,
            measured: 0,
        };
        main.notes.threaded = true;
        main.notes.carried.clear();
        main.steps = threaded.steps;
        (main, 1)
    }
}
