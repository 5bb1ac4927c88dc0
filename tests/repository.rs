//! The repository stands on its own:
//!
//! - no tracked file names a path outside it (an absolute path to someone's machine,
//!   or a folder beside the checkout);
//! - every relative link in its markdown documents resolves to a file inside it;
//! - the workspace's `rust-version` is at least every locked dependency's, for the
//!   host workspace and the firmware alike (`cargo metadata`).

use std::collections::BTreeSet;
use std::path::{Component, Path, PathBuf};
use std::process::Command;

use arc_tests::{cargo, require_tool, workspace_root};

/// The files git tracks, relative to the workspace root.
fn tracked_files() -> Vec<PathBuf> {
    require_tool("git", &["--version"], "git");
    let out = Command::new("git")
        .current_dir(workspace_root())
        .args(["ls-files", "-z"])
        .output()
        .expect("git runs");
    assert!(
        out.status.success(),
        "git ls-files failed (is this a git checkout?): {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let files: Vec<PathBuf> = out
        .stdout
        .split(|&b| b == 0)
        .filter(|f| !f.is_empty())
        .map(|f| PathBuf::from(String::from_utf8_lossy(f).into_owned()))
        .collect();
    assert!(files.len() > 50, "git lists only {} files", files.len());
    files
}

/// The text of a tracked file, or None for binary files (maps, pictures, tables).
fn text(path: &Path) -> Option<String> {
    let bytes = std::fs::read(workspace_root().join(path)).ok()?;
    String::from_utf8(bytes).ok()
}

#[test]
fn no_tracked_file_points_outside_the_repository() {
    // Written in pieces so that this file does not match itself.
    let patterns = [
        ["/wo", "rk/"].concat(),
        ["/ho", "me/"].concat(),
        ["/ro", "ot/"].concat(),
        ["/Us", "ers/"].concat(),
        ["../sh", "ared"].concat(),
    ];
    let mut hits = Vec::new();
    let mut checked = 0;
    for file in tracked_files() {
        let Some(content) = text(&file) else {
            continue;
        };
        checked += 1;
        for (n, line) in content.lines().enumerate() {
            if let Some(p) = patterns.iter().find(|p| line.contains(p.as_str())) {
                hits.push(format!(
                    "{}:{}: {p}: {}",
                    file.display(),
                    n + 1,
                    line.trim()
                ));
            }
        }
    }
    assert!(checked > 50, "only {checked} text files checked");
    assert!(
        hits.is_empty(),
        "tracked files name paths outside the repository:\n{}",
        hits.join("\n")
    );
}

/// The targets of the markdown links in `md`: `[text](target)` and `[label]: target`.
fn link_targets(md: &str) -> Vec<String> {
    let mut targets = Vec::new();
    let mut in_code = false;
    for line in md.lines() {
        if line.trim_start().starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if in_code {
            continue;
        }
        let mut rest = line;
        while let Some(i) = rest.find("](") {
            let after = &rest[i + 2..];
            let Some(end) = after.find(')') else { break };
            targets.push(after[..end].trim().to_string());
            rest = &after[end..];
        }
        let t = line.trim_start();
        if t.starts_with('[') {
            if let Some(i) = t.find("]: ") {
                targets.push(t[i + 3..].trim().to_string());
            }
        }
    }
    targets
}

/// `path` with `.` and `..` folded away, without touching the file system.
fn normalise(path: &Path) -> Option<PathBuf> {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    return None;
                }
            }
            Component::Normal(p) => out.push(p),
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(out)
}

