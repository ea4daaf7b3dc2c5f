//! Loading a datapath from `--config FILE|baseline` and `--n SET` on the command line.

use std::path::Path;

use anyhow::{Context, Result};

use specfx::nset::NSet;
use specfx::pipeline::{Config, Datapath};

/// Reads a configuration: a built-in name (`baseline`) or a TOML file, then applies `--n`.
pub fn load(arg: &str, n: Option<&NSet>) -> Result<Datapath> {
    let path = Path::new(arg);
    let mut config = match Config::builtin(arg) {
        Some(c) if !path.exists() => c,
        _ => {
            let text = std::fs::read_to_string(path).with_context(|| {
                format!("config {arg}: cannot read it (and it is not a built-in name: baseline)")
            })?;
            Config::from_toml(&text).with_context(|| format!("config {arg}"))?
        }
    };
    if let Some(n) = n {
        config.n = n.clone();
    }
    Datapath::new(config).with_context(|| format!("config {arg}"))
}
