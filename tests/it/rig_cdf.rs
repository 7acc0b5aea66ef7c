//! The published `.cdf` files of the simulated cameras (`profiles/sim/`)
//! must describe exactly the cameras the simulator renders through, so they
//! never drift. Regenerate deliberately with `VSS_REGEN_CDF=1 cargo test
//! --test it rig_cdf::`.

use std::path::PathBuf;

use vss::formats::cdf::{format_cdf, read_cdf, write_cdf};
use vss::rig::sim::camera_cdf;

#[test]
fn committed_camera_files_match_the_simulated_cameras() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("profiles/sim");
    let regen = std::env::var_os("VSS_REGEN_CDF").is_some_and(|v| v == "1");
    for k in 1..=4 {
        let want = camera_cdf(k, 512, 512).expect("camera exists");
        let path = dir.join(format!("cam{k}.cdf"));
        if regen {
            std::fs::create_dir_all(&dir).expect("profiles/sim");
            write_cdf(&path, &want).expect("write cdf");
        }
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
            panic!("{}: {e} (regenerate with VSS_REGEN_CDF=1)", path.display())
        });
        assert_eq!(
            text,
            format_cdf(&want),
            "{} drifted from the simulated camera {k}; regenerate with VSS_REGEN_CDF=1",
            path.display()
        );
        // And it reads back as the same camera model.
        let back = read_cdf(&path).expect("parse");
        assert_eq!(back.camera_model(), want.camera_model());
    }
    assert!(camera_cdf(5, 512, 512).is_none() && camera_cdf(0, 512, 512).is_none());
}
