//! Shape tables: the library (LSC), the random shapes (SRS) and their roadmap
//! (`G_SRS`) in one postcard blob, shared by the host planner and the units.
//!
//! # Format, version 1
//! Every field is postcard (varints for integers, little-endian IEEE for `f32`):
//!
//! | part | content |
//! |---|---|
//! | header | magic `b"ARCT"` (4 bytes), version `u16`, total length `u32` (4 bytes, fixed, little-endian: the length of everything before the CRC), chain parameters (`units: u8`, then `link_length`, `unit_radius`, `link_radius`, `theta_max`, `beta_max` as `f32`), `lsc_count: u8`, `srs_count: u16`, `max_degree: u8` |
//! | LSC × `lsc_count` | name (`str`, e.g. `"PN"`), shape (`2N-1` × `f32`), headings (`Option`: tag byte then `N` × `f32`) |
//! | SRS × `srs_count` | shape (`2N-1` × `f32`): a fixed-size record, so shape `k` is found without reading the others |
//! | `G_SRS` × `srs_count` | degree (`u8`), then that many neighbour indices (`u16`) |
//! | CRC | CRC-32 (ISO-HDLC, as zlib) of everything before it, 4 bytes little-endian |
//!
//! [`TableView::open`] checks all of it once (magic, version, length, CRC, chain,
//! every shape's validity, every neighbour index); afterwards lookups read straight
//! from the slice, so a unit can keep the table in flash and RAM use does not grow
//! with `N_SRS`. No input makes the decoder panic.

use serde::{Deserialize, Serialize};

use crate::lsc::{LscEntry, LscKind};
use crate::params::{ChainParams, ParamError, MAX_UNITS};
use crate::shape::Shape;
use crate::srs::{Neighbours, Srs};
use crate::validity::{check_shape, Violation};

/// The first four bytes of every table.
pub const MAGIC: [u8; 4] = *b"ARCT";
/// The format version this code writes and reads.
pub const VERSION: u16 = 1;
/// Largest roadmap degree a table may declare.
pub const MAX_DEGREE: usize = 64;

const CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

/// Every way a table can be wrong (or a buffer too small to write one).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TableError {
    /// The blob does not start with [`MAGIC`].
    WrongMagic,
    /// The version is not [`VERSION`].
    UnsupportedVersion(u16),
    /// The blob is shorter than its header says, or ends inside a record.
    Truncated,
    /// The blob is longer than its header says.
    TrailingBytes,
    /// The stored CRC does not match the content.
    CrcMismatch {
        /// CRC stored in the blob.
        stored: u32,
        /// CRC computed over the content.
        computed: u32,
    },
    /// The chain parameters in the table are not valid.
    InvalidParams(ParamError),
    /// The table was made for another chain than the one expected.
    ChainMismatch,
    /// The table holds more than the caller's storage (or the format) allows.
    CapacityExceeded,
    /// A shape is not finite or not valid (limits, self-collision).
    InvalidShape {
        /// Index over LSC shapes then SRS shapes.
        index: u16,
    },
    /// A field holds a value the format does not allow (name, count, neighbour).
    Malformed,
    /// An index asked of a view is out of range.
    NoSuchShape,
    /// The output buffer is too small for the table.
    BufferTooSmall,
}

impl core::fmt::Display for TableError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::WrongMagic => f.write_str("not a shape table (wrong magic)"),
            Self::UnsupportedVersion(v) => write!(
                f,
                "unsupported table version {v} (this build reads {VERSION})"
            ),
            Self::Truncated => f.write_str("table is truncated"),
            Self::TrailingBytes => f.write_str("table has bytes beyond its declared length"),
            Self::CrcMismatch { stored, computed } => {
                write!(
                    f,
                    "CRC mismatch: stored {stored:#010x}, computed {computed:#010x}"
                )
            }
            Self::InvalidParams(e) => write!(f, "invalid chain parameters in table: {e}"),
            Self::ChainMismatch => f.write_str("table was made for another chain"),
            Self::CapacityExceeded => f.write_str("table exceeds the capacity of this build"),
            Self::InvalidShape { index } => write!(f, "shape {index} in table is not valid"),
            Self::Malformed => f.write_str("table has a malformed field"),
            Self::NoSuchShape => f.write_str("no such shape in table"),
            Self::BufferTooSmall => f.write_str("output buffer too small for table"),
        }
    }
}

