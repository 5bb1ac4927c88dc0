//! Shape tables (being written).
