//! The `.hpo`/`.vpo` reader: an edge file that parses holds no more points
//! than its bytes allow, encodes again and parses back the same.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use vss::formats::edgefile::{POINT_LEN, encode_edges, parse_edges};

fuzz_target!(|data: &[u8]| {
    let p = Path::new("fuzz.hpo");
    if let Ok(e) = parse_edges(data, p) {
        assert!(e.points.len() * POINT_LEN <= data.len());
        let back = parse_edges(&encode_edges(&e), p).expect("an encoded edge file parses");
        assert_eq!(back, e);
    }
});
