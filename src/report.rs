//! PostScript and SVG reports (to be written).
