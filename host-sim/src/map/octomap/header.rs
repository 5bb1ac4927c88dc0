//! The text header of `.bt` and `.ot` files: read the way OctoMap's
//! `AbstractOcTree::readHeader` reads it, written the way OctoMap writes it, and the
//! resolution range both ends accept.

use super::error::MapFileError;

/// Smallest resolution (metres) accepted in a file or by [`OcTree::from_voxels`].
///
/// [`OcTree::from_voxels`]: super::OcTree::from_voxels
pub const MIN_RESOLUTION: f64 = 1e-3;

/// Largest resolution (metres) accepted in a file or by [`OcTree::from_voxels`].
///
/// [`OcTree::from_voxels`]: super::OcTree::from_voxels
pub const MAX_RESOLUTION: f64 = 100.0;

/// The first line of a `.bt` file.
const BT_FIRST_LINE: &str = "# Octomap OcTree binary file";
/// The first line of a full `.ot` file.
const OT_FIRST_LINE: &str = "# Octomap OcTree file";

/// Parsed text header.
pub(super) struct Header {
    /// Which of the two formats follows the header.
    pub(super) kind: Kind,
    /// The number of nodes the header announces.
    pub(super) size: u64,
    /// Edge of the smallest voxel, metres.
    pub(super) resolution: f64,
    /// Where the binary tree starts in the file.
    pub(super) data_start: usize,
}

/// The two tree formats behind the header.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    /// `.bt`: two bytes of child codes per inner node.
    Binary,
    /// Full `.ot`: log-odds and child-exists bits per node.
    Full,
}

/// The header OctoMap writes before a tree of `nodes` nodes at `resolution`.
pub(super) fn header_text(kind: Kind, nodes: u64, resolution: f64) -> String {
    let first_line = match kind {
        Kind::Binary => BT_FIRST_LINE,
        Kind::Full => OT_FIRST_LINE,
    };
    format!(
        "{first_line}\n\
         # (feel free to add / change comments, but leave the first line as it is!)\n\
         #\n\
         id OcTree\n\
         size {nodes}\n\
         res {resolution}\n\
         data\n"
    )
}

/// `Ok` when `resolution` is one a tree may have; `name` is used in the error.
pub(super) fn check_resolution(resolution: f64, name: &str) -> Result<(), MapFileError> {
    if resolution.is_finite() && (MIN_RESOLUTION..=MAX_RESOLUTION).contains(&resolution) {
        Ok(())
    } else {
        Err(MapFileError::BadResolution {
            file: name.to_string(),
            resolution,
        })
    }
}

/// At most `max` characters of `bytes`, for error messages.
fn shorten(bytes: &[u8], max: usize) -> String {
    let text = String::from_utf8_lossy(bytes);
    let mut out: String = text.chars().take(max).collect();
    if text.chars().count() > max {
        out.push_str("...");
    }
    out
}

/// C's `isspace`, which OctoMap's `>>` uses to split the header.
fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
}

/// Reads the text header, the way OctoMap's `AbstractOcTree::readHeader` does.
pub(super) fn parse_header(bytes: &[u8], name: &str) -> Result<Header, MapFileError> {
    let (kind, mut pos) = file_kind(bytes, name)?;
    let header_err = |problem: &str| header_error(name, problem.to_string());
    let mut id: Option<&[u8]> = None;
    let mut size: Option<u64> = None;
    let mut res: Option<f64> = None;
    let data_start = loop {
        let (after, tok) = token(bytes, pos);
        pos = after;
        match tok {
            b"" => {
                return Err(header_err(
                    "the header ends without a \"data\" line (is the file truncated?)",
                ))
            }
            b"data" => break skip_line(bytes, pos),
            t if t.starts_with(b"#") => pos = skip_line(bytes, pos),
            keyword @ (b"id" | b"size" | b"res") => {
                let (after, value) = token(bytes, pos);
                pos = after;
                match keyword {
                    b"id" => id = Some(value),
                    b"size" => size = Some(parse_size(value, name)?),
                    _ => res = Some(parse_res(value, name)?),
                }
            }
            // OctoMap warns about unknown keywords and skips their line; so do we.
            _ => pos = skip_line(bytes, pos),
        }
    };
    let id = match id {
        None | Some(b"") => return Err(header_err("no \"id\" line")),
        Some(id) => id,
    };
    if id != b"OcTree" && id != b"1" {
        return Err(MapFileError::UnknownId {
            file: name.to_string(),
            id: shorten(id, 40),
        });
    }
    let Some(resolution) = res else {
        return Err(header_err("no \"res\" line"));
    };
    check_resolution(resolution, name)?;
    let Some(size) = size else {
        return Err(header_err("no \"size\" line"));
    };
    Ok(Header {
        kind,
        size,
        resolution,
        data_start,
    })
}

/// The format the first line announces, and where the second line starts.
fn file_kind(bytes: &[u8], name: &str) -> Result<(Kind, usize), MapFileError> {
    if bytes.is_empty() {
        return Err(MapFileError::Empty {
            file: name.to_string(),
        });
    }
    let line_end = bytes.iter().position(|&b| b == b'\n');
    let first_line = bytes
        .get(..line_end.unwrap_or(bytes.len()))
        .unwrap_or(bytes);
    let kind = if first_line.starts_with(BT_FIRST_LINE.as_bytes()) {
        Kind::Binary
    } else if first_line.starts_with(OT_FIRST_LINE.as_bytes()) {
        Kind::Full
    } else if bytes.get(..4) == Some(&3i32.to_le_bytes()[..]) {
        return Err(MapFileError::LegacyFormat {
            file: name.to_string(),
        });
    } else {
        return Err(MapFileError::NotOctoMap {
            file: name.to_string(),
            first_line: shorten(first_line, 60),
        });
    };
    Ok((kind, line_end.map_or(bytes.len(), |p| p + 1)))
}

/// Where the line after the one holding `pos` starts (the end of `bytes` if none).
fn skip_line(bytes: &[u8], pos: usize) -> usize {
    match bytes
        .get(pos..)
        .and_then(|rest| rest.iter().position(|&b| b == b'\n'))
    {
        Some(p) => pos + p + 1,
        None => bytes.len(),
    }
}

/// The next whitespace-separated word from `pos`, and where it ends (empty at the end).
fn token(bytes: &[u8], pos: usize) -> (usize, &[u8]) {
    let mut start = pos;
    while bytes.get(start).is_some_and(|&b| is_space(b)) {
        start += 1;
    }
    let mut end = start;
    while bytes.get(end).is_some_and(|&b| !is_space(b)) {
        end += 1;
    }
    (end, bytes.get(start..end).unwrap_or(&[]))
}

/// A [`MapFileError::Header`] for the file `name`.
fn header_error(name: &str, problem: String) -> MapFileError {
    MapFileError::Header {
        file: name.to_string(),
        problem,
    }
}

/// The value of a `size` line: digits only, as a node count.
fn parse_size(value: &[u8], name: &str) -> Result<u64, MapFileError> {
    std::str::from_utf8(value)
        .ok()
        .filter(|s| s.bytes().all(|b| b.is_ascii_digit()))
        .and_then(|s| s.parse::<u64>().ok())
        .ok_or_else(|| {
            let problem = format!("\"size {}\" is not a node count", shorten(value, 40));
            header_error(name, problem)
        })
}

/// The value of a `res` line, as a number.
fn parse_res(value: &[u8], name: &str) -> Result<f64, MapFileError> {
    std::str::from_utf8(value)
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .ok_or_else(|| {
            let problem = format!("\"res {}\" is not a number", shorten(value, 40));
            header_error(name, problem)
        })
}
