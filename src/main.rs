//! The `vss` binary: parse the command line, then run a subcommand or the console.

fn main() -> std::process::ExitCode {
    vss::cli::main()
}
