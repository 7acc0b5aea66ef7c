//! The session manifest: text that parses and passes the sense checks is
//! written back (`to_toml`) and parses to the same manifest.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use vss::session::manifest::Manifest;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let p = Path::new("fuzz.toml");
    if let Ok(m) = Manifest::parse(text, p) {
        let written = m.to_toml().expect("a parsed manifest is written");
        let back = Manifest::parse(&written, p).expect("a written manifest parses");
        assert_eq!(back, m);
    }
});
