//! The relay boards' replies and commands: a Numato command that parses
//! prints and parses back the same; the reply the driver takes from what a
//! board sent lies inside it and, for `readall`, gives a mask that prints
//! back in its own width; an LCUS frame that decodes encodes back to
//! itself.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vss::rig::protocol::{
    NumatoCommand, lcus_frame, lcus_parse, numato_parse_mask, numato_parse_state, numato_reply,
};

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Some(c) = NumatoCommand::parse(text)
        && let Some(t) = c.text()
    {
        assert_eq!(NumatoCommand::parse(&t), Some(c));
    }
    for sent in ["ver", "relay on 2", "relay read 2", "relay readall"] {
        if let Some((used, reply)) = numato_reply(sent, data) {
            assert!(used <= data.len());
            if let Ok(lines) = reply {
                if let Ok((mask, digits)) = numato_parse_mask(&lines) {
                    let again = vec![format!("{mask:0digits$x}")];
                    assert_eq!(numato_parse_mask(&again), Ok((mask, digits)));
                }
                let _ = numato_parse_state(&lines);
            }
        }
    }
    if let Some((relay, on)) = lcus_parse(data) {
        assert_eq!(lcus_frame(relay, on).as_ref().map(|f| &f[..]), Some(data));
    }
});
