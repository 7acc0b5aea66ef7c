//! Profiles: text that parses and passes every check is written back as
//! TOML and loads to the same profile.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use vss::profile::Profile;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let p = Path::new("fuzz.toml");
    if let Ok(prof) = Profile::from_toml(text, p) {
        let written = toml::to_string(&prof).expect("a loaded profile is written");
        let back = Profile::from_toml(&written, p).expect("a written profile loads");
        assert_eq!(back, prof);
    }
});
