//! Time stamps and content hashes for the manifest: UTC RFC 3339 (from
//! [`crate::clock`], which the log and the relay state use too), and a
//! CRC-32 plus length that tells a changed input file from the one an
//! output was made from.

pub use crate::clock::{now_rfc3339, rfc3339};

/// The content hash recorded for a file: `crc32:xxxxxxxx:LEN`.
pub fn hash(bytes: &[u8]) -> String {
    format!("crc32:{:08x}:{}", crc32fast::hash(bytes), bytes.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hash_changes_with_content() {
        assert_ne!(hash(b"abc"), hash(b"abd"));
        assert_eq!(hash(b""), "crc32:00000000:0");
    }
}
