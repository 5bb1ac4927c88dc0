//! Library of shape configurations (being written).