/// The table header.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Header {
    /// Always [`MAGIC`].
    pub magic: [u8; 4],
    /// Format version.
    pub version: u16,
    /// Length of everything before the CRC (bytes).
    #[serde(with = "postcard::fixint::le")]
    pub total_len: u32,
    /// The chain the shapes are for.
    pub params: ChainParams,
    /// Number of LSC entries.
    pub lsc_count: u8,
    /// Number of SRS shapes.
    pub srs_count: u16,
    /// Largest neighbour count in `G_SRS`.
    pub max_degree: u8,
}

// ---------------------------------------------------------------- writing

struct Writer<'b> {
    buf: &'b mut [u8],
    pos: usize,
}

impl Writer<'_> {
    fn put<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), TableError> {
        let rest = self
            .buf
            .get_mut(self.pos..)
            .ok_or(TableError::BufferTooSmall)?;
        let used = postcard::to_slice(v, rest)
            .map_err(|_| TableError::BufferTooSmall)?
            .len();
        self.pos += used;
        Ok(())
    }

    fn put_floats(&mut self, v: &[f32]) -> Result<(), TableError> {
        v.iter().try_for_each(|x| self.put(x))
    }
}

/// Writes a table into `buf` and returns its length. `adjacency[i]` lists the
/// neighbours of `srs[i]`. Runs on the host (or anywhere): no allocation.
pub fn encode_into<A: AsRef<[u16]>>(
    buf: &mut [u8],
    params: &ChainParams,
    lsc: &[LscEntry],
    srs: &[Shape],
    adjacency: &[A],
) -> Result<usize, TableError> {
    let params = params.validate().map_err(TableError::InvalidParams)?;
    if lsc.len() > LscKind::ALL.len()
        || srs.len() > u16::MAX as usize
        || adjacency.len() != srs.len()
    {
        return Err(TableError::CapacityExceeded);
    }
    let max_degree = adjacency
        .iter()
        .map(|a| a.as_ref().len())
        .max()
        .unwrap_or(0);
    if max_degree > MAX_DEGREE {
        return Err(TableError::CapacityExceeded);
    }
    let mut header = Header {
        magic: MAGIC,
        version: VERSION,
        total_len: 0,
        params,
        lsc_count: lsc.len() as u8,
        srs_count: srs.len() as u16,
        max_degree: max_degree as u8,
    };
    let mut w = Writer { buf, pos: 0 };
    w.put(&header)?;
    let n = params.n();
    for e in lsc {
        if e.shape.units() != n {
            return Err(TableError::ChainMismatch);
        }
        w.put(e.kind.name())?;
        w.put_floats(e.shape.as_slice())?;
        match &e.headings {
            Some(h) => {
                w.put(&1u8)?;
                w.put_floats(&h[..n])?;
            }
            None => w.put(&0u8)?,
        }
    }
    for s in srs {
        if s.units() != n {
            return Err(TableError::ChainMismatch);
        }
        w.put_floats(s.as_slice())?;
    }
    for a in adjacency {
        let a = a.as_ref();
        w.put(&(a.len() as u8))?;
        for &j in a {
            if j as usize >= srs.len() {
                return Err(TableError::Malformed);
            }
            w.put(&j)?;
        }
    }
    let total = w.pos;
    header.total_len = total as u32;
    // The header's size does not depend on total_len (fixed 4 bytes): rewrite in place.
    let end = w.pos;
    w.pos = 0;
    w.put(&header)?;
    w.pos = end;
    let crc = CRC32.checksum(&w.buf[..total]);
    let tail = w
        .buf
        .get_mut(total..total + 4)
        .ok_or(TableError::BufferTooSmall)?;
    tail.copy_from_slice(&crc.to_le_bytes());
    Ok(total + 4)
}

// ---------------------------------------------------------------- reading

fn take<'a, T: Deserialize<'a>>(bytes: &'a [u8], pos: &mut usize) -> Result<T, TableError> {
    let rest = bytes.get(*pos..).ok_or(TableError::Truncated)?;
    let (v, left) = postcard::take_from_bytes::<T>(rest).map_err(|e| match e {
        postcard::Error::DeserializeUnexpectedEnd => TableError::Truncated,
        _ => TableError::Malformed,
    })?;
    *pos += rest.len() - left.len();
    Ok(v)
}

