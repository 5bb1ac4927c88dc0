//! `arc view` in a real headless browser: the page it writes for a plan (and a
//! flight) on the window scenario loads with no script error, draws a canvas that is
//! not blank, and `#t=` moves the chain. Needs Debian's `chromium`; without it the
//! test fails, naming the package.

mod support;

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use support::{expect, hover_plan, s, words};

/// Wall time one browser run may take before it counts as hung; a guard, not a timing.
const BROWSER_GUARD: Duration = Duration::from_secs(180);

/// The headless browser, or a failure that says what to install.
fn chromium() -> PathBuf {
    let found = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|d| d.join("chromium"))
            .find(|p| p.is_file())
    });
    found.unwrap_or_else(|| {
        panic!(
            "`chromium` is not on PATH: tests/view.rs needs a headless browser; \
             install the Debian package `chromium` (apt-get install chromium)"
        )
    })
}

/// Runs chromium headless on `page` (with `fragment`) and `what` (`--screenshot=...`
/// or `--dump-dom`); returns its standard output and standard error.
fn browse(dir: &Path, page: &Path, fragment: &str, what: &str) -> (String, String) {
    let profile = tempfile::tempdir_in(dir).unwrap();
    let out = tempfile::NamedTempFile::new_in(dir).unwrap();
    let err = tempfile::NamedTempFile::new_in(dir).unwrap();
    let mut child = Command::new(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--virtual-time-budget=5000",
            "--window-size=1000,700",
            "--hide-scrollbars",
        ])
        .arg(format!("--user-data-dir={}", s(profile.path())))
        .arg(what)
        .arg(format!("file://{}#{fragment}", s(page)))
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(out.reopen().unwrap())
        .stderr(err.reopen().unwrap())
        .spawn()
        .expect("spawn chromium");
    let start = Instant::now();
    let status = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        if start.elapsed() > BROWSER_GUARD {
            let _ = child.kill();
            let _ = child.wait();
            panic!("chromium {what} on {} hung", page.display());
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    let stderr = std::fs::read_to_string(err.path()).unwrap_or_default();
    assert!(
        status.success(),
        "chromium {what} failed: {status}; it said:\n{stderr}"
    );
    (std::fs::read_to_string(out.path()).unwrap(), stderr)
}

/// The page loads and its script runs to the end without an error.
fn assert_runs(dir: &Path, page: &Path) {
    let (dom, _) = browse(dir, page, "t=0", "--dump-dom");
    assert!(
        !dom.contains("id=\"arc-view-error\""),
        "the page reports an error: {}",
        dom.split("id=\"arc-view-error\"")
            .nth(1)
            .unwrap_or("")
            .chars()
            .take(400)
            .collect::<String>()
    );
    assert!(
        dom.contains("id=\"arc-view-ready\""),
        "the page's script did not run to its end ({} bytes of DOM)",
        dom.len()
    );
}

/// The RGB pixels of a screenshot of `page` at `fragment`, drawing only (no panels).
fn pixels(dir: &Path, page: &Path, fragment: &str, name: &str) -> Vec<[u8; 3]> {
    let png_path = dir.join(name);
    // Headless chromium on a loaded machine now and then ends with success and no
    // screenshot; a second try is then enough. A page that fails fails every time.
    let mut said = Vec::new();
    for _ in 0..3 {
        let (_, stderr) = browse(
            dir,
            page,
            &format!("{fragment}&ui=0"),
            &format!("--screenshot={}", s(&png_path)),
        );
        if png_path.is_file() {
            break;
        }
        said.push(stderr);
    }
    let file = std::fs::File::open(&png_path).unwrap_or_else(|e| {
        panic!(
            "chromium wrote no screenshot of {}#{fragment} in 3 tries ({e}); it said:\n{}",
            page.display(),
            said.join("\n---\n")
        )
    });
    let decoder = png::Decoder::new(file);
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    assert!(
        channels >= 3,
        "screenshot colour type {:?}",
        info.color_type
    );
    buf[..info.buffer_size()]
        .chunks_exact(channels)
        .map(|p| [p[0], p[1], p[2]])
        .collect()
}

#[test]
fn the_page_draws_the_plan_and_its_time_moves_the_chain() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    expect(
        &words("plan --scenario window --units 5 --out window.json"),
        d,
        0,
    );
    let out = expect(
        &words("view --scenario window --plan window.json --out view.html"),
        d,
        0,
    );
    assert!(out.stdout.contains("wrote view.html"), "{out:?}");
    let page = d.join("view.html");
    assert_runs(d, &page);
    let start = pixels(d, &page, "t=0", "start.png");
    let colours: HashSet<[u8; 3]> = start.iter().copied().collect();
    assert!(
        colours.len() > 200,
        "the drawing looks blank: {} distinct colours",
        colours.len()
    );
    // Past the end is clamped to the end.
    let end = pixels(d, &page, "t=100000", "end.png");
    assert_eq!(start.len(), end.len());
    let changed = start.iter().zip(&end).filter(|(a, b)| a != b).count();
    assert!(
        changed > 500,
        "#t=0 and #t=<end> draw the same picture ({changed} pixels differ)"
    );
}

