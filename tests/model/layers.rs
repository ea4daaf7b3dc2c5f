//! The layer map of ARCHITECTURE.md holds: every `crate::` import of a source file under
//! `src/` (outside comments and `#[cfg(test)]` modules) names a module of a lower layer than
//! the file's own, as the table in ARCHITECTURE.md says, and every source file opens with its
//! `//!` line. The table is read from ARCHITECTURE.md itself, so the map and the check are one.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The layer of each top-level module, from ARCHITECTURE.md's table (`| layer | modules |
/// what |`, modules in backquotes).
fn layers() -> BTreeMap<String, u32> {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("ARCHITECTURE.md"))
            .expect("ARCHITECTURE.md");
    let mut map = BTreeMap::new();
    for line in text.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // "| 3 | `pipeline` | ... |" splits into ["", "3", "`pipeline`", "...", ""].
        if cells.len() < 4 {
            continue;
        }
        let Ok(layer) = cells[1].parse::<u32>() else {
            continue;
        };
        for module in cells[2].split(',') {
            let module = module.trim().trim_matches('`');
            assert!(
                map.insert(module.to_string(), layer).is_none(),
                "ARCHITECTURE.md lists {module} twice"
            );
        }
    }
    assert!(
        map.len() >= 10,
        "no layer table in ARCHITECTURE.md: {map:?}"
    );
    map
}

/// Every `.rs` file under `dir`, sorted.
pub fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(sources(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    out.sort();
    out
}

/// The top-level module a file of `src/` belongs to (`main.rs` is the command line's).
fn module_of(rel: &Path) -> String {
    let first = rel
        .components()
        .next()
        .unwrap()
        .as_os_str()
        .to_string_lossy();
    match first.trim_end_matches(".rs") {
        "main" => "cli".to_string(),
        m => m.to_string(),
    }
}

/// The top-level modules a source text imports through `crate::` (or, in the binary's files,
/// `specfx::`), with their line numbers; comments and everything from the first
/// `#[cfg(test)]` on are left out.
fn imports(text: &str, prefix: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let code = line.trim_start();
        if code.starts_with("#[cfg(test)]") {
            break;
        }
        if code.starts_with("//") {
            continue;
        }
        let code = code.split(" //").next().unwrap();
        let mut rest = code;
        while let Some(at) = rest.find(prefix) {
            // Not part of a longer path (`my_crate::` is not `crate::`).
            let before = rest[..at].chars().last();
            rest = &rest[at + prefix.len()..];
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
                continue;
            }
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || *c == '_')
                .collect();
            if !name.is_empty() {
                out.push((i + 1, name));
            }
        }
    }
    out
}

#[test]
fn every_import_goes_down_the_layers_and_every_file_has_its_doc_line() {
    let layers = layers();
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut problems = Vec::new();
    for path in sources(&src) {
        let rel = path.strip_prefix(&src).unwrap().to_path_buf();
        let text = std::fs::read_to_string(&path).unwrap();
        if !text.starts_with("//!") {
            problems.push(format!(
                "src/{}: does not open with a //! line",
                rel.display()
            ));
        }
        if rel == Path::new("lib.rs") {
            continue;
        }
        let own = module_of(&rel);
        let Some(&own_layer) = layers.get(&own) else {
            problems.push(format!(
                "src/{}: module {own} is in no layer of ARCHITECTURE.md",
                rel.display()
            ));
            continue;
        };
        let mut found = imports(&text, "crate::");
        if own == "cli" {
            found.extend(imports(&text, "specfx::"));
        }
        for (line, module) in found {
            if module == own {
                continue;
            }
            match layers.get(&module) {
                Some(&l) if l < own_layer => {}
                Some(&l) => problems.push(format!(
                    "src/{}:{line}: {own} (layer {own_layer}) imports {module} (layer {l})",
                    rel.display()
                )),
                None => problems.push(format!(
                    "src/{}:{line}: imports {module}, which is in no layer of ARCHITECTURE.md",
                    rel.display()
                )),
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The checker itself finds an upward import, skips comments and tests, and is not fooled by
/// a longer path.
#[test]
fn the_import_reader_sees_code_only() {
    let text = "//! doc\nuse crate::report::x;\n// crate::cli::y\nlet a = my_crate::z; // crate::w\nfn f() { crate::fixed::g(); }\n#[cfg(test)]\nmod tests { use crate::cli; }\n";
    assert_eq!(
        imports(text, "crate::"),
        [(2, "report".to_string()), (5, "fixed".to_string())]
    );
}

/// External programs have one home: no file of `src/` outside `src/tools/` names
/// `std::process::Command` (the library receives a tool as a closure; the CLI calls
/// `specfx::tools`).
/// The code lines (`src/<file>:<line>`) of the files of `src/` outside `allowed` for which
/// `pred` holds; comment lines are left out.
fn lines_outside(allowed: &[&str], pred: impl Fn(&str) -> bool) -> Vec<String> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut found = Vec::new();
    for path in sources(&src) {
        if allowed.iter().any(|a| path.starts_with(src.join(a))) {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        for (i, line) in text.lines().enumerate() {
            let code = line.trim_start();
            if !code.starts_with("//") && pred(code) {
                found.push(format!(
                    "src/{}:{}",
                    path.strip_prefix(&src).unwrap().display(),
                    i + 1
                ));
            }
        }
    }
    found
}

#[test]
fn only_tools_starts_a_process() {
    let found = lines_outside(&["tools"], |code| {
        (code.contains("process::") && code.contains("Command"))
            || (code.contains("Command::new(") && !code.contains("clap::"))
    });
    assert!(
        found.is_empty(),
        "processes started outside src/tools/: {found:?}"
    );
}

/// ARCHITECTURE.md's sixth invariant: in the library, only `tools/` (the programs' work
/// directories, the synthesis cache) and `output.rs` (result files) touch the file system.
#[test]
fn only_tools_output_and_input_touch_files() {
    let found = lines_outside(
        &["tools", "output.rs", "input.rs", "cli", "main.rs"],
        |code| {
            ["fs::", "File::", "OpenOptions"]
                .iter()
                .any(|p| code.contains(p))
        },
    );
    assert!(
        found.is_empty(),
        "file system calls outside src/tools/, src/output.rs and src/input.rs: {found:?}"
    );
}
