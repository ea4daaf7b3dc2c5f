//! The `specfx` command-line tool: a thin layer of argument parsing and file output over the
//! library.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
