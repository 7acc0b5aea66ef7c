//! Camera pixels to the cell's 8-bit grey: the pixel formats the `genicam`
//! grabber accepts and how a 10-, 12- or 16-bit sample becomes one byte of
//! a `.img` (formats.md §2: one byte per pixel).
//!
//! The reduction keeps the sample's top eight bits (a right shift by
//! depth − 8): linear, the camera's whole range onto 0–255, black stays 0
//! and full scale 255, the way a 16-bit PNG is read (its low byte
//! dropped). No rounding, which could lift full scale past 255; a sample
//! above its declared depth (a camera that sets stray high bits) is
//! clamped to 255. docs/hardware.md gives the reasons. Plain Rust, no
//! Aravis: the default build tests it too.

/// The pixel formats vss reads, by their GenICam names.
pub const PIXEL_FORMATS: [&str; 4] = ["Mono8", "Mono10", "Mono12", "Mono16"];

/// A pixel format vss reads, and its bits per sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mono {
    Mono8,
    Mono10,
    Mono12,
    Mono16,
}

impl Mono {
    /// By GenICam name (`Mono8` …); `None` for any other format.
    pub fn from_name(name: &str) -> Option<Mono> {
        Some(match name {
            "Mono8" => Mono::Mono8,
            "Mono10" => Mono::Mono10,
            "Mono12" => Mono::Mono12,
            "Mono16" => Mono::Mono16,
            _ => return None,
        })
    }

    /// By the PFNC code a GigE Vision or USB3 Vision stream carries.
    pub fn from_pfnc(code: u32) -> Option<Mono> {
        Some(match code {
            0x0108_0001 => Mono::Mono8,
            0x0110_0003 => Mono::Mono10,
            0x0110_0005 => Mono::Mono12,
            0x0110_0007 => Mono::Mono16,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            Mono::Mono8 => "Mono8",
            Mono::Mono10 => "Mono10",
            Mono::Mono12 => "Mono12",
            Mono::Mono16 => "Mono16",
        }
    }

    /// Significant bits per sample.
    pub fn bits(self) -> u32 {
        match self {
            Mono::Mono8 => 8,
            Mono::Mono10 => 10,
            Mono::Mono12 => 12,
            Mono::Mono16 => 16,
        }
    }

    /// Bytes per sample on the wire (Mono10/12 come unpacked, in two
    /// little-endian bytes).
    pub fn bytes(self) -> usize {
        if self == Mono::Mono8 { 1 } else { 2 }
    }
}

/// The 8-bit grey of a `width × height` frame of `format` samples, rows
/// packed (no padding); `None` when `raw` is shorter than the frame (a frame
/// with missing rows is never made whole by guessing).
pub fn to_grey8(format: Mono, raw: &[u8], width: usize, height: usize) -> Option<Vec<u8>> {
    let n = width.checked_mul(height)?;
    let need = n.checked_mul(format.bytes())?;
    let raw = raw.get(..need)?;
    if format == Mono::Mono8 {
        return Some(raw.to_vec());
    }
    let shift = format.bits() - 8;
    Some(
        raw.chunks_exact(2)
            .map(|s| {
                let v = u16::from_le_bytes([s[0], s[1]]) >> shift;
                v.min(255) as u8
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mono8_is_copied() {
        let raw = [0u8, 1, 2, 255, 9, 8];
        assert_eq!(to_grey8(Mono::Mono8, &raw, 3, 2), Some(raw.to_vec()));
        assert_eq!(to_grey8(Mono::Mono8, &raw, 3, 3), None, "a short frame");
    }

    #[test]
    fn deeper_samples_keep_their_top_eight_bits() {
        let le = |v: &[u16]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        // Black, one grey level (in 8 bits), full scale, a stray high bit.
        let cases = [
            (Mono::Mono10, [0u16, 4, 1023, 0x0400], [0u8, 1, 255, 255]),
            (Mono::Mono12, [0, 16, 4095, 0x1000], [0, 1, 255, 255]),
            (Mono::Mono16, [0, 256, 65535, 0x00FF], [0, 1, 255, 0]),
        ];
        for (f, samples, grey) in cases {
            assert_eq!(
                to_grey8(f, &le(&samples), 2, 2),
                Some(grey.to_vec()),
                "{}",
                f.name()
            );
            assert_eq!(
                to_grey8(f, &le(&samples[..3]), 2, 2),
                None,
                "short {}",
                f.name()
            );
        }
        // Mid-scale of each depth lands mid-scale.
        for f in [Mono::Mono10, Mono::Mono12, Mono::Mono16] {
            let mid = 1u16 << (f.bits() - 1);
            assert_eq!(to_grey8(f, &mid.to_le_bytes(), 1, 1), Some(vec![128]));
        }
    }

    #[test]
    fn names_and_codes_agree() {
        for name in PIXEL_FORMATS {
            let m = Mono::from_name(name);
            assert_eq!(m.map(|m| m.name()), Some(name));
        }
        assert_eq!(Mono::from_name("Mono12Packed"), None);
        assert_eq!(Mono::from_pfnc(0x0108_0001), Some(Mono::Mono8));
        assert_eq!(Mono::from_pfnc(0x0110_0005), Some(Mono::Mono12));
        assert_eq!(Mono::from_pfnc(0x0218_0014), None, "RGB8 is refused");
    }
}
