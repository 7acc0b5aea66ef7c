//! The `vss` binary this build made, one way for every test module (and
//! for `tests/accuracy`, which includes this file by path).

use std::process::Command;

/// A command that runs the `vss` under test. `std`'s `Command`, so it can
/// be spawned as well as run; `assert_cmd`'s `OutputAssertExt` gives it
/// `.assert()`.
pub fn vss() -> Command {
    Command::new(env!("CARGO_BIN_EXE_vss"))
}
