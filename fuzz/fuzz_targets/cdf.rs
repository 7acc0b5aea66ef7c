//! The `.cdf` reader: a description that parses is written back and parses
//! to the same parameters (unknown ones kept).
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use vss::formats::cdf::{format_cdf, parse_cdf};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let p = Path::new("fuzz.cdf");
    if let Ok(c) = parse_cdf(text, p) {
        let back = parse_cdf(&format_cdf(&c), p).expect("a written .cdf parses");
        assert_eq!(back, c);
    }
});
