//! Maps: OctoMap files, occupancy grids, distance fields and scenario generators.
