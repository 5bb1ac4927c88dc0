//! The library's layering, as docs/architecture.md states it in its table "Module: may
//! use", held against the source: every `crate::<module>` path of non-test code under
//! `host-sim/src` (and every `super::` that climbs out of a top-level module) must be
//! an edge the table allows. A failure names the file, the line and the edge. Every
//! module needs a row, so a new module adds one; an edge marked "to remove" that the
//! source no longer has fails too, so the table stays honest.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The table: per module, the modules it may use, and those of them it uses today
/// but should not (the "to remove" column).
struct Table {
    may_use: BTreeMap<String, BTreeSet<String>>,
    to_remove: BTreeSet<(String, String)>,
}

/// The backticked module names of a table cell (file names and paths are skipped).
fn names(cell: &str) -> Vec<String> {
    cell.split('`')
        .skip(1)
        .step_by(2)
        .filter(|n| !n.is_empty() && n.chars().all(|c| c.is_ascii_lowercase() || c == '_'))
        .map(String::from)
        .collect()
}

fn table(doc: &str) -> Table {
    let start = doc
        .find("## Module: may use")
        .expect("docs/architecture.md has the section \"Module: may use\"");
    let mut t = Table {
        may_use: BTreeMap::new(),
        to_remove: BTreeSet::new(),
    };
    let rows = doc[start..].lines().skip_while(|l| !l.starts_with('|'));
    for row in rows.take_while(|l| l.starts_with('|')).skip(2) {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        let module = names(cells[1]).pop().expect("a row names its module");
        let mut allowed: BTreeSet<String> = names(cells[2]).into_iter().collect();
        for edge in names(cells.get(3).copied().unwrap_or("")) {
            t.to_remove.insert((module.clone(), edge.clone()));
            allowed.insert(edge);
        }
        t.may_use.insert(module, allowed);
    }
    t
}

/// Every `.rs` file below `dir`, outside the binary's own source.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            if path.file_name().is_some_and(|n| n != "bin") {
                sources(&path, out);
            }
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The lines of `text` that are code and not tests: comments and every item under
/// `#[cfg(test)]` (a line, or a block up to its closing brace) are blanked, so that
/// line numbers stay.
fn code_lines(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut skipping = false;
    let mut depth = 0i32;
    let mut pending = false;
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        let trimmed = line.trim_start();
        if trimmed.starts_with("#[cfg(test)]") {
            pending = true;
            out.push(String::new());
            continue;
        }
        if pending && !trimmed.starts_with("#[") {
            pending = false;
            skipping = true;
            depth = 0;
        }
        if skipping {
            depth += code.matches('{').count() as i32 - code.matches('}').count() as i32;
            if depth <= 0 && (code.contains('}') || code.trim_end().ends_with(';')) {
                skipping = false;
            }
            out.push(String::new());
            continue;
        }
        out.push(if trimmed.starts_with("//") {
            String::new()
        } else {
            code.to_string()
        });
    }
    out
}

/// The top-level module a file under `src` belongs to, and whether it is a file of
/// its own at the top (where `super::` is the crate).
fn module_of(src: &Path, file: &Path) -> Option<(String, bool)> {
    let rel = file.strip_prefix(src).ok()?;
    let mut parts = rel.iter().map(|p| p.to_string_lossy().into_owned());
    let first = parts.next()?;
    let top_file = rel.components().count() == 1;
    let name = first.trim_end_matches(".rs").to_string();
    (name != "lib").then_some((name, top_file))
}

/// The first name of each path in `heads` (the parts of a `{...}` group, or one path).
fn first_names<'a>(heads: impl Iterator<Item = &'a str>) -> Vec<String> {
    heads
        .filter_map(|h| {
            let name: String = h
                .trim()
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            name.starts_with(|c: char| c.is_ascii_lowercase())
                .then_some(name)
        })
        .collect()
}

