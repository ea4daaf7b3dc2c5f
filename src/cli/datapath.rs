//! Parsing a set of numbers of squarings (`--k`). (A `--config` argument is read by
//! `specfx::input::load_datapath`.)

use specfx::nset::NSet;
use specfx::reference::lobe::{K_RANGE, K_RANGE_TEXT};

/// Parses a set of numbers of squarings (`--k`): the n-set notation (`4`, `3..=5`, `1,4,7`)
/// with every value in 1..=7.
pub fn parse_k_set(s: &str) -> std::result::Result<NSet, String> {
    let bad = || {
        format!(
            "expected numbers of squarings k in {K_RANGE_TEXT} (e.g. 4, 3..=5 or 1,4,7), got '{s}'"
        )
    };
    let set: NSet = s.parse().map_err(|_| bad())?;
    if set.values().iter().all(|k| K_RANGE.contains(k)) {
        Ok(set)
    } else {
        Err(bad())
    }
}
