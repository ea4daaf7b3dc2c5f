//! Reading the files a user names: regular files only (a FIFO or a device would block or
//! never end), within a stated size limit, as UTF-8 text when text is expected.

use std::io::Read;
use std::path::Path;

use anyhow::{bail, Context, Result};

/// The largest text input (a configuration, design space, scene or manifest): 16 MiB.
pub const MAX_TEXT_BYTES: u64 = 16 << 20;

/// The largest binary input (a mesh): 1 GiB.
pub const MAX_BINARY_BYTES: u64 = 1 << 30;

/// Refuses a path that is not a regular file (a FIFO or a device would block or never end),
/// for inputs read as a stream without a size limit (VCD traces); `what` names it in errors.
pub fn check_regular_file(path: &Path, what: &str) -> Result<()> {
    regular_file(path, what).map(|_| ())
}

/// The metadata of a regular file (following symbolic links); a dangling link is named as one.
fn regular_file(path: &Path, what: &str) -> Result<std::fs::Metadata> {
    let meta = std::fs::metadata(path).or_else(|e| {
        if let Ok(target) = std::fs::read_link(path) {
            bail!(
                "{what}: a symbolic link to {}, which cannot be read: {e}",
                target.display()
            );
        }
        Err(e).with_context(|| format!("{what}: cannot read it"))
    })?;
    if !meta.is_file() {
        bail!("{what}: expected a regular file, got {}", kind(&meta));
    }
    Ok(meta)
}

/// The bytes of a regular file of at most `max` bytes; `what` names it in errors
/// (e.g. "config my.toml").
pub fn read_bytes(path: &Path, what: &str, max: u64) -> Result<Vec<u8>> {
    let meta = regular_file(path, what)?;
    if meta.len() > max {
        bail!(
            "{what}: expected at most {max} bytes, got {} bytes",
            meta.len()
        );
    }
    let file = std::fs::File::open(path).with_context(|| format!("{what}: cannot open it"))?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .with_context(|| format!("{what}: cannot read it"))?;
    if bytes.len() as u64 > max {
        bail!("{what}: expected at most {max} bytes, it grew while being read");
    }
    log::debug!("read {} ({} bytes)", path.display(), bytes.len());
    Ok(bytes)
}

/// The text of a regular UTF-8 file of at most [`MAX_TEXT_BYTES`].
pub fn read_text(path: &Path, what: &str) -> Result<String> {
    let bytes = read_bytes(path, what, MAX_TEXT_BYTES)?;
    String::from_utf8(bytes).map_err(|e| {
        anyhow::anyhow!(
            "{what}: expected UTF-8 text, got an invalid byte at offset {}",
            e.utf8_error().valid_up_to()
        )
    })
}

fn kind(meta: &std::fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = meta.file_type();
    if t.is_dir() {
        "a directory"
    } else if t.is_fifo() {
        "a FIFO"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else {
        "not a regular file"
    }
}
