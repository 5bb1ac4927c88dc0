//! The `arc` command line. All logic lives in [`aerial_chain::cli`].
fn main() -> std::process::ExitCode {
    aerial_chain::cli::main()
}
