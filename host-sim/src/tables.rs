//! Shape tables on the host: build them with the core generators, write and read
//! them as the very postcard blob the units flash (`aerial_chain_core::table`), and hand the
//! planner growable copies.

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use aerial_chain_core::lsc::LIMIT_MARGIN;
use aerial_chain_core::lsc::{library, LscEntry, LscKind};
use aerial_chain_core::srs::{
    nearest_later, Candidates, Neighbours, Sampler, SrsError, SrsSettings,
};
use aerial_chain_core::table::{encode_into, TableError, TableView};
use aerial_chain_core::validity::{check_transition, Violation};
use aerial_chain_core::{ChainParams, Shape};
use rayon::prelude::*;

use crate::shape_index::ShapeIndex;

/// Roadmap degree the host builds `G_SRS` with.
pub const DEGREE: usize = 12;

/// Settings of a table build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TableSettings {
    /// Number of random shapes `N_SRS`.
    pub srs: usize,
    /// Seed of the SRS sampler.
    pub seed: u64,
    /// Roadmap radius `r_S` (in the `C_T` metric); `None`: `aerial_chain_core::srs::default_r_s`.
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

/// How [`roadmap`] finds each shape's roadmap candidates. Both give the core's
/// candidates bit for bit; they differ only in speed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CandidateSearch {
    /// Shapes sorted by head yaw; each shape's later shapes within the head-yaw window
    /// `C_T^2 >= N dpsi1_r^2` allows are all measured.
    YawWindow,
    /// A k-d tree over all angles (`ShapeIndex`): boxes that cannot hold a nearer
    /// shape than those found so far are skipped.
    KdTree,
}

/// `G_SRS` as the core's `build_roadmap` makes it, bit for bit, without comparing
/// every pair: each shape's candidates are found with `search` (in parallel: they are
/// independent), then joined in order as the core's `connect` does.
pub fn roadmap(
    params: &ChainParams,
    shapes: &[Shape],
    r_s: f32,
    search: CandidateSearch,
) -> Vec<Neighbours<DEGREE>> {
    let near = match search {
        CandidateSearch::YawWindow => yaw_window_candidates(params, shapes, r_s),
        CandidateSearch::KdTree => {
            let index = ShapeIndex::new(shapes);
            (0..shapes.len())
                .into_par_iter()
                .map(|i| index.nearest_later::<DEGREE>(shapes, i, r_s))
                .collect()
        }
    };
    join_candidates(params, shapes, &near)
}

/// The core's candidates of every shape, from a head-yaw window:
/// `C_T^2 >= N dpsi1_r^2`, so only shapes whose head yaw lies within `r_s / sqrt(N)` of
/// a shape's can be its neighbours.
fn yaw_window_candidates(
    params: &ChainParams,
    shapes: &[Shape],
    r_s: f32,
) -> Vec<Candidates<DEGREE>> {
    let n = params.units as f32;
    // A little wider than the bound, for rounding in the core's angle differences.
    let w = (r_s * r_s / n).sqrt() * (1.0 + 1e-4) + 1e-5;
    let mut by_yaw: Vec<(f32, usize)> = shapes
        .iter()
        .enumerate()
        .map(|(i, s)| (aerial_chain_core::angle::wrap(s.head_yaw()), i))
        .collect();
    by_yaw.sort_by(|a, b| a.0.total_cmp(&b.0));
    let yaws: Vec<f32> = by_yaw.iter().map(|p| p.0).collect();
    let window = |y: f32| -> Vec<(f32, f32)> {
        use std::f32::consts::{PI, TAU};
        if w >= PI {
            return vec![(f32::NEG_INFINITY, f32::INFINITY)];
        }
        let mut v = vec![(y - w, y + w)];
        if y - w < -PI {
            v.push((y - w + TAU, f32::INFINITY));
        }
        if y + w > PI {
            v.push((f32::NEG_INFINITY, y + w - TAU));
        }
        v
    };
    (0..shapes.len())
        .into_par_iter()
        .map(|i| {
            let mut later: Vec<usize> = Vec::new();
            for (lo, hi) in window(aerial_chain_core::angle::wrap(shapes[i].head_yaw())) {
                let a = yaws.partition_point(|&y| y < lo);
                let b = yaws.partition_point(|&y| y <= hi);
                later.extend(by_yaw[a..b].iter().map(|p| p.1).filter(|&j| j > i));
            }
            later.sort_unstable();
            later.dedup();
            nearest_later::<DEGREE>(shapes, i, r_s, later.into_iter())
        })
        .collect()
}