/// The modules `lines` name through `crate::` (and, in a top-level file, `super::`),
/// with the index of the line naming each; a `{...}` group may span lines.
fn used(lines: &[String], top_file: bool) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut prefixes = vec!["crate::"];
    if top_file {
        prefixes.push("super::");
    }
    let mut open_group = false;
    for (n, line) in lines.iter().enumerate() {
        if open_group {
            let inside = line.split('}').next().unwrap_or("");
            out.extend(first_names(inside.split(',')).into_iter().map(|m| (n, m)));
            open_group = !line.contains('}');
            continue;
        }
        for prefix in &prefixes {
            for (i, _) in line.match_indices(prefix) {
                // `self::super::` or `foo::crate` are not paths from the root.
                let before = line[..i].chars().last();
                if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                    continue;
                }
                let rest = &line[i + prefix.len()..];
                match rest.strip_prefix('{') {
                    Some(group) => {
                        let inside = group.split('}').next().unwrap_or("");
                        out.extend(first_names(inside.split(',')).into_iter().map(|m| (n, m)));
                        open_group = !group.contains('}');
                    }
                    None => out.extend(first_names([rest].into_iter()).into_iter().map(|m| (n, m))),
                }
            }
        }
    }
    out
}

#[test]
fn every_crate_path_is_an_edge_the_architecture_table_allows() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = fs::read_to_string(root.join("../docs/architecture.md")).unwrap();
    let t = table(&doc);
    let src = root.join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    files.sort();
    let mut forbidden = Vec::new();
    let mut seen: BTreeSet<(String, String)> = BTreeSet::new();
    let mut missing_rows = BTreeSet::new();
    for file in &files {
        let Some((module, top_file)) = module_of(&src, file) else {
            continue;
        };
        let name = file.file_name().unwrap().to_string_lossy();
        if name.ends_with("tests.rs") {
            continue;
        }
        let Some(allowed) = t.may_use.get(&module) else {
            missing_rows.insert(module);
            continue;
        };
        let text = fs::read_to_string(file).unwrap();
        for (n, target) in used(&code_lines(&text), top_file) {
            // Itself, or not a module of the crate (a macro exported at the root).
            if target == module || !is_module(&src, &target) {
                continue;
            }
            seen.insert((module.clone(), target.clone()));
            if !allowed.contains(&target) {
                let at = file.strip_prefix(root).unwrap().display();
                forbidden.push(format!("{at}:{}: {module} -> {target}", n + 1));
            }
        }
    }
    assert!(
        missing_rows.is_empty(),
        "modules without a row in docs/architecture.md's table: {missing_rows:?}"
    );
    assert!(
        forbidden.is_empty(),
        "edges the table in docs/architecture.md does not allow:\n{}",
        forbidden.join("\n")
    );
    let gone: Vec<_> = t.to_remove.difference(&seen).collect();
    assert!(
        gone.is_empty(),
        "edges marked \"to remove\" that the source no longer has (drop the note): {gone:?}"
    );
}

/// Whether `name` is a module of the crate (a file or a folder under `src`).
fn is_module(src: &Path, name: &str) -> bool {
    src.join(format!("{name}.rs")).exists() || src.join(name).join("mod.rs").exists()
}

/// The scanner's own rules: comments and test items are not code, grouped and
/// `super::` paths count, and a path of a path does not.
#[test]
fn the_scanner_reads_paths_as_the_compiler_does() {
    let text = "use crate::map::Grid;\n// crate::sim\n#[cfg(test)]\nmod tests {\n    use crate::sim;\n}\nuse crate::{plan_file::Plan, collision};\nuse crate::{\n    goal::GoalPose,\n    mission,\n};\n";
    let found = used(&code_lines(text), false);
    let at = |m: &str| (0..text.lines().count()).find(|&n| found.contains(&(n, m.into())));
    assert_eq!(at("map"), Some(0));
    assert_eq!(at("sim"), None);
    assert_eq!((at("plan_file"), at("collision")), (Some(6), Some(6)));
    assert_eq!((at("goal"), at("mission")), (Some(8), Some(9)));
    let one = |s: &str, top: bool| used(&code_lines(s), top);
    assert_eq!(one("use super::map::Grid;", true), [(0, "map".to_string())]);
    assert!(one("use super::map::Grid;", false).is_empty());
    assert!(one("x::crate::map", false).is_empty());
}
