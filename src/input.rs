//! The files a user names, read the one way every face reads them: regular files only, within
//! a stated size limit, as UTF-8 text when text is expected; vector directories verified
//! whole; and the datapath a `--config` argument (a built-in name, a TOML file or a vector
//! directory) names. The command line, the C ABI and the Python package call these, so a
//! refused input gets the same one-line message in each.

use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::golden::verify::{VerifiedManifest, CSV_FILE};
use crate::nset::NSet;
use crate::pipeline::{Config, Datapath};

/// The largest text input (a configuration, design space, scene or manifest): 16 MiB.
pub const MAX_TEXT_BYTES: u64 = 16 << 20;

/// The largest binary input (a mesh): 1 GiB.
pub const MAX_BINARY_BYTES: u64 = 1 << 30;

/// The largest data file of a vector directory (`vectors.csv` or a hex file): 4 GiB.
pub const MAX_DATA_BYTES: u64 = 4 << 30;

type Result<T> = std::result::Result<T, Error>;

/// An input refused: `context` followed, as one line, by the error and each of its sources.
fn failed(context: &str, e: &dyn std::error::Error) -> Error {
    let mut message = format!("{context}: {e}");
    let mut source = e.source();
    while let Some(s) = source {
        message.push_str(&format!(": {s}"));
        source = s.source();
    }
    Error::Input { message }
}

/// Returns a refusal (`format!` arguments) from the function.
macro_rules! bail {
    ($($arg:tt)*) => {
        return Err(Error::Input { message: format!($($arg)*) })
    };
}

/// Refuses a path that is not a regular file (a FIFO or a device would block or never end),
/// for inputs read as a stream without a size limit (VCD traces); `what` names it in errors.
pub fn check_regular_file(path: &Path, what: &str) -> Result<()> {
    regular_file(path, what).map(|_| ())
}

/// The metadata of a regular file (following symbolic links); a dangling link is named as one.
fn regular_file(path: &Path, what: &str) -> Result<std::fs::Metadata> {
    let meta = match std::fs::metadata(path) {
        Ok(meta) => meta,
        Err(e) => {
            if let Ok(target) = std::fs::read_link(path) {
                bail!(
                    "{what}: a symbolic link to {}, which cannot be read: {e}",
                    target.display()
                );
            }
            return Err(failed(&format!("{what}: cannot read it"), &e));
        }
    };
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
    let file =
        std::fs::File::open(path).map_err(|e| failed(&format!("{what}: cannot open it"), &e))?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| failed(&format!("{what}: cannot read it"), &e))?;
    if bytes.len() as u64 > max {
        bail!("{what}: expected at most {max} bytes, it grew while being read");
    }
    log::debug!("read {} ({} bytes)", path.display(), bytes.len());
    Ok(bytes)
}

