//! The `arc` command line. All logic lives in [`arc_host_sim::cli`].
fn main() -> std::process::ExitCode {
    arc_host_sim::cli::main()
}
