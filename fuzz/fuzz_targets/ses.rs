//! The `.ses` reader: three numbers that parse are written and parse back.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use vss::formats::ses::{format_ses, parse_ses};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let p = Path::new("fuzz.ses");
    if let Ok(s) = parse_ses(text, p) {
        let back = parse_ses(&format_ses(&s), p).expect("a written .ses parses");
        assert_eq!(back, s);
    }
});
