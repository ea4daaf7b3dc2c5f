//! Sets of specular exponents n, written like `16..=1024`, `16..1024` or `1,2,16..32`.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::Error;

/// The largest exponent any command accepts.
pub const N_MAX: u32 = 65_535;

/// A sorted, duplicate-free set of exponents n >= 1, with the text it was parsed from.
///
/// Ranges are inclusive at both ends whether written `a..b` or `a..=b` (hardware documents
/// say "n = 16..1024" for both ends included).
///
/// # Examples
/// ```
/// use specfx::nset::NSet;
/// let s: NSet = "1,4..=6,16..17".parse().unwrap();
/// assert_eq!(s.values(), &[1, 4, 5, 6, 16, 17]);
/// assert_eq!(s.to_string(), "1,4..=6,16..17");
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct NSet {
    text: String,
    values: Vec<u32>,
}

impl NSet {
    /// The inclusive range `lo..=hi`.
    pub fn range(lo: u32, hi: u32) -> Result<NSet, Error> {
        format!("{lo}..={hi}").parse()
    }

    /// The set of the given exponents, written as compactly as ranges allow.
    ///
    /// # Examples
    /// ```
    /// use specfx::nset::NSet;
    /// let s = NSet::from_values(&[7, 1, 2, 3, 5]).unwrap();
    /// assert_eq!(s.to_string(), "1..=3,5,7");
    /// assert_eq!(s.values(), &[1, 2, 3, 5, 7]);
    /// ```
    pub fn from_values(values: &[u32]) -> Result<NSet, Error> {
        let mut v = values.to_vec();
        v.sort_unstable();
        v.dedup();
        let mut parts = Vec::new();
        let mut i = 0;
        while i < v.len() {
            let mut j = i;
            while j + 1 < v.len() && v[j + 1] == v[j] + 1 {
                j += 1;
            }
            parts.push(if j == i {
                v[i].to_string()
            } else {
                format!("{}..={}", v[i], v[j])
            });
            i = j + 1;
        }
        parts.join(",").parse()
    }

    /// The exponents, ascending.
    pub fn values(&self) -> &[u32] {
        &self.values
    }

    /// The smallest exponent.
    pub fn min(&self) -> u32 {
        self.values[0]
    }

    /// The largest exponent.
    pub fn max(&self) -> u32 {
        self.values[self.values.len() - 1]
    }

    /// How many exponents.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Always false: a set holds at least one exponent.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
}

fn parse_n(s: &str, whole: &str) -> Result<u32, Error> {
    let out_of_range = || Error::OutOfRange {
        what: "an exponent n",
        expected: format!("a whole number in 1..={N_MAX}, digits only (in n set '{whole}')"),
        got: format!("'{s}'"),
    };
    // Digits only: `u32::from_str` would also take a leading `+`.
    let digits = s.trim();
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return Err(out_of_range());
    }
    let n: u32 = digits.parse().map_err(|_| out_of_range())?;
    if (1..=N_MAX).contains(&n) {
        Ok(n)
    } else {
        Err(out_of_range())
    }
}

impl FromStr for NSet {
    type Err = Error;
    /// Parses comma-separated items `a`, `a..b` or `a..=b`. Spaces (U+0020) are ignored
    /// around an item and an operator; any other whitespace (a tab, a line break) is refused,
    /// because the set is echoed as written into reports, TOML, CSV and Verilog comments,
    /// where it would change the file.
    fn from_str(s: &str) -> Result<Self, Error> {
        if let Some(c) = s.chars().find(|&c| c.is_whitespace() && c != ' ') {
            return Err(Error::OutOfRange {
                what: "an n set",
                expected: format!(
                    "items a, a..b or a..=b separated by ',', with spaces only between them (got {:?}, which is whitespace but not a space)",
                    c
                ),
                got: format!("'{s}'"),
            });
        }
        // Ranges are kept as written and merged before they are expanded, so that the work
        // and memory follow the text and the distinct values, not the sum of the ranges'
        // lengths (thousands of `1..65535` are still 65535 values).
        let mut ranges = Vec::new();
        for part in s.split(',') {
            let part = part.trim();
            if let Some((lo, hi)) = part.split_once("..") {
                let hi = hi.strip_prefix('=').unwrap_or(hi);
                let (lo, hi) = (parse_n(lo, s)?, parse_n(hi, s)?);
                if lo > hi {
                    return Err(Error::OutOfRange {
                        what: "a range of n",
                        expected: "written low..high".to_string(),
                        got: format!("'{part}'"),
                    });
                }
                ranges.push((lo, hi));
            } else {
                let n = parse_n(part, s)?;
                ranges.push((n, n));
            }
        }
        ranges.sort_unstable();
        let mut values: Vec<u32> = Vec::new();
        for (lo, hi) in ranges {
            let from = values.last().map_or(lo, |&last| lo.max(last + 1));
            values.extend(from..=hi);
        }
        Ok(NSet {
            text: s.trim().to_string(),
            values,
        })
    }
}

