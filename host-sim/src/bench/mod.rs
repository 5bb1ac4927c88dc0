//! Benchmark runs (placeholder while it is written).