fn take_floats<const K: usize>(
    bytes: &[u8],
    pos: &mut usize,
    n: usize,
) -> Result<[f32; K], TableError> {
    let mut v = [0.0f32; K];
    for x in v.iter_mut().take(n) {
        *x = take(bytes, pos)?;
    }
    Ok(v)
}

/// A checked, read-only view of a table in memory or flash.
#[derive(Clone, Copy, Debug)]
pub struct TableView<'a> {
    bytes: &'a [u8],
    header: Header,
    lsc_start: usize,
    srs_start: usize,
    adj_start: usize,
}

impl<'a> TableView<'a> {
    /// Checks the whole table and returns a view of it. With `expected`, the table
    /// must be for exactly that chain.
    pub fn open(bytes: &'a [u8], expected: Option<&ChainParams>) -> Result<Self, TableError> {
        if bytes.len() < MAGIC.len() {
            return Err(if MAGIC.starts_with(bytes) {
                TableError::Truncated
            } else {
                TableError::WrongMagic
            });
        }
        if bytes[..4] != MAGIC {
            return Err(TableError::WrongMagic);
        }
        let mut pos = 0;
        let header: Header = take(bytes, &mut pos)?;
        if header.version != VERSION {
            return Err(TableError::UnsupportedVersion(header.version));
        }
        let total = header.total_len as usize;
        let end = total.checked_add(4).ok_or(TableError::Truncated)?;
        if bytes.len() < end || total < pos {
            return Err(TableError::Truncated);
        }
        if bytes.len() > end {
            return Err(TableError::TrailingBytes);
        }
        let stored = u32::from_le_bytes([
            bytes[total],
            bytes[total + 1],
            bytes[total + 2],
            bytes[total + 3],
        ]);
        let computed = CRC32.checksum(&bytes[..total]);
        if stored != computed {
            return Err(TableError::CrcMismatch { stored, computed });
        }
        let params = header
            .params
            .validate()
            .map_err(TableError::InvalidParams)?;
        if expected.is_some_and(|e| *e != params) {
            return Err(TableError::ChainMismatch);
        }
        if header.lsc_count as usize > LscKind::ALL.len() || header.max_degree as usize > MAX_DEGREE
        {
            return Err(TableError::Malformed);
        }
        let content = &bytes[..total];
        let mut view = Self {
            bytes: content,
            header,
            lsc_start: pos,
            srs_start: 0,
            adj_start: 0,
        };
        view.check_records(pos)?;
        Ok(view)
    }

    /// Walks every record once: finds where each part starts and checks each value.
    fn check_records(&mut self, mut pos: usize) -> Result<(), TableError> {
        let h = self.header;
        for i in 0..h.lsc_count as usize {
            let e = self.read_lsc(&mut pos)?;
            check_shape(&h.params, &e.shape)
                .map_err(|_| TableError::InvalidShape { index: i as u16 })?;
        }
        self.srs_start = pos;
        let record = 4 * h.params.shape_dim();
        self.adj_start = self.srs_start + record * h.srs_count as usize;
        if self.adj_start > self.bytes.len() {
            return Err(TableError::Truncated);
        }
        for k in 0..h.srs_count as usize {
            let s = self.srs_shape(k)?;
            check_shape(&h.params, &s).map_err(|_: Violation| TableError::InvalidShape {
                index: (h.lsc_count as usize + k) as u16,
            })?;
        }
        pos = self.adj_start;
        for _ in 0..h.srs_count {
            let deg: u8 = take(self.bytes, &mut pos)?;
            if deg > h.max_degree {
                return Err(TableError::Malformed);
            }
            for _ in 0..deg {
                let j: u16 = take(self.bytes, &mut pos)?;
                if j >= h.srs_count {
                    return Err(TableError::Malformed);
                }
            }
        }
        if pos != self.bytes.len() {
            return Err(TableError::Malformed);
        }
        Ok(())
    }

    fn read_shape(&self, pos: &mut usize) -> Result<Shape, TableError> {
        let p = &self.header.params;
        let eta: [f32; crate::params::MAX_SHAPE_DIM] = take_floats(self.bytes, pos, p.shape_dim())?;
        Shape::from_slice(p.units, &eta[..p.shape_dim()]).map_err(|_| TableError::Malformed)
    }

