//! The cell's file formats (to be written).
