//! Build-time constants of this unit, written by `build.rs`.

include!(concat!(env!("OUT_DIR"), "/unit_config.rs"));
