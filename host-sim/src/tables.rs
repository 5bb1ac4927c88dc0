//! Shape tables on the host: build them with the core generators, write and read
//! them as the very postcard blob the units flash (`arc_core::table`), and hand the
//! planner growable copies.

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use arc_core::lsc::{library, LscEntry, LscKind};
use arc_core::srs::{build_roadmap, Neighbours, Sampler, SrsError, SrsSettings};
use arc_core::table::{encode_into, TableError, TableView};
use arc_core::validity::Violation;
use arc_core::{ChainParams, Shape};

/// Roadmap degree the host builds `G_SRS` with.
pub const DEGREE: usize = 12;

/// Settings of a table build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TableSettings {
    /// Number of random shapes `N_SRS`.
    pub srs: usize,
    /// Seed of the SRS sampler.
    pub seed: u64,
    /// Roadmap radius `r_S` (in the `C_T` metric); `None`: `arc_core::srs::default_r_s`.
    pub r_s: Option<f32>,
}

impl Default for TableSettings {
    fn default() -> Self {
        Self {
            srs: 500,
            seed: 1,
            r_s: None,
        }
    }
}

/// The tables of one chain, in growable storage.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeTables {
    /// The chain.
    pub params: ChainParams,
    /// The library shapes that are valid for this chain.
    pub lsc: Vec<LscEntry>,
    /// Library shapes left out, and why.
    pub excluded: Vec<(LscKind, Violation)>,
    /// The random shapes.
    pub srs: Vec<Shape>,
    /// `adjacency[i]`: neighbours of `srs[i]` in `G_SRS`.
    pub adjacency: Vec<Vec<u16>>,
}

/// Why tables could not be built, read or written.
#[derive(Debug, thiserror::Error)]
pub enum TablesError {
    /// SRS sampling failed.
    #[error("SRS: {0}")]
    Srs(SrsError),
    /// The table bytes are wrong.
    #[error("{path}: {error}")]
    Table {
        /// The file.
        path: String,
        /// What is wrong.
        error: TableError,
    },
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
}

impl ShapeTables {
    /// Builds the library and an SRS with its roadmap. `progress` is told how many
    /// random shapes have been sampled so far (it may be read from another thread).
    pub fn build(
        params: ChainParams,
        settings: &TableSettings,
        progress: &AtomicUsize,
    ) -> Result<Self, TablesError> {
        if settings.srs > u16::MAX as usize {
            return Err(TablesError::Srs(SrsError::Capacity));
        }
        let lib = library(&params);
        let defaults = SrsSettings::new(params.units, settings.srs, settings.seed);
        let mut sampler = Sampler::new(params, settings.seed, defaults.max_tries_per_shape);
        let mut srs = Vec::with_capacity(settings.srs);
        for i in 0..settings.srs {
            srs.push(sampler.next_shape().map_err(TablesError::Srs)?);
            progress.store(i + 1, Ordering::Relaxed);
        }
        let mut adj = vec![Neighbours::<DEGREE>::new(); srs.len()];
        build_roadmap(
            &params,
            &srs,
            settings.r_s.unwrap_or(defaults.r_s),
            &mut adj,
        );
        Ok(Self {
            params,
            lsc: lib.entries.to_vec(),
            excluded: lib.excluded.to_vec(),
            srs,
            adjacency: adj.into_iter().map(|a| a.to_vec()).collect(),
        })
    }

    /// The postcard blob (`arc_core::table` format).
    pub fn encode(&self) -> Result<Vec<u8>, TableError> {
        // Upper bound: header + LSC (name, shape, headings) + SRS + adjacency + CRC.
        let dim = self.params.shape_dim();
        let n = self.params.n();
        let bound = 64
            + self.lsc.len() * (8 + 4 * (dim + n) + 2)
            + self.srs.len() * 4 * dim
            + self
                .adjacency
                .iter()
                .map(|a| 1 + 3 * a.len())
                .sum::<usize>()
            + 4;
        let mut buf = vec![0u8; bound];
        let len = encode_into(
            &mut buf,
            &self.params,
            &self.lsc,
            &self.srs,
            &self.adjacency,
        )?;
        buf.truncate(len);
        Ok(buf)
    }

    /// Reads tables from blob bytes (`name` is used in messages).
    pub fn decode(bytes: &[u8], name: &str) -> Result<Self, TablesError> {
        let err = |error| TablesError::Table {
            path: name.to_string(),
            error,
        };
        let view = TableView::open(bytes, None).map_err(err)?;
        let params = *view.params();
        let lsc = (0..view.header().lsc_count as usize)
            .map(|i| view.lsc(i))
            .collect::<Result<Vec<_>, _>>()
            .map_err(err)?;
        let srs = (0..view.header().srs_count as usize)
            .map(|k| view.srs_shape(k))
            .collect::<Result<Vec<_>, _>>()
            .map_err(err)?;
        let mut adjacency = Vec::with_capacity(srs.len());
        view.for_each_adjacency(|_, nb| adjacency.push(nb.to_vec()))
            .map_err(err)?;
        // Library shapes absent from the table: recompute why, for reports.
        let excluded = library(&params)
            .excluded
            .into_iter()
            .filter(|(k, _)| !lsc.iter().any(|e| e.kind == *k))
            .collect();
        Ok(Self {
            params,
            lsc,
            excluded,
            srs,
            adjacency,
        })
    }

    /// Reads a table file.
    pub fn read(path: &Path) -> Result<Self, TablesError> {
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|source| TablesError::Io {
            path: name.clone(),
            source,
        })?;
        Self::decode(&bytes, &name)
    }

    /// Writes the table file atomically.
    pub fn write(&self, path: &Path) -> Result<usize, TablesError> {
        let name = path.display().to_string();
        let bytes = self.encode().map_err(|error| TablesError::Table {
            path: name.clone(),
            error,
        })?;
        crate::fsutil::write_atomic(path, &bytes)
            .map_err(|source| TablesError::Io { path: name, source })?;
        Ok(bytes.len())
    }

    /// Number of `G_SRS` edges.
    pub fn edge_count(&self) -> usize {
        self.adjacency.iter().map(Vec::len).sum::<usize>() / 2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn build_encode_decode_round_trip() {
        let p = ChainParams::new(5);
        let s = TableSettings {
            srs: 60,
            seed: 3,
            ..Default::default()
        };
        let t = ShapeTables::build(p, &s, &AtomicUsize::new(0)).unwrap();
        assert_eq!(t.srs.len(), 60);
        let bytes = t.encode().unwrap();
        let back = ShapeTables::decode(&bytes, "mem").unwrap();
        assert_eq!(back, t);
    }

    #[test]
    fn host_and_core_build_the_same_srs() {
        let p = ChainParams::new(4);
        let t = ShapeTables::build(
            p,
            &TableSettings {
                srs: 30,
                seed: 9,
                ..Default::default()
            },
            &AtomicUsize::new(0),
        )
        .unwrap();
        let core =
            arc_core::srs::Srs::<30, DEGREE>::generate(p, &SrsSettings::new(4, 30, 9)).unwrap();
        assert_eq!(t.srs, core.shapes.to_vec());
        let adj: Vec<Vec<u16>> = core.adjacency.iter().map(|a| a.to_vec()).collect();
        assert_eq!(t.adjacency, adj);
    }

    #[test]
    fn bad_file_names_the_file() {
        let e = ShapeTables::decode(b"nope", "x.tbl")
            .unwrap_err()
            .to_string();
        assert!(e.contains("x.tbl") && e.contains("magic"), "{e}");
    }
}
