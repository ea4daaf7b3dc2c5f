//! The fuzz targets' seed corpus (`fuzz/corpus/<target>/`) and every crash reproducer found
//! and fixed (`fuzz/regressions/<target>/`) through the same checks as the fuzz targets
//! (`fuzz/src/lib.rs`, included here), so they stay checked by plain `cargo test`, without the
//! fuzzer.

#[path = "../fuzz/src/lib.rs"]
mod checks;

use std::path::{Path, PathBuf};

/// The files of `fuzz/<kind>/<target>/`, sorted (none when the directory does not exist).
fn files(kind: &str, target: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz")
        .join(kind)
        .join(target);
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = entries
        .map(|e| e.expect("a directory entry").path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

/// Runs a target's check on every file of its corpus and regressions; returns how many. A
/// seed is a real input: accepted, unless its name starts with `bad_` (a real mistake, taken
/// from the bad inputs of `tests/command_line/robustness.rs` and the docs), which must be refused.
/// Reproducers may go either way: their check must only pass.
fn replay(target: &str) -> usize {
    let (_, check) = checks::TARGETS
        .iter()
        .find(|(name, _)| *name == target)
        .unwrap_or_else(|| panic!("no target {target}"));
    let mut n = 0;
    for kind in ["corpus", "regressions"] {
        for file in files(kind, target) {
            let data = std::fs::read(&file).expect("a corpus file");
            let accepted = std::panic::catch_unwind(|| check(&data))
                .unwrap_or_else(|_| panic!("{target}: {} fails its check", file.display()));
            if kind == "corpus" {
                let bad = file
                    .file_name()
                    .is_some_and(|name| name.to_string_lossy().starts_with("bad_"));
                assert_eq!(
                    accepted,
                    !bad,
                    "{target}: the seed {} is {}",
                    file.display(),
                    if accepted { "accepted" } else { "refused" }
                );
            }
            n += 1;
        }
    }
    n
}

#[test]
fn every_target_has_a_seed_corpus_and_every_directory_a_target() {
    for (target, _) in checks::TARGETS {
        assert!(
            !files("corpus", target).is_empty(),
            "fuzz/corpus/{target}/ is empty"
        );
    }
    // A reproducer or corpus directory under a name no target has would never be replayed.
    for kind in ["corpus", "regressions"] {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("fuzz")
            .join(kind);
        for entry in std::fs::read_dir(&dir).expect("the fuzz directory") {
            let name = entry.expect("an entry").file_name();
            let name = name.to_string_lossy();
            assert!(
                checks::TARGETS.iter().any(|(t, _)| *t == name),
                "fuzz/{kind}/{name}/ names no fuzz target"
            );
        }
    }
    // Every target of the fuzz crate has a check here, and the other way round.
    let manifest =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/Cargo.toml"))
            .expect("fuzz/Cargo.toml");
    let bins: Vec<&str> = manifest
        .lines()
        .filter_map(|l| l.strip_prefix("name = \""))
        .filter_map(|l| l.strip_suffix('"'))
        .filter(|name| *name != "specfx-fuzz")
        .collect();
    let mut names: Vec<&str> = checks::TARGETS.iter().map(|(t, _)| *t).collect();
    let mut bins_sorted = bins.clone();
    names.sort_unstable();
    bins_sorted.sort_unstable();
    assert_eq!(bins_sorted, names, "fuzz/Cargo.toml's [[bin]] targets");
}

/// The (name, version) pairs of a `Cargo.lock`.
fn locked_packages(path: &str) -> Vec<(String, String)> {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(path))
        .unwrap_or_else(|e| panic!("{path}: {e}"));
    let lock: toml::Table = text.parse().unwrap_or_else(|e| panic!("{path}: {e}"));
    lock["package"]
        .as_array()
        .expect("[[package]] tables")
        .iter()
        .map(|p| {
            (
                p["name"].as_str().expect("a name").to_string(),
                p["version"].as_str().expect("a version").to_string(),
            )
        })
        .collect()
}

#[test]
fn the_fuzz_targets_build_the_binarys_dependency_versions() {
    // The fuzz crate has its own lock file; every package the binary also uses must be at the
    // binary's version, or the fuzzer tests other parsers than the ones users run.
    let main = locked_packages("Cargo.lock");
    let stale: Vec<String> = locked_packages("fuzz/Cargo.lock")
        .into_iter()
        .filter(|(name, version)| {
            main.iter().any(|(n, _)| n == name) && !main.contains(&(name.clone(), version.clone()))
        })
        .map(|(name, version)| format!("{name} {version}"))
        .collect();
    assert!(
        stale.is_empty(),
        "fuzz/Cargo.lock has other versions than Cargo.lock: {stale:?}; refresh it with \
         `cp Cargo.lock fuzz/Cargo.lock && cargo metadata --manifest-path fuzz/Cargo.toml >/dev/null`"
    );
}

#[test]
fn config_corpus() {
    assert!(replay("config") > 0);
}

#[test]
fn space_corpus() {
    assert!(replay("space") > 0);
}

#[test]
fn scene_corpus() {
    assert!(replay("scene") > 0);
}

#[test]
fn nset_corpus() {
    assert!(replay("nset") > 0);
}

#[test]
fn budget_corpus() {
    assert!(replay("budget") > 0);
}

#[test]
fn format_corpus() {
    assert!(replay("format") > 0);
}

#[test]
fn manifest_corpus() {
    assert!(replay("manifest") > 0);
}

#[test]
fn mesh_obj_corpus() {
    assert!(replay("mesh_obj") > 0);
}

#[test]
fn mesh_stl_corpus() {
    assert!(replay("mesh_stl") > 0);
}

#[test]
fn trace_corpus() {
    assert!(replay("trace") > 0);
}

#[test]
fn testbench_log_corpus() {
    assert!(replay("testbench_log") > 0);
}
