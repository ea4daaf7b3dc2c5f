//! Terminal output shared by the commands (stdout, broken pipes, the interrupt handler) and
//! the inputs a command must never write over.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use anyhow::Result;

/// Whether an error is (caused by) a closed stdout, which is not an error for a CLI.
pub fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain().any(|e| {
        e.downcast_ref::<io::Error>()
            .is_some_and(|io| io.kind() == io::ErrorKind::BrokenPipe)
    })
}

/// Standard output whose errors say that they are stdout's (a full disk behind `> file`, a
/// closed pipe), keeping the error kind so that a broken pipe is still recognised.
pub struct Stdout(io::StdoutLock<'static>);

/// Locks standard output; see [`Stdout`].
pub fn stdout() -> Stdout {
    Stdout(io::stdout().lock())
}

/// What every stdout error message begins with.
const STDOUT_ERROR: &str = "cannot write to stdout";

fn on_stdout(e: io::Error) -> io::Error {
    io::Error::new(e.kind(), format!("{STDOUT_ERROR}: {e}"))
}

/// Whether an error is (caused by) a failed write to stdout.
pub fn is_stdout_error(err: &anyhow::Error) -> bool {
    err.chain().any(|e| {
        e.downcast_ref::<io::Error>()
            .is_some_and(|io| io.to_string().starts_with(STDOUT_ERROR))
    })
}

impl Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.write(buf).map_err(on_stdout)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.0.flush().map_err(on_stdout)
    }
}

impl Drop for Stdout {
    fn drop(&mut self) {
        // Errors were reported by the explicit flush of the callers that care; a late one
        // (after a broken pipe) is not worth a panic.
        let _ = self.0.flush();
    }
}

/// `println!` on [`stdout`], returning the error (which names stdout) instead of panicking.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let mut out = $crate::cli::output::stdout();
        writeln!(out, $($arg)*).and_then(|()| out.flush())
    }};
}
pub(crate) use outln;

/// Renders into a buffer with a writer function, then prints it to stdout in one go.
pub fn print_with(render: impl FnOnce(&mut Vec<u8>) -> io::Result<()>) -> Result<()> {
    let mut buf = Vec::new();
    render(&mut buf)?;
    let mut out = stdout();
    out.write_all(&buf)?;
    out.flush()?;
    Ok(())
}

/// Prints a value as pretty JSON on stdout, with a trailing newline.
pub fn print_json(value: &impl serde::Serialize) -> Result<()> {
    print_with(|buf| {
        serde_json::to_writer_pretty(&mut *buf, value).map_err(io::Error::other)?;
        buf.push(b'\n');
        Ok(())
    })
}

/// What the interrupt message adds when the run can be resumed (set by a resumable command).
pub static RESUME_HINT: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

/// Installs the Ctrl-C / SIGTERM handler: removes this process's staging directories (the
/// previous results stay as they were) and exits with code 130.
pub fn install_interrupt_handler() {
    let _ = ctrlc::set_handler(|| {
        specfx::tools::child::end_all();
        specfx::output::remove_uncommitted();
        specfx::tools::cache::release_all();
        let hint = RESUME_HINT
            .lock()
            .ok()
            .and_then(|h| h.clone())
            .map_or(String::new(), |h| format!("; {h}"));
        let _ = writeln!(
            io::stderr(),
            "specfx: interrupted; earlier results are unchanged{hint}"
        );
        std::process::exit(130);
    });
}

/// file it names; for a vector directory (or its `manifest.json`), the manifest and every
/// file the manifest lists.
pub fn config_input(arg: &str) -> Vec<PathBuf> {
    if specfx::pipeline::Config::builtin(arg).is_some() {
        return Vec::new();
    }
    let path = Path::new(arg);
    let is_vectors = path.is_dir() || path.file_name().is_some_and(|f| f == "manifest.json");
    if !is_vectors {
        return vec![path.to_path_buf()];
    }
    let dir = specfx::input::dir_of(path);
    let manifest = dir.join("manifest.json");
    let listed: Vec<PathBuf> = fs::read_to_string(&manifest)
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .and_then(|v| {
            v.get("sha256").and_then(|h| h.as_object()).map(|h| {
                h.keys()
                    .filter(|k| !k.contains('/') && !k.starts_with('.'))
                    .map(|k| dir.join(k))
                    .collect()
            })
        })
        .unwrap_or_default();
    std::iter::once(manifest).chain(listed).collect()
}

/// [`refuse_over_inputs`].
pub fn inputs(config: &str, scene: Option<&Path>) -> Vec<(&'static str, PathBuf)> {
    let mut v = config_inputs_as("--config", config);
    if let Some(scene) = scene {
        v.push(("--scene", scene.to_path_buf()));
        v.extend(
            mesh_files(scene)
                .into_iter()
                .map(|p| ("a mesh of --scene", p)),
        );
    }
    v
}

/// The mesh files a scene file names (relative to its directory); none when it cannot be
/// read (the scene's own error comes later).
fn mesh_files(scene: &Path) -> Vec<PathBuf> {
    let dir = scene.parent().unwrap_or(Path::new(""));
    let table = fs::read_to_string(scene)
        .ok()
        .and_then(|t| t.parse::<toml::Table>().ok());
    let objects = table
        .as_ref()
        .and_then(|t| t.get("object"))
        .and_then(|o| o.as_array());
    objects
        .into_iter()
        .flatten()
        .filter_map(|o| o.get("file").and_then(|f| f.as_str()))
        .map(|f| dir.join(f))
        .collect()
}

/// [`config_input`]'s files, each labelled with the flag that named them.
pub fn config_inputs_as(flag: &'static str, arg: &str) -> Vec<(&'static str, PathBuf)> {
    config_input(arg).into_iter().map(|p| (flag, p)).collect()
}

/// Writes what determined a result into its directory: `inputs.toml` (the canonical inputs)
/// and `provenance.json` (the specfx version, the command and the inputs' sha256). Every
/// command that writes a result directory calls it (`specfx::provenance`).
pub fn write_provenance(dir: &Path, p: &specfx::provenance::Provenance) -> Result<()> {
    Ok(specfx::output::write_all_in(dir, &p.files())?)
}
