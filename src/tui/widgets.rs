//! Widgets the console draws itself: image previews in text cells.

pub mod preview;
