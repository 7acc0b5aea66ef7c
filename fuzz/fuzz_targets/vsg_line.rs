//! VSG/1 lines: a line that checks out encodes back to itself; a reply or
//! command that parses prints and parses back the same; and the scanner
//! that finds a reply behind junk only finds lines that check out, where
//! it says they are.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vss::rig::protocol::{Command, Reply, decode_line, encode_line, find_reply};

fn line_of(bytes: &[u8]) -> &[u8] {
    let b = bytes.strip_suffix(b"\n").unwrap_or(bytes);
    b.strip_suffix(b"\r").unwrap_or(b)
}

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = decode_line(data) {
        let again = encode_line(text);
        assert_eq!(decode_line(line_of(&again)), Ok(text));
        if let Some(r) = Reply::parse(text) {
            assert_eq!(Reply::parse(&r.to_string()).as_ref(), Some(&r));
            let enc = r.encode();
            let t = decode_line(line_of(&enc)).expect("an encoded reply checks out");
            assert_eq!(Reply::parse(t), Some(r));
        }
        if let Some(c) = Command::parse(text) {
            let enc = c.encode();
            let t = decode_line(line_of(&enc)).expect("an encoded command checks out");
            assert_eq!(Command::parse(t), Some(c));
        }
    }
    if let Some((start, end, r)) = find_reply(data) {
        assert!(start < end && end <= data.len());
        let line = line_of(&data[start..end]);
        assert_eq!(decode_line(line).ok().and_then(Reply::parse), Some(r));
    }
});