    fn read_lsc(&self, pos: &mut usize) -> Result<LscEntry, TableError> {
        let name: &str = take(self.bytes, pos)?;
        let kind = LscKind::from_name(name).ok_or(TableError::Malformed)?;
        let shape = self.read_shape(pos)?;
        let headings = match take::<u8>(self.bytes, pos)? {
            0 => None,
            1 => {
                let h: [f32; MAX_UNITS] = take_floats(self.bytes, pos, self.header.params.n())?;
                if h.iter().any(|x| !x.is_finite()) {
                    return Err(TableError::Malformed);
                }
                Some(h)
            }
            _ => return Err(TableError::Malformed),
        };
        Ok(LscEntry {
            kind,
            shape,
            headings,
        })
    }

    /// The header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// The chain parameters.
    pub fn params(&self) -> &ChainParams {
        &self.header.params
    }

    /// Number of shapes: LSC entries then SRS shapes.
    pub fn shape_count(&self) -> usize {
        self.header.lsc_count as usize + self.header.srs_count as usize
    }

    /// The stored CRC-32.
    pub fn crc(&self) -> u32 {
        CRC32.checksum(self.bytes)
    }

    /// LSC entry `i`.
    pub fn lsc(&self, i: usize) -> Result<LscEntry, TableError> {
        if i >= self.header.lsc_count as usize {
            return Err(TableError::NoSuchShape);
        }
        let mut pos = self.lsc_start;
        for _ in 0..i {
            self.read_lsc(&mut pos)?;
        }
        self.read_lsc(&mut pos)
    }

    /// SRS shape `k`, read in constant time.
    pub fn srs_shape(&self, k: usize) -> Result<Shape, TableError> {
        if k >= self.header.srs_count as usize {
            return Err(TableError::NoSuchShape);
        }
        let mut pos = self.srs_start + k * 4 * self.header.params.shape_dim();
        self.read_shape(&mut pos)
    }

    /// Shape `k` over LSC entries then SRS shapes ("go to shape k").
    pub fn shape(&self, k: usize) -> Result<Shape, TableError> {
        let l = self.header.lsc_count as usize;
        if k < l {
            Ok(self.lsc(k)?.shape)
        } else {
            self.srs_shape(k - l)
        }
    }

    /// Calls `f(i, neighbours)` for every SRS shape, in order.
    pub fn for_each_adjacency(&self, mut f: impl FnMut(usize, &[u16])) -> Result<(), TableError> {
        let mut pos = self.adj_start;
        let mut list = [0u16; MAX_DEGREE];
        for i in 0..self.header.srs_count as usize {
            let deg: u8 = take(self.bytes, &mut pos)?;
            for slot in list.iter_mut().take(deg as usize) {
                *slot = take(self.bytes, &mut pos)?;
            }
            f(i, &list[..deg as usize]);
        }
        Ok(())
    }

