//! Profile fragments several test modules build their cells from, as
//! macros that expand to string literals so that a module can `concat!`
//! them into a `const` with its own name, `[relay]`, `[survey]` and
//! `[sim]` tables; and [`quick_sim_profile`], a whole profile file for
//! the CLI tests that grab on the simulated cell.

/// Two lights, `left` (relay 0) and `right` (relay 1), and three lightings:
/// `a` left, `b` right, `c` none (the ambient image).
macro_rules! two_lights {
    () => {
        r#"
[[lights]]
name = "left"
relay = 0
[[lights]]
name = "right"
relay = 1

[[lighting]]
letter = "a"
on = ["left"]
[[lighting]]
letter = "b"
on = ["right"]
[[lighting]]
letter = "c"
on = []
"#
    };
}

/// The default cell's four lights (`lf`, `rf`, `lb`, `rb` on relays 0–3)
/// and five lightings: `a`–`d` one light each, `e` none (ambient).
macro_rules! five_lightings {
    () => {
        r#"
[[lights]]
name = "lf"
relay = 0
[[lights]]
name = "rf"
relay = 1
[[lights]]
name = "lb"
relay = 2
[[lights]]
name = "rb"
relay = 3

[[lighting]]
letter = "a"
on = ["lf"]
[[lighting]]
letter = "b"
on = ["rf"]
[[lighting]]
letter = "c"
on = ["lb"]
[[lighting]]
letter = "d"
on = ["rb"]
[[lighting]]
letter = "e"
on = []
"#
    };
}

#[allow(unused_imports)] // each test module uses some of them
pub(crate) use {five_lightings, two_lights};

/// Writes `dir/name`: the simulated cell with 64 × 64 frames, no noise
/// and 5 ms for the lights to settle, for quick `vss grab` runs.
pub fn quick_sim_profile(dir: &std::path::Path, name: &str) {
    let mut p = vss::rig::sim::cell_profile(64, 64);
    p.sim.noise = 0.0;
    p.relay.settle_ms = 5;
    std::fs::write(dir.join(name), toml::to_string(&p).expect("profile")).expect("write profile");
}

/// The arguments of `vss grab` into session `s/g` (under the current
/// folder): image `image` of camera `camera` under `lighting` (`a,b,c`),
/// on the cell of profile file `profile`, or the built-in one.
pub fn grab_args<'a>(
    profile: Option<&'a str>,
    image: &'a str,
    camera: &'a str,
    lighting: &'a str,
) -> Vec<&'a str> {
    let mut args = profile.map_or_else(Vec::new, |p| vec!["--profile", p]);
    args.extend([
        "grab",
        "--session",
        "s/g",
        "--image",
        image,
        "--camera",
        camera,
        "--lighting",
        lighting,
    ]);
    args
}
