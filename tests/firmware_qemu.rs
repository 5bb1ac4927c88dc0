//! The unit firmware (`firmware-sketch/`) built for thumbv7em-none-eabihf and run
//! in QEMU (netduinoplus2, an STM32F405), its defmt output decoded in-process with
//! the `defmt-decoder` crate (the ELF's defmt table, the semihosting byte stream):
//!
//! - with the table its build script generates (the same bytes as the host's
//!   `arc tables build`, checked by CRC): the table is valid, every
//!   scripted "go to shape k" settles within tolerance and time, the stack peak
//!   is within budget, and the firmware exits with success;
//! - with that table corrupted (feature `corrupt-table`): safe mode, every shape
//!   command refused, attitude held, exit failure;
//! - with a table file made on the host (`ARC_TABLE`, as `arc tables build`
//!   writes them): accepted when it is for this chain, refused as a chain
//!   mismatch when it is for another.
//!
//! Without `qemu-system-arm` the tests fail and name the package to install:
//! a run in which the firmware never ran must not look green (`./test`
//! installs QEMU).

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::atomic::AtomicUsize;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use aerial_chain::tables::{ShapeTables, TableSettings};
use aerial_chain_core::lsc::library;
use aerial_chain_core::srs::{Srs, SrsSettings};
use aerial_chain_core::table::{encode_into, TableView};
use aerial_chain_core::ChainParams;
use arc_tests::{cargo, require_thumbv7em_target, require_tool, workspace_root};
use defmt_decoder::{DecodeError, Table};

/// Builds share one target folder and one output path: one at a time.
static BUILD: Mutex<()> = Mutex::new(());

/// Longest a firmware run may take in QEMU.
const QEMU_TIMEOUT: Duration = Duration::from_secs(120);
/// Stack budget (bytes).
const STACK_BUDGET: u64 = 8 * 1024;
/// Settle tolerance the firmware uses (degrees).
const TOLERANCE_DEG: f64 = 0.5;

/// Fails the test, naming the package, when QEMU is not installed.
fn require_qemu() {
    require_tool("qemu-system-arm", &["--version"], "qemu-system-arm");
}

/// Builds the firmware with `features` and build environment `env`, and copies
/// the ELF to `target/firmware/qemu-tests/<name>.elf`.
fn build(name: &str, features: &[&str], env: &[(&str, &str)]) -> PathBuf {
    require_thumbv7em_target();
    let _guard = BUILD.lock().unwrap_or_else(|e| e.into_inner());
    let dir = workspace_root().join("firmware-sketch");
    let mut c = cargo("firmware");
    c.current_dir(&dir).args(["build", "--release"]);
    if !features.is_empty() {
        c.args(["--features", &features.join(",")]);
    }
    for v in [
        "RUSTFLAGS",
        "CARGO_ENCODED_RUSTFLAGS",
        "CARGO_BUILD_RUSTFLAGS",
        "CARGO_BUILD_TARGET",
        "ARC_TABLE",
        "ARC_N_SRS",
        "ARC_SEED",
    ] {
        c.env_remove(v);
    }
    c.env("DEFMT_LOG", "info")
        .env("ARC_UNITS", "6")
        .env("ARC_UNIT", "2");
    for (k, v) in env {
        c.env(k, v);
    }
    let out = c.output().expect("cargo runs");
    assert!(
        out.status.success(),
        "firmware build `{name}` failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let built = workspace_root().join("target/firmware/thumbv7em-none-eabihf/release/arc-firmware");
    let dest_dir = workspace_root().join("target/firmware/qemu-tests");
    std::fs::create_dir_all(&dest_dir).expect("create qemu-tests folder");
    let dest = dest_dir.join(format!("{name}.elf"));
    std::fs::copy(&built, &dest).expect("copy firmware ELF");
    dest
}

/// A run's decoded log and exit status.
struct Run {
    /// QEMU's exit status (the firmware's semihosting exit code).
    status: ExitStatus,
    /// The decoded defmt frames, then anything QEMU wrote on stderr.
    log: String,
}

impl Run {
    /// The decoded log lines that contain `needle`.
    fn lines_with<'a>(&'a self, needle: &'a str) -> impl Iterator<Item = &'a str> + 'a {
        self.log.lines().filter(move |l| l.contains(needle))
    }

    /// Whether some decoded log line contains `needle`.
    fn has(&self, needle: &str) -> bool {
        self.lines_with(needle).next().is_some()
    }

    /// The first decoded log line containing `needle`; fails with `what` (and the
    /// run's context) when there is none.
    fn expect_line<'a>(&'a self, needle: &'a str, what: &str) -> &'a str {
        self.lines_with(needle)
            .next()
            .unwrap_or_else(|| panic!("{what}; {}", self.context()))
    }

    /// Fails with `what` (and the run's context) when a decoded log line contains
    /// `needle`.
    fn forbid(&self, needle: &str, what: &str) {
        assert!(!self.has(needle), "{what}; {}", self.context());
    }

    /// Exit status and whole log, for failure messages.
    fn context(&self) -> String {
        format!("exit status {:?}; decoded log:\n{}", self.status, self.log)
    }
}

