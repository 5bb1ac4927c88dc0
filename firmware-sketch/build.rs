//! Build script of the ARC firmware.
//!
//! 1. Puts the top-level `memory.x` on the linker's search path (cortex-m-rt's
//!    `link.x` includes it).
//! 2. Makes the shape-table image for the table flash slot: a little-endian
//!    `u32` length and the table blob. The blob is the file named by `ARC_TABLE`
//!    (e.g. the output of `arc tables build`) or, by default, a table generated
//!    here with aerial-chain-core's own generators and encoder for the chain this unit is
//!    built for. With feature `corrupt-table` one byte in its middle is flipped;
//!    with feature `external-table` no table is made (the slot is flashed apart).
//! 3. Writes `unit_config.rs`: the build-time constants of this unit.
//!
//! Environment (all optional):
//! - `ARC_UNITS`  number of units N of the chain (default 6)
//! - `ARC_UNIT`   this unit's 1-based index, 1 = head (default 2)
//! - `ARC_N_SRS`  number of random shapes in a generated table (default 100)
//! - `ARC_SEED`   seed of the random shape set (default 1)
//! - `ARC_TABLE`  path of a ready table blob to link instead of generating one

use std::env;
use std::fs;
use std::path::PathBuf;

/// Reads a numeric build setting, with a default.
fn setting<T: std::str::FromStr>(name: &str, default: T) -> T {
    println!("cargo:rerun-if-env-changed={name}");
    match env::var(name) {
        Ok(v) => v
            .trim()
            .parse()
            .unwrap_or_else(|_| panic!("{name}={v:?} is not a valid number")),
        Err(_) => default,
    }
}

/// Copies memory.x, writes the table image and the unit's constants.
fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));

    // 1. memory.x lives at the top of the project; link.x does `INCLUDE memory.x`.
    let memory_x = manifest.join("../memory.x");
    fs::copy(&memory_x, out.join("memory.x"))
        .unwrap_or_else(|e| panic!("cannot copy {}: {e}", memory_x.display()));
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory_x.display());
    println!("cargo:rerun-if-changed=build.rs");

    // 2. The table image.
    let units: u8 = setting("ARC_UNITS", 6);
    let unit: u8 = setting("ARC_UNIT", 2);
    let n_srs: usize = setting("ARC_N_SRS", 100);
    let seed: u64 = setting("ARC_SEED", 1);
    assert!(
        (1..=units).contains(&unit),
        "ARC_UNIT={unit} must lie in 1..=ARC_UNITS={units}"
    );
    println!("cargo:rerun-if-env-changed=ARC_TABLE");
    let (mut blob, source) = if env::var_os("CARGO_FEATURE_EXTERNAL_TABLE").is_some() {
        (Vec::new(), "external")
    } else if let Some(path) = env::var_os("ARC_TABLE") {
        let path = PathBuf::from(path);
        println!("cargo:rerun-if-changed={}", path.display());
        let blob = fs::read(&path).unwrap_or_else(|e| panic!("ARC_TABLE={}: {e}", path.display()));
        (blob, "file")
    } else {
        (tables::generate(units, n_srs, seed), "generated")
    };
    if env::var_os("CARGO_FEATURE_CORRUPT_TABLE").is_some() && !blob.is_empty() {
        let mid = blob.len() / 2;
        blob[mid] ^= 0x5A;
    }
    let mut image = Vec::with_capacity(blob.len() + 4);
    image.extend_from_slice(&(blob.len() as u32).to_le_bytes());
    image.extend_from_slice(&blob);
    fs::write(out.join("arc_table.bin"), &image).expect("write arc_table.bin");

    // 3. The unit's constants.
    let config = format!(
        "/// Number of units N of the chain this firmware is built for (`ARC_UNITS`).\n\
         pub const UNITS: u8 = {units};\n\
         /// This unit's 1-based index in the chain, 1 = head (`ARC_UNIT`).\n\
         pub const UNIT: u8 = {unit};\n\
         /// Random shapes requested for a generated table (`ARC_N_SRS`).\n\
         pub const N_SRS_BUILT: u32 = {n_srs};\n\
         /// Bytes of the linked table image (length word + blob).\n\
         #[allow(dead_code)] // unused with feature `external-table`\n\
         pub const TABLE_IMAGE_LEN: usize = {len};\n\
         /// Where the linked table came from: \"generated\", \"file\" (`ARC_TABLE`)\n\
         /// or \"external\" (none linked: feature `external-table`).\n\
         pub const TABLE_SOURCE: &str = \"{source}\";\n",
        len = image.len(),
    );
    fs::write(out.join("unit_config.rs"), config).expect("write unit_config.rs");
}

/// Table generation with aerial-chain-core's generators and encoder (host side).
mod tables {
    use aerial_chain_core::lsc::library;
    use aerial_chain_core::srs::{build_roadmap, Neighbours, Sampler, SrsSettings};
    use aerial_chain_core::table::encode_into;
    use aerial_chain_core::{ChainParams, Shape, MAX_SHAPE_DIM, MAX_UNITS};

    /// Roadmap degree cap of a generated table: the host's
    /// (`aerial_chain::tables::DEGREE`), so both make the same bytes.
    const DEGREE: usize = 12;

    /// The table for `units` units (docs/model.md default parameters): the full
    /// library, `n_srs` random shapes from `seed` and their roadmap, built as
    /// `arc tables build --units N --srs N_SRS --seed SEED` builds it (same
    /// sampler, same roadmap radius and degree, same encoder), so the two give
    /// the same blob.
    pub fn generate(units: u8, n_srs: usize, seed: u64) -> Vec<u8> {
        let params = ChainParams::new(units)
            .validate()
            .unwrap_or_else(|e| panic!("ARC_UNITS={units}: {e}"));
        let lib = library(&params);
        let settings = SrsSettings::new(params.units, n_srs, seed);
        let mut sampler = Sampler::new(params, settings.seed, settings.max_tries_per_shape);
        let shapes: Vec<Shape> = (0..n_srs)
            .map(|_| {
                sampler
                    .next_shape()
                    .unwrap_or_else(|e| panic!("SRS sampling failed: {e}"))
            })
            .collect();
        let mut adjacency = vec![Neighbours::<DEGREE>::new(); n_srs];
        build_roadmap(&params, &shapes, settings.r_s, &mut adjacency);
        // Generous upper bound of the encoded size (postcard varints are shorter).
        let lsc_bytes = 8 + 4 * MAX_SHAPE_DIM + 1 + 4 * MAX_UNITS;
        let capacity = 64 + 6 * lsc_bytes + n_srs * (4 * MAX_SHAPE_DIM + 1 + 3 * DEGREE) + 4;
        let mut buf = vec![0u8; capacity];
        let len = encode_into(&mut buf, &params, &lib.entries, &shapes, &adjacency)
            .unwrap_or_else(|e| panic!("table encoding failed: {e}"));
        buf.truncate(len);
        buf
    }
}