#[test]
fn markdown_links_resolve_inside_the_repository() {
    let files = tracked_files();
    let tracked: BTreeSet<&Path> = files.iter().map(PathBuf::as_path).collect();
    let mut broken = Vec::new();
    let mut checked = 0;
    for md in files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "md"))
    {
        let content = text(md).unwrap_or_default();
        let dir = md.parent().unwrap_or(Path::new(""));
        for target in link_targets(&content) {
            let target = target.split_whitespace().next().unwrap_or("");
            let external = ["http://", "https://", "mailto:"]
                .iter()
                .any(|s| target.starts_with(s));
            let file = target.split('#').next().unwrap_or("");
            if external || file.is_empty() {
                continue;
            }
            checked += 1;
            let resolved = normalise(&dir.join(file));
            let ok = resolved
                .as_deref()
                .is_some_and(|r| tracked.contains(r) || tracked.iter().any(|t| t.starts_with(r)));
            if !ok {
                broken.push(format!("{}: ({target})", md.display()));
            }
        }
    }
    assert!(checked >= 10, "only {checked} relative links found");
    assert!(
        broken.is_empty(),
        "links that do not resolve to a tracked file of the repository:\n{}",
        broken.join("\n")
    );
}

/// The largest `rust-version` among the dependencies of the project in `dir` (its lock
/// file as it is) that build for `platforms`, with the package that declares it, and
/// the project's own.
fn msrv_of(dir: &Path, platforms: &[String]) -> ((u32, u32), String, (u32, u32)) {
    let mut c = cargo("msrv");
    c.current_dir(dir)
        .args(["metadata", "--format-version", "1", "--locked"]);
    for p in platforms {
        c.args(["--filter-platform", p]);
    }
    let out = c.output().expect("cargo runs");
    assert!(
        out.status.success(),
        "cargo metadata failed in {}: {}",
        dir.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).expect("metadata is JSON");
    let members: BTreeSet<&str> = meta["workspace_members"]
        .as_array()
        .expect("workspace_members")
        .iter()
        .filter_map(|m| m.as_str())
        .collect();
    let mut own = None;
    let mut max = ((0, 0), String::new());
    for p in meta["packages"].as_array().expect("packages") {
        let Some(rv) = p["rust_version"].as_str() else {
            continue;
        };
        let v = major_minor(rv);
        let name = format!("{} {}", p["name"].as_str().unwrap_or("?"), p["version"]);
        if members.contains(p["id"].as_str().unwrap_or("")) {
            own = Some(own.map_or(v, |o: (u32, u32)| o.min(v)));
        } else if v > max.0 {
            max = (v, name);
        }
    }
    let own = own.unwrap_or_else(|| panic!("{}: no member declares rust-version", dir.display()));
    (max.0, max.1, own)
}

/// `1.86` or `1.86.0` as (1, 86).
fn major_minor(v: &str) -> (u32, u32) {
    let mut it = v.split('.').map(|x| x.parse::<u32>().unwrap_or(0));
    (it.next().unwrap_or(0), it.next().unwrap_or(0))
}

/// The host's target triple (rustc -vV).
fn host_triple() -> String {
    let out = Command::new(std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into()))
        .arg("-vV")
        .output()
        .expect("rustc runs");
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .find_map(|l| l.strip_prefix("host: "))
        .expect("rustc -vV names the host")
        .to_string()
}

#[test]
fn rust_version_covers_every_locked_dependency() {
    let host = host_triple();
    let firmware = [host.clone(), "thumbv7em-none-eabihf".to_string()];
    for (dir, platforms) in [
        (workspace_root(), &[host.clone()][..]),
        (workspace_root().join("firmware-sketch"), &firmware[..]),
    ] {
        let (need, who, own) = msrv_of(&dir, platforms);
        eprintln!(
            "{}: rust-version {}.{}; the locked dependencies need {}.{} ({who})",
            dir.display(),
            own.0,
            own.1,
            need.0,
            need.1
        );
        assert!(
            own >= need,
            "{}: rust-version = \"{}.{}\", but {who} needs Rust {}.{}: raise rust-version \
             (Cargo.toml) or choose dependencies that build on {}.{}",
            dir.display(),
            own.0,
            own.1,
            need.0,
            need.1,
            own.0,
            own.1
        );
    }
}
