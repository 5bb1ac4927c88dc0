//! Set of random shapes (being written).