/// Joins every shape to its candidates `near`, as the core's `connect` does.
fn join_candidates(
    params: &ChainParams,
    shapes: &[Shape],
    near: &[Candidates<DEGREE>],
) -> Vec<Neighbours<DEGREE>> {
    // The transition checks dominate. A pair is joined only while neither list is
    // full, and a full list stays full: so block by block, check in parallel only the
    // pairs whose lists both have room before the block, then join the block in order
    // exactly as the core's `connect` does (a pair left unchecked is one it skips).
    // Small blocks waste fewer checks on pairs whose lists fill within the block.
    const BLOCK: usize = 256;
    let mut adj = vec![Neighbours::<DEGREE>::new(); shapes.len()];
    for start in (0..shapes.len()).step_by(BLOCK) {
        let end = (start + BLOCK).min(shapes.len());
        let valid: Vec<Vec<Option<bool>>> = (start..end)
            .into_par_iter()
            .map(|i| {
                near[i]
                    .iter()
                    .map(|&(_, j)| {
                        let j = j as usize;
                        (!adj[i].is_full() && !adj[j].is_full()).then(|| {
                            check_transition(params, &shapes[i], &shapes[j], LIMIT_MARGIN).is_ok()
                        })
                    })
                    .collect()
            })
            .collect();
        for (i, valid) in (start..end).zip(valid) {
            for (&(_, j), ok) in near[i].iter().zip(valid) {
                let j = j as usize;
                if !adj[i].is_full() && !adj[j].is_full() && ok == Some(true) {
                    let _ = adj[i].push(j as u16);
                    let _ = adj[j].push(i as u16);
                }
            }
        }
    }
    adj
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
        let adj = roadmap(
            &params,
            &srs,
            settings.r_s.unwrap_or(defaults.r_s),
            CandidateSearch::KdTree,
        );
        Ok(Self {
            params,
            lsc: lib.entries.to_vec(),
            excluded: lib.excluded.to_vec(),
            srs,
            adjacency: adj.into_iter().map(|a| a.to_vec()).collect(),
        })
    }

    /// The postcard blob (`aerial_chain_core::table` format).
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
    fn both_searches_give_the_cores_roadmap_bit_for_bit() {
        // Small N (narrow yaw windows, with wrap-around) and a larger one (windows
        // covering the circle), default and wide radii.
        for (units, count, r_s) in [
            (3u8, 900, None),
            (3, 400, Some(1.2)),
            (6, 300, None),
            (10, 150, None),
        ] {
            let p = ChainParams::new(units);
            let mut sampler = Sampler::new(p, 7, 100_000);
            let shapes: Vec<Shape> = (0..count).map(|_| sampler.next_shape().unwrap()).collect();
            let r_s = r_s.unwrap_or(SrsSettings::new(units, count, 7).r_s);
            let mut core = vec![Neighbours::<DEGREE>::new(); count];
            aerial_chain_core::srs::build_roadmap(&p, &shapes, r_s, &mut core);
            for search in [CandidateSearch::YawWindow, CandidateSearch::KdTree] {
                let host = roadmap(&p, &shapes, r_s, search);
                assert_eq!(host, core, "N = {units}, {search:?}");
            }
            assert!(core.iter().map(|a| a.len()).sum::<usize>() > count);
        }
    }

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
            aerial_chain_core::srs::Srs::<30, DEGREE>::generate(p, &SrsSettings::new(4, 30, 9))
                .unwrap();
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