    /// Copies the SRS and its roadmap into fixed-capacity storage.
    pub fn to_srs<const CAP: usize, const DEG: usize>(&self) -> Result<Srs<CAP, DEG>, TableError> {
        let h = &self.header;
        if h.srs_count as usize > CAP || h.max_degree as usize > DEG {
            return Err(TableError::CapacityExceeded);
        }
        let mut srs = Srs {
            params: h.params,
            shapes: heapless::Vec::new(),
            adjacency: heapless::Vec::new(),
        };
        for k in 0..h.srs_count as usize {
            srs.shapes
                .push(self.srs_shape(k)?)
                .map_err(|_| TableError::CapacityExceeded)?;
        }
        let mut overflow = false;
        self.for_each_adjacency(|_, nb| {
            let mut n = Neighbours::<DEG>::new();
            overflow |= n.extend_from_slice(nb).is_err() || srs.adjacency.push(n).is_err();
        })?;
        if overflow {
            return Err(TableError::CapacityExceeded);
        }
        Ok(srs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lsc::library;
    use crate::srs::SrsSettings;

    fn table(n: u8, count: usize, buf: &mut [u8]) -> usize {
        let p = ChainParams::new(n);
        let lib = library(&p);
        let srs = Srs::<64, 8>::generate(p, &SrsSettings::new(n, count, 5)).unwrap();
        encode_into(buf, &p, &lib.entries, &srs.shapes, &srs.adjacency).unwrap()
    }

    #[test]
    fn round_trip() {
        let mut buf = [0u8; 16384];
        let len = table(6, 40, &mut buf);
        let p = ChainParams::new(6);
        let v = TableView::open(&buf[..len], Some(&p)).unwrap();
        assert_eq!(v.shape_count(), 46);
        let lib = library(&p);
        for (i, e) in lib.entries.iter().enumerate() {
            assert_eq!(v.lsc(i).unwrap(), *e);
        }
        let srs = Srs::<64, 8>::generate(p, &SrsSettings::new(6, 40, 5)).unwrap();
        let back: Srs<64, 8> = v.to_srs().unwrap();
        assert_eq!(back.shapes, srs.shapes);
        assert_eq!(back.adjacency, srs.adjacency);
        assert_eq!(v.shape(6).unwrap(), srs.shapes[0]);
        assert_eq!(v.shape(46), Err(TableError::NoSuchShape));
    }

    #[test]
    fn another_chain_is_refused() {
        let mut buf = [0u8; 16384];
        let len = table(5, 10, &mut buf);
        let other = ChainParams {
            link_length: 0.6,
            ..ChainParams::new(5)
        };
        assert_eq!(
            TableView::open(&buf[..len], Some(&other)).unwrap_err(),
            TableError::ChainMismatch
        );
        assert_eq!(
            TableView::open(&buf[..len], Some(&ChainParams::new(6))).unwrap_err(),
            TableError::ChainMismatch
        );
    }

    #[test]
    fn every_truncation_and_every_byte_corruption_is_rejected() {
        let mut buf = [0u8; 8192];
        let len = table(3, 4, &mut buf);
        let blob = &buf[..len];
        for cut in 0..len {
            assert!(
                TableView::open(&blob[..cut], None).is_err(),
                "truncation at {cut} accepted"
            );
        }
        let mut copy = [0u8; 8192];
        for i in 0..len {
            for flip in 1..=255u8 {
                copy[..len].copy_from_slice(blob);
                copy[i] ^= flip;
                assert!(
                    TableView::open(&copy[..len], None).is_err(),
                    "flip {flip:#x} at byte {i} accepted"
                );
            }
        }
    }

    #[test]
    fn typed_errors() {
        let mut buf = [0u8; 8192];
        let len = table(3, 5, &mut buf);
        let mut b = buf;
        b[0] = b'X';
        assert_eq!(
            TableView::open(&b[..len], None).unwrap_err(),
            TableError::WrongMagic
        );
        let mut b = buf;
        b[4] = 2; // version varint
        assert_eq!(
            TableView::open(&b[..len], None).unwrap_err(),
            TableError::UnsupportedVersion(2)
        );
        assert_eq!(
            TableView::open(&buf[..len - 1], None).unwrap_err(),
            TableError::Truncated
        );
        let mut b = buf;
        b[len - 1] ^= 1;
        assert!(matches!(
            TableView::open(&b[..len], None).unwrap_err(),
            TableError::CrcMismatch { .. }
        ));
        assert_eq!(
            TableView::open(&buf[..len + 1], None).unwrap_err(),
            TableError::TrailingBytes
        );
        assert_eq!(
            TableView::open(&[], None).unwrap_err(),
            TableError::Truncated
        );
        let v = TableView::open(&buf[..len], None).unwrap();
        assert_eq!(
            v.to_srs::<4, 8>().unwrap_err(),
            TableError::CapacityExceeded
        );
        let mut small = [0u8; 64];
        let p = ChainParams::new(3);
        let lib = library(&p);
        assert_eq!(
            encode_into::<[u16; 0]>(&mut small, &p, &lib.entries, &[], &[]).unwrap_err(),
            TableError::BufferTooSmall
        );
    }

    #[test]
    fn an_invalid_shape_with_a_good_crc_is_refused() {
        // Re-encode a table whose SRS shape breaks the pitch limit: CRC is right,
        // the shape is not.
        let p = ChainParams::new(3);
        let bad = Shape::from_slice(3, &[0.0, 1.5, 0.0, 0.0, 0.0]).unwrap();
        let mut buf = [0u8; 1024];
        let len = encode_into(&mut buf, &p, &[], &[bad], &[[0u16; 0]]).unwrap();
        assert_eq!(
            TableView::open(&buf[..len], None).unwrap_err(),
            TableError::InvalidShape { index: 0 }
        );
    }
}
