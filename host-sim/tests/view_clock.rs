//! `arc view`'s clock is the flight's: the page times a plan's waypoints as `arc sim`
//! flies the plan (along its blended trajectory, after the start hold), not stopping
//! at every waypoint. Issue 36 measured corridor:100, N = 6: the page said 1211 s, the
//! flight took 561 s. No browser needed: the page's data is read from its JSON block.

mod support;

use std::path::Path;

use aerial_chain::flying::{self, FlyOptions};
use aerial_chain::plan_file::Plan;
use aerial_chain::problem::scenarios;
use aerial_chain::sim::{Reference, ReferenceLimits};
use support::{expect, words};

/// The waypoint times (`t`) of the page `arc view` wrote to `page`.
fn page_times(page: &Path) -> Vec<f64> {
    let html = std::fs::read_to_string(page).expect("the page");
    let open = "<script type=\"application/json\" id=\"arc-data\">";
    let from = html.find(open).expect("the data block") + open.len();
    let to = from + html[from..].find("</script>").expect("its end");
    let scene: serde_json::Value = serde_json::from_str(&html[from..to]).expect("JSON");
    let t = scene["waypoints"]["t"].as_array().expect("waypoints.t");
    t.iter().map(|v| v.as_f64().expect("a time")).collect()
}

/// How long `plan` takes stopping at every waypoint with `arc sim`'s default limits
/// (the page's old clock).
fn stopping_at_every_waypoint(plan: &Plan) -> f64 {
    let zetas: Vec<Vec<f64>> = plan.waypoints.iter().map(|w| w.zeta.clone()).collect();
    let (n, l) = (plan.chain.units as usize, plan.chain.link_length);
    let r = Reference::new(n, l, &zetas, &ReferenceLimits::default()).expect("timed");
    r.duration()
}

/// Plans `scenario` for `units` and writes its page in `d`: the plan and the page's
/// waypoint times.
fn plan_and_page(scenario: &str, units: &str, d: &Path) -> (Plan, Vec<f64>) {
    let plan = ["plan", "--scenario", scenario, "--units", units];
    expect(&[&plan[..], &["--out", "plan.json"]].concat(), d, 0);
    let view = ["view", "--scenario", scenario, "--plan", "plan.json"];
    expect(&[&view[..], &["--out", "page.html"]].concat(), d, 0);
    let plan = Plan::read(&d.join("plan.json")).expect("the plan");
    (plan, page_times(&d.join("page.html")))
}

#[test]
fn the_page_ends_when_arc_sim_ends_its_plan() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (plan, t) = plan_and_page("window", "5", d);
    let fly = "sim --scenario window --plan plan.json --record-every 100 --out flight.json";
    expect(&words(fly), d, 0);
    let text = std::fs::read_to_string(d.join("flight.json")).unwrap();
    let flight: serde_json::Value = serde_json::from_str(&text).unwrap();
    let flown = flight["report"]["planned_duration"].as_f64().unwrap();
    let end = t[t.len() - 1];
    assert!(
        (end - flown).abs() <= 1e-3,
        "page {end} s, arc sim {flown} s"
    );
    // The old clock would not pass: stopping at every waypoint takes longer.
    let stopping = stopping_at_every_waypoint(&plan);
    assert!(stopping > flown + 1.0, "{stopping} s against {flown} s");
    assert!(t.windows(2).all(|w| w[0] <= w[1]), "{t:?}");
}

#[test]
fn a_100_m_corridor_page_says_what_arc_sim_flies() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (plan, t) = plan_and_page("corridor:100", "6", d);
    let grid = scenarios::build("corridor:100").unwrap().grid;
    // What `arc sim --plan` flies with its defaults (the library call it makes).
    let timed = flying::time(&plan, &grid, &FlyOptions::default()).unwrap();
    let flown = timed.reference.duration();
    let end = t[t.len() - 1];
    assert!(
        (end - flown).abs() <= 1e-3,
        "page {end} s, arc sim {flown} s"
    );
    // Issue 36: 1211 s stopping at every waypoint, 561 s flown.
    let stopping = stopping_at_every_waypoint(&plan);
    assert!(stopping > 1.5 * flown, "{stopping} s against {flown} s");
}
