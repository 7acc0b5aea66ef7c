//! The `.img` reader: a file that parses encodes again and parses back to
//! the same image, comment and corner, and its pixels are the file's bytes
//! (no allocation beyond the input).
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use vss::formats::img::{encode_img, parse_img};

fuzz_target!(|data: &[u8]| {
    let p = Path::new("fuzz.img");
    if let Ok(f) = parse_img(data, p) {
        assert!(f.image.data().len() <= data.len(), "more pixels than bytes");
        let bytes = encode_img(&f).expect("a parsed image encodes");
        let back = parse_img(&bytes, p).expect("an encoded image parses");
        assert_eq!(back, f);
    }
});
