//! End to end: `arc plan --picture x.gif` and `arc sim --picture x.gif` write
//! animations with one frame per `--frame-step` of the motion, which decode and move;
//! bad steps and unwritable outputs are refused with a clear error and leave no file.

mod support;

use std::path::Path;

use support::{arc_ok, expect, plan_scenario, s};

/// The frames of the GIF at `path`, each composited over the ones before (RGBA).
fn frames(path: &Path) -> (Vec<Vec<u8>>, Vec<u16>) {
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let file = std::fs::File::open(path).expect("the animation");
    let mut dec = opts.read_info(file).expect("a GIF");
    let (w, h) = (dec.width() as usize, dec.height() as usize);
    let mut canvas = vec![0u8; w * h * 4];
    let (mut out, mut delays) = (Vec::new(), Vec::new());
    while let Some(f) = dec.read_next_frame().expect("a frame") {
        let fw = f.width as usize;
        for y in 0..f.height as usize {
            for x in 0..fw {
                let src = 4 * (y * fw + x);
                if f.buffer[src + 3] == 0 {
                    continue;
                }
                let dst = 4 * ((y + f.top as usize) * w + x + f.left as usize);
                canvas[dst..dst + 4].copy_from_slice(&f.buffer[src..src + 4]);
            }
        }
        out.push(canvas.clone());
        delays.push(f.delay);
    }
    (out, delays)
}

/// Pixels that differ between two frames.
fn differing(a: &[u8], b: &[u8]) -> usize {
    a.chunks(4).zip(b.chunks(4)).filter(|(p, q)| p != q).count()
}

#[test]
fn a_plan_animates_one_frame_per_step_of_its_trajectory() {
    let dir = tempfile::tempdir().unwrap();
    let [plan, traj, gif] = ["p.json", "t.json", "p.gif"].map(|n| dir.path().join(n));
    plan_scenario(
        "window",
        4,
        &[
            "--trajectory",
            s(&traj),
            "--picture",
            s(&gif),
            "--frame-step",
            "0.5",
        ],
        &plan,
    )
    .expect("plan and animation");
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&traj).unwrap()).unwrap();
    let duration = t["samples"]
        .as_array()
        .and_then(|a| a.last())
        .and_then(|r| r["t"].as_f64())
        .expect("the trajectory's last time");
    let (f, delays) = frames(&gif);
    let expected = (duration / 0.5 - 1e-9).ceil() as usize + 1;
    assert_eq!(f.len(), expected, "a {duration} s trajectory at 0.5 s");
    assert!(f.len() >= 3);
    assert!(
        differing(&f[0], &f[f.len() / 2]) > 100,
        "the chain moves between frames"
    );
    assert!(
        delays.iter().all(|&d| d > 0),
        "every frame shows: {delays:?}"
    );
    let size = std::fs::metadata(&gif).unwrap().len();
    assert!(size < 3 << 20, "{size} bytes");
}

#[test]
fn a_flight_animates_one_frame_per_step_of_flight() {
    let dir = tempfile::tempdir().unwrap();
    let [plan, out, gif] = ["p.json", "f.json", "f.gif"].map(|n| dir.path().join(n));
    plan_scenario("window", 4, &[], &plan).expect("plan");
    arc_ok(&[
        "sim",
        "--scenario",
        "window",
        "--plan",
        s(&plan),
        "--out",
        s(&out),
        "--picture",
        s(&gif),
        "--frame-step",
        "1",
    ])
    .expect("flight and animation");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let flown = v["report"]["simulated_time"].as_f64().expect("flown time");
    let (f, _) = frames(&gif);
    assert_eq!(
        f.len(),
        (flown - 1e-9).ceil() as usize + 1,
        "{flown} s at 1 s"
    );
    assert!(differing(&f[0], &f[f.len() - 1]) > 100);
}

#[test]
fn bad_steps_and_outputs_are_refused_and_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let with = |extra: &[&str]| -> Vec<String> {
        "plan --scenario window --units 4 --out p.json"
            .split(' ')
            .chain(extra.iter().copied())
            .map(String::from)
            .collect()
    };
    for (extra, says) in [
        (
            &["--picture", "a.gif", "--frame-step", "0"][..],
            "--frame-step 0",
        ),
        (
            &["--picture", "a.gif", "--frame-step", "-1"],
            "--frame-step -1",
        ),
        (
            &["--picture", "a.gif", "--frame-step", "nan"],
            "--frame-step NaN",
        ),
        (
            &["--picture", "a.png", "--frame-step", "1"],
            "only with an animation",
        ),
        (&["--frame-step", "1"], "only with an animation"),
        (
            &["--picture", "a.gif", "--frame-step", "0.001"],
            "more than 600",
        ),
        (&["--picture", "a.bmp"], "or an animation ending in .gif"),
        (&["--picture", "no/such/dir/a.gif"], "no/such/dir/a.gif"),
    ] {
        let args = with(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = expect(&args, d, 2);
        assert!(o.stderr.contains(says), "{extra:?}: {}", o.stderr);
        for name in ["a.gif", "a.png", "a.bmp"] {
            assert!(!d.join(name).exists(), "{extra:?} left {name}");
        }
        let stray: Vec<_> = std::fs::read_dir(d)
            .unwrap()
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n != "p.json")
            .collect();
        assert!(stray.is_empty(), "{extra:?} left {stray:?}");
    }
}
