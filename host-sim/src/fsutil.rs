//! File output that is never lost or half-written: write to a temporary file in the
//! destination's directory, then rename it over the destination. The path `-` names
//! standard output (and standard input where a command reads a file). Files are told
//! apart by their ending in one way, and a file format's JSON text is read in one way:
//! parsed, then checked by the format's rules.

use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` atomically (temporary file + rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::NamedTempFile::new_in(dir).map_err(|e| in_directory(dir, e))?;
    tmp.write_all(bytes)?;
    // Temporary files are created private (0600); the result is an ordinary file.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(0o644))?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// The error of creating the temporary file in `dir`, told in terms of `dir` (the
/// temporary file's own name means nothing to the user).
fn in_directory(dir: &Path, e: std::io::Error) -> std::io::Error {
    let what = match e.kind() {
        std::io::ErrorKind::NotFound => "does not exist".to_string(),
        std::io::ErrorKind::PermissionDenied => "is not writable".to_string(),
        kind => format!("cannot take a new file ({kind})"),
    };
    std::io::Error::new(e.kind(), format!("the directory {} {what}", dir.display()))
}

/// Whether `path` is `-`: standard input or output rather than a file.
pub fn is_stdio(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// How messages name an input `path`: `standard input` for `-`, else the path.
pub fn input_name(path: &Path) -> String {
    if is_stdio(path) {
        "standard input".into()
    } else {
        path.display().to_string()
    }
}

/// How messages name an output `path`: `standard output` for `-`, else the path.
pub fn output_name(path: &Path) -> String {
    if is_stdio(path) {
        "standard output".into()
    } else {
        path.display().to_string()
    }
}

/// The whole text of `path`, or of standard input when `path` is `-`.
pub fn read_input(path: &Path) -> std::io::Result<String> {
    use std::io::Read;
    let mut text = String::new();
    if is_stdio(path) {
        std::io::stdin().read_to_string(&mut text)?;
    } else {
        std::fs::File::open(path)?.read_to_string(&mut text)?;
    }
    Ok(text)
}

/// The entry of `table` (a lower-case ending without its dot, and what it names) that
/// `path` ends in, in any case.
pub fn by_extension<T: Copy>(path: &Path, table: &[(&str, T)]) -> Option<T> {
    let ending = path.extension()?.to_str()?.to_ascii_lowercase();
    table.iter().find(|(e, _)| *e == ending).map(|&(_, t)| t)
}

/// `text` parsed as a JSON file of `format` and checked by `check`; `Err` says what is
/// wrong (not JSON of the file's shape, or the rule `check` found broken), for the
/// caller to name the file.
pub fn parse_checked<T, R, E>(
    text: &str,
    format: &str,
    check: impl FnOnce(&T) -> Result<R, E>,
) -> Result<T, String>
where
    T: serde::de::DeserializeOwned,
    E: std::fmt::Display,
{
    let file: T = serde_json::from_str(text).map_err(|e| not_of_format(text, format, &e))?;
    check(&file).map_err(|e| e.to_string())?;
    Ok(file)
}

/// Why `text` did not parse as a JSON file of `format` (`e`, serde's error): where
/// its `format` field names another format, that (a plan given where a trajectory is
/// asked for fails on some field deep inside, which says nothing of the mistake);
/// else serde's error.
pub fn not_of_format(text: &str, format: &str, e: &serde_json::Error) -> String {
    #[derive(serde::Deserialize)]
    struct Tagged {
        format: String,
    }
    match serde_json::from_str::<Tagged>(text) {
        Ok(t) if t.format != format => {
            format!(
                "this is an {:?} file; an {format} file is expected here",
                t.format
            )
        }
        _ => format!("not an {format} JSON file: {e}"),
    }
}

/// Writes `bytes` to standard output when `path` is `-`, else atomically to the file.
pub fn write_output(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    if is_stdio(path) {
        let mut out = std::io::stdout().lock();
        out.write_all(bytes)?;
        return out.flush();
    }
    write_atomic(path, bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_and_replaces() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.bin");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(&p).unwrap().permissions().mode() & 0o777;
            assert_eq!(mode, 0o644, "readable like any other output file");
        }
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "no temporary file left"
        );
    }

    #[test]
    fn a_file_of_another_format_is_named_by_its_format() {
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct Wanted {
            format: String,
            samples: Vec<f64>,
        }
        let check = |_: &Wanted| Ok::<(), String>(());
        let other = r#"{"format": "arc-plan/1", "waypoints": []}"#;
        let e = parse_checked::<Wanted, _, _>(other, "arc-trajectory/1", check).unwrap_err();
        assert_eq!(
            e,
            r#"this is an "arc-plan/1" file; an arc-trajectory/1 file is expected here"#
        );
        // The right format with a bad field still says which field.
        let bad = r#"{"format": "arc-trajectory/1", "samples": "x"}"#;
        let e = parse_checked::<Wanted, _, _>(bad, "arc-trajectory/1", check).unwrap_err();
        assert!(
            e.starts_with("not an arc-trajectory/1 JSON file: invalid type"),
            "{e}"
        );
    }

    #[test]
    fn missing_directory_is_an_error_that_names_it() {
        let e = write_atomic(Path::new("/nonexistent-dir-arc/x"), b"x").unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::NotFound);
        assert_eq!(
            e.to_string(),
            "the directory /nonexistent-dir-arc does not exist"
        );
    }
}
