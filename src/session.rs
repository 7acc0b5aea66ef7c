//! A survey on disk (to be written).