/// Boots `elf` in QEMU and decodes its defmt frames.
fn run(elf: &Path) -> Run {
    run_with(elf, &[])
}

/// [`run`] with extra QEMU arguments.
fn run_with(elf: &Path, qemu_args: &[&str]) -> Run {
    require_qemu();
    let mut qemu = Command::new("qemu-system-arm")
        .args(["-cpu", "cortex-m4", "-machine", "netduinoplus2"])
        .args([
            "-nographic",
            "-semihosting-config",
            "enable=on,target=native",
        ])
        .arg("-kernel")
        .arg(elf)
        .args(qemu_args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("qemu-system-arm starts");
    let mut frames = qemu.stdout.take().expect("piped");
    let reader = std::thread::spawn(move || {
        let mut bytes = Vec::new();
        let _ = frames.read_to_end(&mut bytes);
        bytes
    });
    let start = Instant::now();
    let status = loop {
        if let Some(s) = qemu.try_wait().expect("wait for qemu") {
            break s;
        }
        if start.elapsed() > QEMU_TIMEOUT {
            let _ = qemu.kill();
            let _ = qemu.wait();
            let log = decode(elf, &reader.join().unwrap_or_default());
            panic!(
                "firmware {} still running after {QEMU_TIMEOUT:?}; log so far:\n{log}",
                elf.display()
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut log = decode(elf, &reader.join().expect("reader thread"));
    let mut err = String::new();
    if let Some(mut e) = qemu.stderr.take() {
        let _ = e.read_to_string(&mut err);
    }
    if !err.trim().is_empty() {
        log.push_str("\n[qemu stderr] ");
        log.push_str(&err);
    }
    Run { status, log }
}

/// Decodes the defmt frames in `bytes` with the table in `elf`: one line per frame,
/// `LEVEL message` (or the message alone for `println!`). A frame that cannot be
/// decoded becomes a `[malformed defmt frame]` line, which no check accepts.
fn decode(elf: &Path, bytes: &[u8]) -> String {
    let image = std::fs::read(elf).unwrap_or_else(|e| panic!("{}: {e}", elf.display()));
    let table = Table::parse(&image)
        .unwrap_or_else(|e| panic!("{}: defmt table unreadable: {e}", elf.display()))
        .unwrap_or_else(|| panic!("{}: no .defmt section", elf.display()));
    let mut stream = table.new_stream_decoder();
    stream.received(bytes);
    let mut log = String::new();
    loop {
        match stream.decode() {
            Ok(frame) => {
                if let Some(level) = frame.level() {
                    log.push_str(&level.as_str().to_ascii_uppercase());
                    log.push(' ');
                }
                log.push_str(&frame.display_message().to_string());
                log.push('\n');
            }
            Err(DecodeError::UnexpectedEof) => break,
            Err(DecodeError::Malformed) if table.encoding().can_recover() => {
                log.push_str("[malformed defmt frame]\n");
            }
            Err(DecodeError::Malformed) => {
                log.push_str("[malformed defmt frame: the rest of the stream is lost]\n");
                break;
            }
        }
    }
    log
}

/// The number after `key` in `line` (e.g. `key = "in "` in "settled ... in 2.1 s").
fn number_after(line: &str, key: &str) -> f64 {
    let rest = &line[line
        .find(key)
        .unwrap_or_else(|| panic!("no {key:?} in {line:?}"))
        + key.len()..];
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
        .unwrap_or(rest.len());
    rest[..end]
        .parse()
        .unwrap_or_else(|_| panic!("no number after {key:?} in {line:?}"))
}

/// Common checks of a run that must not have crashed.
fn assert_clean(r: &Run) {
    r.forbid("panic", "firmware panicked");
    r.forbid("hard fault", "firmware faulted");
    let stack = r.expect_line("stack peak", "no stack report");
    let peak = number_after(stack, "stack peak ") as u64;
    assert!(
        peak > 0 && peak <= STACK_BUDGET,
        "stack peak {peak} B over {STACK_BUDGET} B; {}",
        r.context()
    );
}

/// Checks a run that must have reached every target; returns the shapes visited.
fn assert_mission_success(r: &Run, srs: u64) -> Vec<u64> {
    assert_eq!(
        r.status.code(),
        Some(0),
        "firmware did not exit with success; {}",
        r.context()
    );
    assert_clean(r);
    let summary = r.expect_line("table valid:", "no table summary");
    assert!(summary.contains("format v1"), "{summary}");
    assert!(summary.contains("chain N=6"), "{summary}");
    assert!(
        summary.contains(&format!("6 LSC + {srs} SRS shapes")),
        "{summary}"
    );
    r.forbid("SAFE MODE", "valid table took safe mode");
    r.forbid("NOT settled", "a target was missed");

    let commanded: Vec<u64> = r
        .lines_with("go to shape")
        .map(|l| number_after(l, "go to shape ") as u64)
        .collect();
    let settles: Vec<&str> = r.lines_with("settled shape").collect();
    let settled: Vec<u64> = settles
        .iter()
        .map(|l| number_after(l, "settled shape ") as u64)
        .collect();
    assert!(commanded.len() >= 7, "too few commands; {}", r.context());
    assert_eq!(
        settled,
        commanded,
        "every command must settle, in order; {}",
        r.context()
    );
    let total = number_after(
        r.expect_line("command 1/", "no first command"),
        "command 1/",
    ) as usize;
    assert_eq!(
        commanded.len(),
        total,
        "commands logged vs announced; {}",
        r.context()
    );
    for k in 0..6 {
        assert!(
            commanded.contains(&k),
            "LSC shape {k} never commanded; {}",
            r.context()
        );
    }
    assert!(
        commanded.iter().any(|&k| k >= 6),
        "no SRS shape commanded; {}",
        r.context()
    );
    for l in &settles {
        let t = number_after(l, " in ");
        let e = number_after(l, "final error ");
        assert!(t > 0.0 && t < 6.0, "settle time {t} s out of range: {l}");
        assert!(
            e.abs() < TOLERANCE_DEG,
            "final error {e} deg over tolerance: {l}"
        );
    }
    let done = format!("all {total} targets reached");
    assert!(
        r.has(&done) && r.has("exit success"),
        "no success report; {}",
        r.context()
    );
    commanded
}

/// Checks a run that must have refused its table with `reason` and held attitude.
fn assert_safe_mode(r: &Run, reason: &str) {
    assert_eq!(
        r.status.code(),
        Some(1),
        "safe mode must exit with failure (1); {}",
        r.context()
    );
    assert_clean(r);
    r.forbid("table valid", "corrupt table accepted");
    let why = r.expect_line("SAFE MODE: table rejected", "no safe-mode report");
    assert!(
        why.contains(reason),
        "safe mode for another reason than {reason}: {why}"
    );
    let refused = r.lines_with("refused go to shape").count();
    assert!(refused >= 7, "shape commands not refused; {}", r.context());
    assert!(
        r.lines_with("refused go to shape")
            .all(|l| l.contains(reason)),
        "{}",
        r.context()
    );
    assert_eq!(
        r.lines_with("holding attitude").count(),
        refused,
        "{}",
        r.context()
    );
    r.forbid("settled shape", "a shape was flown in safe mode");
    let held = r.expect_line("attitude held within", "no hold report");
    let e = number_after(held, "held within ");
    assert!(e < TOLERANCE_DEG, "attitude not held: {held}");
    r.expect_line(
        "safe mode: no target reached: exit failure",
        "no safe-mode exit report",
    );
}

#[test]
fn firmware_reaches_every_commanded_shape() {
    require_qemu();
    let elf = build("valid", &[], &[("ARC_N_SRS", "100")]);
    let r = run(&elf);
    assert_mission_success(&r, 100);
    // The table the firmware's build script generated is the very table the
    // host makes (`arc tables build --units 6 --srs 100 --seed 1`): same CRC.
    let host = ShapeTables::build(
        ChainParams::new(6),
        &TableSettings {
            srs: 100,
            seed: 1,
            ..Default::default()
        },
        &AtomicUsize::new(0),
    )
    .expect("host tables")
    .encode()
    .expect("encode");
    let crc = TableView::open(&host, None)
        .expect("host table opens")
        .crc();
    let expected = format!("CRC {crc:#010x}");
    assert!(
        r.lines_with("table valid:").any(|l| l.contains(&expected)),
        "firmware table differs from the host's ({expected}); {}",
        r.context()
    );
}

#[test]
fn corrupted_table_puts_the_unit_in_safe_mode() {
    require_qemu();
    let elf = build("corrupt", &["corrupt-table"], &[("ARC_N_SRS", "100")]);
    let r = run(&elf);
    assert_safe_mode(&r, "CrcMismatch");
}

/// A table file written on the host, as `arc tables build` does.
fn host_table(units: u8, count: usize, name: &str) -> PathBuf {
    let p = ChainParams::new(units);
    let lib = library(&p);
    let srs = Srs::<128, 8>::generate(p, &SrsSettings::new(p.units, count, 7)).expect("srs");
    let mut buf = vec![0u8; 64 * 1024];
    let len = encode_into(&mut buf, &p, &lib.entries, &srs.shapes, &srs.adjacency).expect("encode");
    let dir = workspace_root().join("target/firmware/qemu-tests");
    std::fs::create_dir_all(&dir).expect("create qemu-tests folder");
    let path = dir.join(name);
    std::fs::write(&path, &buf[..len]).expect("write table");
    path
}

/// The firmware `name` built with a table written on the host ([`host_table`]), run.
fn run_with_host_table(units: u8, count: usize, name: &str) -> Run {
    let table = host_table(units, count, &format!("{name}.table"));
    let elf = build(
        name,
        &[],
        &[("ARC_TABLE", table.to_str().expect("utf-8 path"))],
    );
    run(&elf)
}

#[test]
fn host_written_tables_are_checked_against_the_unit_chain() {
    require_qemu();
    // For this chain (N = 6), with 64 SRS shapes: the script's SRS shape 105 is
    // not there, so that command is refused and the run fails, but the table is
    // accepted and every shape it has is reached.
    let r = run_with_host_table(6, 64, "host-n6");
    assert_clean(&r);
    r.expect_line("table valid: format v1, chain N=6", "no table summary");
    r.expect_line("6 LSC + 64 SRS shapes", "wrong shape count");
    r.expect_line(
        "go to shape 105 refused: NoSuchShape",
        "the missing shape was not refused",
    );
    r.forbid("NOT settled", "a target was missed");
    assert_eq!(
        r.status.code(),
        Some(1),
        "a refused command must fail the run; {}",
        r.context()
    );

    // For another chain (N = 5): refused before any command is flown.
    let r = run_with_host_table(5, 16, "host-n5");
    assert_safe_mode(&r, "ChainMismatch");
}

#[test]
fn table_flashed_apart_from_the_program() {
    require_qemu();
    // A program that links no table (its ELF leaves the table slot alone)...
    let elf = build("external", &["external-table"], &[]);
    let r = run(&elf);
    assert_safe_mode(&r, "Slot(Empty)");
    // ...and a table image flashed on its own at the slot's address, as
    // `probe-rs download --binary-format bin --base-address 0x080C0000` would:
    // a little-endian u32 length, then the table written on the host.
    let table = std::fs::read(host_table(6, 100, "host-n6-100.table")).expect("read table");
    let mut image = (table.len() as u32).to_le_bytes().to_vec();
    image.extend_from_slice(&table);
    let slot = workspace_root().join("target/firmware/qemu-tests/slot-n6-100.bin");
    std::fs::write(&slot, &image).expect("write slot image");
    let loader = format!("loader,file={},addr=0x080C0000", slot.display());
    let r = run_with(&elf, &["-device", &loader]);
    r.expect_line("table external", "the external table was not used");
    assert_mission_success(&r, 100);
}

#[test]
fn head_and_tail_units_steer_their_links() {
    require_qemu();
    // Unit 1 (the head) steers link 1; unit 6, the tail, leads no link and
    // steers link 5, the one it trails.
    for (unit, link) in [("1", "1"), ("6", "5")] {
        let elf = build(&format!("unit{unit}"), &[], &[("ARC_UNIT", unit)]);
        let r = run(&elf);
        let up = format!("ARC unit {unit} of 6 up: steers link {link},");
        r.expect_line(&up, &format!("expected {up:?}"));
        assert_mission_success(&r, 100);
    }
}
