//! The `.lex`/`.ldr` reader: lines that parse are written (six decimals,
//! as the cell's other programs write them) and parse back within half a
//! millionth; written once more they come back exactly.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use vss::formats::lines::{format_lines, parse_lines};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let p = Path::new("fuzz.ldr");
    if let Ok(a) = parse_lines(text, p) {
        assert!(a.len() <= text.len(), "more segments than bytes");
        let b = parse_lines(&format_lines(&a), p).expect("written lines parse");
        assert_eq!(a.len(), b.len());
        let close = |x: f64, y: f64| (x - y).abs() <= 5e-7 + x.abs() * 1e-15;
        for (s, t) in a.iter().zip(&b) {
            for (x, y) in [
                (s.a.x, t.a.x),
                (s.a.y, t.a.y),
                (s.b.x, t.b.x),
                (s.b.y, t.b.y),
            ] {
                assert!(close(x, y), "{x} became {y}");
            }
        }
        let c = parse_lines(&format_lines(&b), p).expect("written again");
        assert_eq!(b, c);
    }
});