/// The text of a regular UTF-8 file of at most [`MAX_TEXT_BYTES`].
pub fn read_text(path: &Path, what: &str) -> Result<String> {
    let bytes = read_bytes(path, what, MAX_TEXT_BYTES)?;
    String::from_utf8(bytes).map_err(|e| Error::Input {
        message: format!(
            "{what}: expected UTF-8 text, got an invalid byte at offset {}",
            e.utf8_error().valid_up_to()
        ),
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

/// A verified vector directory.
pub struct VectorDir {
    /// The configuration of its manifest (unchanged: the `n` set it was written with).
    pub config: Config,
    /// The inputs of every vector, in file order: (n, raw code of c).
    pub inputs: Vec<(u32, i64)>,
}

/// The directory a `--config`/`--vectors` argument names: the directory itself, or the
/// directory of a `manifest.json` path; anything else is its own path, which
/// [`open_vectors`] refuses by name.
pub fn dir_of(path: &Path) -> PathBuf {
    if !path.is_dir() && path.file_name().is_some_and(|f| f == "manifest.json") {
        match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        }
    } else {
        path.to_path_buf()
    }
}

/// Opens and verifies the vector directory `path` names (the directory or its
/// `manifest.json`) with [`VerifiedManifest`]: the manifest's keys, its configuration, ports
/// and columns, every file's sha256, the number of vectors of every file, every value's range,
/// and the hex files against the CSV. Nothing of the directory is used unless all of it checks
/// out.
pub fn open_vectors(path: &Path) -> Result<VectorDir> {
    if let Err(e) = std::fs::metadata(path) {
        let what = if std::fs::symlink_metadata(path).is_ok()
            && e.kind() == std::io::ErrorKind::NotFound
        {
            "a dangling symbolic link".to_string()
        } else if e.kind() == std::io::ErrorKind::NotFound {
            "no such file or directory".to_string()
        } else {
            e.to_string()
        };
        bail!(
            "{}: {what}, expected a vector directory (written by specfx vectors) or its manifest.json",
            path.display()
        );
    }
    let dir = dir_of(path);
    if !dir.is_dir() {
        bail!(
            "{}: not a directory, expected a vector directory (written by specfx vectors) or its manifest.json",
            path.display()
        );
    }
    let file = dir.join("manifest.json");
    let name = file.display().to_string();
    if !file.exists() {
        bail!(
            "{}: no manifest.json (write a vector directory with specfx vectors --out {})",
            dir.display(),
            dir.display()
        );
    }
    let text = read_text(&file, &name)?;
    let manifest = VerifiedManifest::parse(&text, &name)?;
    let label = |f: &str| dir.join(f).display().to_string();
    let mut data = BTreeMap::new();
    for f in manifest.files() {
        let what = label(f);
        let bytes = read_bytes(&dir.join(f), &what, MAX_DATA_BYTES)?;
        manifest.check_sha256(f, &bytes, &what)?;
        data.insert(f.to_string(), bytes);
    }
    let csv_name = label(CSV_FILE);
    let rows = manifest.read_csv(&data[CSV_FILE], &csv_name)?;
    let inputs = manifest.inputs(&rows, &csv_name)?;
    for (j, port) in manifest.ports().iter().enumerate() {
        let f = port.file_name();
        manifest.check_hex(j, &data[&f], &label(&f), &rows)?;
    }
    Ok(VectorDir {
        config: manifest.into_config(),
        inputs,
    })
}

/// Prefixes a library error with the argument it came from, on one line.
fn within(context: &str, e: Error) -> Error {
    Error::Input {
        message: format!("{context}: {e}"),
    }
}

/// A configuration from its TOML text, as a file named `source` holds it: a text that sets no
/// `name` is named after the file's stem. Errors name `config <source>`.
pub fn config_from_toml(text: &str, source: &str) -> Result<Config> {
    let mut config = Config::from_toml(text).map_err(|e| within(&format!("config {source}"), e))?;
    let names_itself = text
        .parse::<toml::Table>()
        .is_ok_and(|t| t.contains_key("name"));
    if !names_itself {
        if let Some(stem) = Path::new(source).file_stem() {
            config.name = crate::pipeline::config::name_from(&stem.to_string_lossy());
        }
    }
    Ok(config)
}

/// The datapath a `--config` argument names: a built-in name (`baseline`; a file of that name
/// is read as `./baseline`), a TOML file (named after the file unless it sets `name`), or a
/// vector directory (or its `manifest.json`), whose manifest holds the full configuration (the
/// whole directory is verified first, see [`open_vectors`]); `n` replaces the configuration's
/// exponent set.
///
/// # Examples
/// ```
/// let dp = specfx::input::load_datapath("baseline", None).unwrap();
/// assert_eq!(dp.config().name, "baseline");
/// let err = specfx::input::load_datapath("no/such.toml", None).unwrap_err();
/// assert_eq!(
///     err.to_string(),
///     "config no/such.toml: no such file (and it is not a built-in name: baseline)"
/// );
/// ```
pub fn load_datapath(arg: &str, n: Option<&NSet>) -> Result<Datapath> {
    let path = Path::new(arg);
    let mut config = match Config::builtin(arg) {
        Some(c) => c,
        None if path.is_dir() || path.file_name().is_some_and(|f| f == "manifest.json") => {
            open_vectors(path)?.config
        }
        None if path.extension().is_some_and(|e| e == "json") => {
            bail!(
                "config {arg}: a JSON file, expected a TOML configuration, a built-in name (baseline) or a vector directory (or its manifest.json)"
            )
        }
        None => {
            // A dangling symbolic link exists as a link: read_text names it.
            if !path.exists() && path.symlink_metadata().is_err() {
                bail!("config {arg}: no such file (and it is not a built-in name: baseline)");
            }
            let text = read_text(path, &format!("config {arg}"))?;
            config_from_toml(&text, arg)?
        }
    };
    if let Some(n) = n {
        config.n = n.clone();
    }
    Datapath::new(config).map_err(|e| within(&format!("config {arg}"), e))
}

/// The datapath of a `--vectors` argument: a verified vector directory (or its
/// `manifest.json`), nothing else.
pub fn load_vectors(path: &Path) -> Result<Datapath> {
    let config = open_vectors(path)?.config;
    Datapath::new(config).map_err(|e| within(&format!("--vectors {}", path.display()), e))
}

/// The datapath of a configuration's TOML text (merged onto `baseline`, as a file is); errors
/// begin with `config:`.
///
/// # Examples
/// ```
/// let dp = specfx::input::datapath_from_toml("k = 5\nn = \"16..=64\"").unwrap();
/// assert_eq!(dp.config().k, 5);
/// assert!(specfx::input::datapath_from_toml("k = 9").is_err());
/// ```
pub fn datapath_from_toml(text: &str) -> Result<Datapath> {
    let config = Config::from_toml(text).map_err(|e| within("config", e))?;
    Datapath::new(config).map_err(|e| within("config", e))
}
