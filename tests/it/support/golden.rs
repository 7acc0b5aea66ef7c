//! Committed golden files under `tests/golden/`: where they are, whether
//! this run rewrites them (`VSS_REGEN=1`), and a byte-for-byte comparison
//! of a text file that shows the rows that differ.

use std::path::{Path, PathBuf};

/// `tests/golden/NAME`.
pub fn dir(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(name)
}

/// Whether this run rewrites the golden files instead of comparing
/// (`VSS_REGEN=1`).
pub fn regen() -> bool {
    std::env::var_os("VSS_REGEN").is_some_and(|v| v == "1")
}

/// Compares `made` byte for byte with the golden text file `path` (with
/// `VSS_REGEN=1`, writes it instead); on a difference, the error shows the
/// rows that differ ([`row_diff`]). `how` is the command that regenerates,
/// without `VSS_REGEN=1`.
pub fn compare_text(path: &Path, made: &str, how: &str) -> Result<(), String> {
    if regen() {
        if let Some(d) = path.parent() {
            std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
        }
        return std::fs::write(path, made).map_err(|e| format!("{}: {e}", path.display()));
    }
    let kept = std::fs::read(path)
        .map_err(|e| format!("{}: {e} (write it with VSS_REGEN=1 {how})", path.display()))?;
    if kept == made.as_bytes() {
        return Ok(());
    }
    Err(format!(
        "{} differs (if the change is intended, regenerate with VSS_REGEN=1 {how} \
         and review the diff) in {}",
        path.display(),
        row_diff(&String::from_utf8_lossy(&kept), made)
    ))
}

/// The rows of `made` that differ from `kept`, numbered from 1, each
/// expected row above the row made.
pub fn row_diff(kept: &str, made: &str) -> String {
    let want: Vec<&str> = kept.split('\n').collect();
    let got: Vec<&str> = made.split('\n').collect();
    let mut rows = Vec::new();
    for i in 0..want.len().max(got.len()) {
        let (w, g) = (want.get(i), got.get(i));
        if w != g {
            rows.push(format!(
                "row {:>2} expected |{}|\n       got      |{}|",
                i + 1,
                w.copied().unwrap_or("(no row)"),
                g.copied().unwrap_or("(no row)")
            ));
        }
    }
    if rows.is_empty() {
        return "no row: the bytes differ only in their encoding".into();
    }
    format!("{} row(s):\n{}", rows.len(), rows.join("\n"))
}