impl fmt::Display for NSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

impl TryFrom<String> for NSet {
    type Error = Error;
    fn try_from(s: String) -> Result<Self, Error> {
        s.parse()
    }
}

impl From<NSet> for String {
    fn from(s: NSet) -> String {
        s.text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_inclusive_and_merged() {
        let s: NSet = "16..18, 17..=19,3".parse().unwrap();
        assert_eq!(s.values(), &[3, 16, 17, 18, 19]);
        assert_eq!((s.min(), s.max(), s.len()), (3, 19, 5));
    }

    #[test]
    fn bad_sets_are_refused_with_the_culprit() {
        let e = "16..x".parse::<NSet>().unwrap_err().to_string();
        assert_eq!(
            e,
            "an exponent n must be a whole number in 1..=65535, digits only (in n set '16..x'), got 'x'"
        );
        assert!("0".parse::<NSet>().is_err());
        assert!("".parse::<NSet>().is_err());
        assert!("20..10".parse::<NSet>().is_err());
        assert!("70000".parse::<NSet>().is_err());
    }

    #[test]
    fn digits_only_and_spaces_around_whole_operators() {
        // docs/arithmetic.md, section 4.3: no sign; spaces around an item or an operator.
        for bad in ["+5", "1..=+3", "16.. =20", "16. .20", "- 5", "5 6", "0x10"] {
            assert!(bad.parse::<NSet>().is_err(), "{bad}");
        }
        let spaced: NSet = " 16 ..= 18 , 20 .. 21 ".parse().unwrap();
        assert_eq!(spaced.values(), &[16, 17, 18, 20, 21]);
    }

    #[test]
    fn user_text_in_errors_stays_on_one_line() {
        let e = "16..17, x\u{1b}".parse::<NSet>().unwrap_err().to_string();
        assert_eq!(
            e,
            r"an exponent n must be a whole number in 1..=65535, digits only (in n set '16..17, x\u{1b}'), got 'x\u{1b}'"
        );
    }

    /// docs/arithmetic.md 4.3 allows spaces only: a tab or a line break would reach every file
    /// that echoes the set as written.
    #[test]
    fn whitespace_other_than_spaces_is_refused() {
        for (text, c) in [
            ("16,\t32", r"'\t'"),
            ("16..17\n,20", r"'\n'"),
            ("16\r", r"'\r'"),
        ] {
            let e = text.parse::<NSet>().unwrap_err().to_string();
            assert!(
                e.starts_with(&format!(
                    "an n set must be items a, a..b or a..=b separated by ',', with spaces only between them (got {c}, which is whitespace but not a space), got '"
                )),
                "{e}"
            );
            assert!(!e.contains(['\t', '\n', '\r']), "{e}");
        }
        assert_eq!(" 16 , 32 ".parse::<NSet>().unwrap().values(), &[16, 32]);
    }

    #[test]
    fn overlapping_ranges_cost_their_distinct_values() {
        // 20000 copies of the widest range: 1.3 billion values if each were expanded.
        let text = vec!["1..65535"; 20_000].join(",");
        let s: NSet = text.parse().unwrap();
        assert_eq!((s.min(), s.max(), s.len()), (1, 65535, 65535));
        let s: NSet = "5..9,1,7..=12,3..4,12".parse().unwrap();
        assert_eq!(s.values(), &[1, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12]);
    }
}
