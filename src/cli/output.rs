//! File and terminal output shared by the commands: atomic writes, stdout, broken pipes.

use std::fs;
use std::io::{self, Write};
use std::path::Path;

use anyhow::{Context, Result};

/// Whether an error is (caused by) a closed stdout, which is not an error for a CLI.
pub fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain().any(|e| {
        e.downcast_ref::<io::Error>()
            .is_some_and(|io| io.kind() == io::ErrorKind::BrokenPipe)
    })
}

/// Writes `bytes` to `path` through a temporary file in the same directory and a rename, so
/// an interrupted run never leaves a half-written file under the final name.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty());
    let file_name = path
        .file_name()
        .with_context(|| format!("{}: not a file path", path.display()))?;
    let tmp = match dir {
        Some(d) => d.join(format!(".{}.tmp", file_name.to_string_lossy())),
        None => Path::new(&format!(".{}.tmp", file_name.to_string_lossy())).to_path_buf(),
    };
    fs::write(&tmp, bytes).with_context(|| format!("cannot write {}", tmp.display()))?;
    fs::rename(&tmp, path)
        .with_context(|| format!("cannot rename {} to {}", tmp.display(), path.display()))
}

/// Writes a figure as `dir/stem.svg` and `dir/stem.png`, each atomically.
pub fn write_figure(dir: &Path, stem: &str, svg: &str, png: &[u8]) -> Result<()> {
    write_atomic(&dir.join(format!("{stem}.svg")), svg.as_bytes())?;
    write_atomic(&dir.join(format!("{stem}.png")), png)
}

/// Renders a chart to SVG and PNG, writes both with [`write_figure`] and returns the SVG.
pub fn write_chart(dir: &Path, stem: &str, chart: &specfx::report::chart::Chart) -> Result<String> {
    let svg = specfx::report::chart::render_svg(chart).map_err(anyhow::Error::msg)?;
    let png = specfx::report::chart::render_png(chart).map_err(anyhow::Error::msg)?;
    write_figure(dir, stem, &svg, &png)?;
    Ok(svg)
}

/// Renders into a buffer with a writer function, then prints it to stdout in one go.
pub fn print_with(render: impl FnOnce(&mut Vec<u8>) -> io::Result<()>) -> Result<()> {
    let mut buf = Vec::new();
    render(&mut buf)?;
    let mut out = io::stdout().lock();
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

/// A progress bar on a terminal (`label`, position, ETA); elsewhere a line per step on stderr.
pub struct Progress {
    bar: Option<indicatif::ProgressBar>,
    label: String,
    len: u64,
    pos: std::sync::atomic::AtomicU64,
}

/// Starts a [`Progress`] of `len` steps.
pub fn progress(len: u64, label: &str) -> Progress {
    use std::io::IsTerminal;
    let bar = io::stderr().is_terminal().then(|| {
        let b = indicatif::ProgressBar::new(len);
        b.set_style(
            indicatif::ProgressStyle::with_template(&format!(
                "{label} {{bar:40}} {{pos}}/{{len}} eta {{eta}}"
            ))
            .expect("valid template"),
        );
        b
    });
    Progress {
        bar,
        label: label.to_string(),
        len,
        pos: std::sync::atomic::AtomicU64::new(0),
    }
}

impl Progress {
    /// One step done; `what` names it on the line printed off a terminal.
    pub fn step(&self, what: &str) {
        let pos = self.pos.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        match &self.bar {
            Some(b) => b.inc(1),
            None => eprintln!("{}: {what} ({pos}/{})", self.label, self.len),
        }
    }

    /// Clears the bar.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}