#[test]
fn the_page_draws_a_flight() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("hover.json"), hover_plan(true)).unwrap();
    let sim = "sim --scenario window --plan hover.json --settle-time 1 --out flight.json";
    expect(&words(sim), d, 0);
    let view =
        words("view --scenario window --plan hover.json --flight flight.json --out flight.html");
    let out = expect(&view, d, 0);
    assert!(out.stdout.contains("with the flight"), "{out:?}");
    assert_runs(d, &d.join("flight.html"));
}

#[test]
fn bad_files_are_refused_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("hover.json"), hover_plan(true)).unwrap();
    std::fs::write(d.join("junk.json"), "{\"format\": \"arc-sim/1\"}").unwrap();
    std::fs::write(
        d.join("short.json"),
        "{\"format\": \"arc-sim/1\", \"samples\": [{\"t\": 0, \"units\": [{\"p\": [0, 0, 0]}]}]}",
    )
    .unwrap();
    let base = ["view", "--scenario", "window", "--out", "v.html"];
    for (extra, says) in [
        (&["--plan", "missing.json"][..], "missing.json"),
        (
            &["--plan", "hover.json", "--flight", "missing.json"],
            "missing.json",
        ),
        (
            &["--plan", "hover.json", "--flight", "junk.json"],
            "junk.json",
        ),
        (&["--plan", "hover.json", "--flight", "short.json"], "N = 3"),
        (
            &["--plan", "hover.json", "--flight", "hover.json"],
            "arc-sim/1",
        ),
    ] {
        let args: Vec<&str> = base.iter().chain(extra).copied().collect();
        let o = expect(&args, d, 2);
        let lines: Vec<&str> = o.stderr.lines().collect();
        assert_eq!(lines.len(), 1, "{args:?}: {o:?}");
        assert!(lines[0].contains(says), "{args:?}: {o:?}");
    }
    assert!(!d.join("v.html").exists(), "a refused run wrote its output");
}

#[test]
fn a_100_m_corridor_page_stays_small() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let plan = words("plan --scenario corridor:100 --units 6 --out corridor.json");
    expect(&plan, d, 0);
    let view = words("view --scenario corridor:100 --plan corridor.json --out corridor.html");
    expect(&view, d, 0);
    let bytes = std::fs::metadata(d.join("corridor.html")).unwrap().len();
    assert!(bytes <= 5_000_000, "the page weighs {bytes} bytes");
}

/// The `seen` count the page's info line gives at `fragment`: "K of N boxes seen
/// occupied".
fn seen_count(dir: &Path, page: &Path, fragment: &str) -> (usize, usize) {
    let (dom, _) = browse(dir, page, fragment, "--dump-dom");
    let tail = dom
        .split(" boxes seen occupied")
        .next()
        .filter(|_| dom.contains(" boxes seen occupied"))
        .unwrap_or_else(|| panic!("no seen count at #{fragment}"));
    let words: Vec<&str> = tail.rsplit("; ").next().unwrap().split(' ').collect();
    match words[..] {
        [k, "of", n] => (k.parse().unwrap(), n.parse().unwrap()),
        _ => panic!("seen count {words:?} at #{fragment}"),
    }
}

/// An exploration's flight carries the map as it grew: the page draws the boxes its
/// sensors saw, more of them as time goes on, all of them at the end; a record made
/// on another map's lattice is refused.
#[test]
fn an_explorations_page_grows_the_map_its_sensors_drew() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let run = "explore --scenario window --units 4 --out f.json --plan-out p.json";
    expect(&words(run), d, 0);
    let view = words("view --scenario window --plan p.json --flight f.json --out e.html");
    let out = expect(&view, d, 0);
    assert!(out.stdout.contains("its sensors saw as it grew"), "{out:?}");
    let page = d.join("e.html");
    assert_runs(d, &page);
    let (early, n) = seen_count(d, &page, "t=0.05");
    let (middle, _) = seen_count(d, &page, "t=6");
    let (end, _) = seen_count(d, &page, "t=100000");
    assert!(n > 500, "{n} boxes seen");
    assert!(
        early < middle && middle < end && end == n,
        "{early} {middle} {end} of {n}"
    );

    let mut flight: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("f.json")).unwrap()).unwrap();
    flight["explore"]["seen_occupied"]["resolution"] = 0.05.into();
    std::fs::write(d.join("other.json"), flight.to_string()).unwrap();
    let view = words("view --scenario window --plan p.json --flight other.json --out o.html");
    let o = expect(&view, d, 2);
    assert!(
        o.stderr.contains("other.json") && o.stderr.contains("resolution"),
        "{o:?}"
    );
    assert!(!d.join("o.html").exists());
}
