//! ARCHITECTURE.md's invariant 8, "one meaning, one place", for the facts that were spelled in
//! several places: the 8-bit display step (`analysis::LSB8`, never a bare `256.0`) and the range
//! of the number of squarings (`reference::lobe::K_RANGE`, `K_MAX` and `K_RANGE_TEXT`, never a
//! literal `1..=7`). Every code line of `src/` (outside comments and `#[cfg(test)]` modules) is
//! read; the one place each fact is defined is the only one allowed to spell it.

use std::path::Path;

use crate::layers::sources;

/// The code lines of a source file with their numbers: comments cut, and nothing from the
/// first `#[cfg(test)]` on (a module's tests come last).
fn code_lines(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("#[cfg(test)]") {
            break;
        }
        let code = line.split("//").next().unwrap_or("");
        if !code.trim().is_empty() {
            out.push((i + 1, code.to_string()));
        }
    }
    out
}

/// The spellings of a fact outside the one file that defines it.
fn spelled_elsewhere(spellings: &[&str], home: &str) -> Vec<String> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut found = Vec::new();
    for file in sources(&src) {
        let rel = file
            .strip_prefix(&src)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        // A module's tests (`src/fixed/tests/`) are tests, as `#[cfg(test)]` modules are.
        if rel == home || rel.contains("/tests/") {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        for (n, code) in code_lines(&text) {
            if spellings.iter().any(|s| code.contains(s)) {
                found.push(format!("src/{rel}:{n}: {}", code.trim()));
            }
        }
    }
    found
}

#[test]
fn the_display_step_is_named_once() {
    let found = spelled_elsewhere(&["256.0", "* 256", "/ 256"], "analysis/mod.rs");
    assert!(
        found.is_empty(),
        "use analysis::LSB8:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_range_of_squarings_is_named_once() {
    let found = spelled_elsewhere(&["1..=7", "2..=7", "5..=7"], "reference/lobe.rs");
    assert!(
        found.is_empty(),
        "use reference::lobe::K_RANGE, K_MAX or K_RANGE_TEXT:\n{}",
        found.join("\n")
    );
}

#[test]
fn a_spelling_in_code_is_found_and_one_in_a_comment_is_not() {
    let lines =
        code_lines("let a = x * 256.0; // 256.0\n/// 1..=7\n#[cfg(test)]\nlet b = 256.0;\n");
    assert_eq!(lines.len(), 1);
    assert!(lines[0].1.contains("256.0") && !lines[0].1.contains("//"));
}
