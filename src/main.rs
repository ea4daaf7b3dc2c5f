//! The `specfx` command-line tool: a thin layer of argument parsing and file output over the
//! library.

mod cli;

fn main() -> std::process::ExitCode {
    // A file-size limit (`ulimit -f`) would kill specfx with SIGXFSZ, silently, in the middle
    // of a write: ignored, the write fails with EFBIG instead and is reported as the write
    // error it is (one line naming the file, exit code 2). Children inherit the disposition,
    // so a tool past the limit reports its failed write too.
    // SAFETY: `signal` only sets the disposition; no handler runs, and no thread exists yet.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
    cli::main()
}
