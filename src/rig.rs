//! The cell's hardware: grabber and lights (to be written).
