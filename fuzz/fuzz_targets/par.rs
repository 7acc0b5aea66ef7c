//! The `.par` reader: a parameter file that parses can be written (the
//! writer's own check agrees) and parses back to the same entries.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use vss::formats::par::{check_writable, format_par, parse_par};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let p = Path::new("fuzz.par");
    if let Ok(f) = parse_par(text, p) {
        assert!(f.entries.len() <= text.len(), "more entries than bytes");
        assert_eq!(check_writable(&f), None, "a parsed file cannot be written");
        let back = parse_par(&format_par(&f), p).expect("a written .par parses");
        assert_eq!(back, f);
    }
});
