//! SVG plots of a flight (being written).
