//! The `skycast` command: glue between flags and the library. See `skycast --help`.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
