//! PNG, PGM, TIFF, BMP and JPEG through `imageio` (the first byte picks the
//! format): a decoded image stays within the decoder's limit (at most
//! ~1100 pixels a byte of input plus 1 MiB); but for JPEG, which vss reads
//! and never writes, it encodes in its format and decodes back to the same
//! pixels (PNG: comment and corner too).
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use vss::formats::imageio::{ImageKind, decode_any, encode_any};

fuzz_target!(|data: &[u8]| {
    let Some((&pick, bytes)) = data.split_first() else {
        return;
    };
    let kinds = [
        ImageKind::Png,
        ImageKind::Pgm,
        ImageKind::Tiff,
        ImageKind::Bmp,
        ImageKind::Jpeg,
    ];
    let kind = kinds[usize::from(pick) % kinds.len()];
    let p = Path::new("fuzz.png");
    if let Ok((f, _notes)) = decode_any(bytes, kind, p) {
        let px = f.image.data().len() as u64;
        assert!(px <= bytes.len() as u64 * 1100 + (1 << 20), "{px} pixels");
        if kind == ImageKind::Jpeg {
            return;
        }
        let enc = encode_any(&f, kind).expect("a decoded image encodes");
        let (back, notes) = decode_any(&enc, kind, p).expect("its encoding decodes");
        assert!(notes.is_empty(), "{notes:?}");
        assert!(back.image == f.image, "pixels changed");
        if kind == ImageKind::Png {
            assert_eq!(back, f);
        }
    }
});
