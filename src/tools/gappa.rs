//! gappa: the formal bounds of `budget` (the scripts come from `analysis::gappa`).

use std::io::{ErrorKind, Write as _};
use std::process::{Command, Stdio};

use super::{child, error, io_error};
use crate::error::Error;

/// Runs gappa on one script and returns what it printed (stderr, then stdout); `Ok(None)` when
/// gappa is not installed.
pub fn run(script: &str) -> Result<Option<String>, Error> {
    let child = child::spawn(
        Command::new("gappa")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped()),
    );
    let mut child = match child {
        Ok(c) => c,
        Err(e) if e.kind() == ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(error("gappa", format!("cannot run gappa: {e}"))),
    };
    child
        .stdin
        .take()
        .expect("piped stdin")
        .write_all(script.as_bytes())
        .map_err(|e| io_error("gappa", "cannot write to gappa", e))?;
    let out = child::wait(child).map_err(|e| io_error("gappa", "gappa did not finish", e))?;
    // gappa prints its results on stderr.
    let mut text = String::from_utf8_lossy(&out.stderr).into_owned();
    text.push_str(&String::from_utf8_lossy(&out.stdout));
    Ok(Some(text))
}
