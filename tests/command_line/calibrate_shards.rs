//! `specfx calibrate --shard` and `calibrate merge` without yosys: records of the committed
//! sample split into shard directories merge back into the committed file's bytes (in index
//! order, whatever the shards' order), together with records already in `--data`; a record of
//! another shard, another seed, or two different records of one configuration are refused in
//! one line, exit code 2, and nothing is written.

use std::path::Path;
use std::process::Output;

use crate::common::specfx;

/// The first `n` lines of the committed iCE40 records.
fn committed(n: usize) -> Vec<String> {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/calibration/ice40.jsonl"),
    )
    .unwrap();
    text.lines().take(n).map(|l| format!("{l}\n")).collect()
}

fn write(dir: &Path, lines: &[&String]) {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(
        dir.join("ice40.jsonl"),
        lines.iter().map(|l| l.as_str()).collect::<String>(),
    )
    .unwrap();
}

fn refused(o: &Output, want: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains(want), "expected '{want}' in {err}");
}

#[test]
fn calibration_shards_merge_into_the_one_file_and_conflicts_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let lines = committed(7);
    // Three shards of indexes 0..7 (i mod 3), index 6 already in --data.
    for s in 0..3 {
        let mine: Vec<&String> = (0..6).filter(|i| i % 3 == s).map(|i| &lines[i]).collect();
        write(&root.join(format!("shard-{s}")), &mine);
    }
    let out = root.join("merged");
    write(&out, &[&lines[6]]);
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let o = specfx(&[
        "calibrate",
        "merge",
        "--data",
        &s(&out),
        &s(&root.join("shard-2")),
        &s(&root.join("shard-0")),
        &s(&root.join("shard-1")),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        std::fs::read_to_string(out.join("ice40.jsonl")).unwrap(),
        lines.concat()
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains("7 records into"));

    // A merge run again (the same records) is the same file.
    let again = specfx(&[
        "calibrate",
        "merge",
        "--data",
        &s(&out),
        &s(&root.join("shard-0")),
    ]);
    assert!(again.status.success());
    assert_eq!(
        std::fs::read_to_string(out.join("ice40.jsonl")).unwrap(),
        lines.concat()
    );

    // Two different records of configuration 0.
    let changed = lines[0].replacen("\"luts\":", "\"luts\":1", 1);
    write(&root.join("other"), &[&changed]);
    let before = std::fs::read(out.join("ice40.jsonl")).unwrap();
    refused(
        &specfx(&[
            "calibrate",
            "merge",
            "--data",
            &s(&out),
            &s(&root.join("other")),
        ]),
        "record 0 differs from the one in",
    );
    assert_eq!(std::fs::read(out.join("ice40.jsonl")).unwrap(), before);
    // Another seed.
    refused(
        &specfx(&[
            "calibrate",
            "merge",
            "--seed",
            "2",
            "--data",
            &s(&root.join("m2")),
            &s(&root.join("shard-0")),
        ]),
        "was drawn with another seed than --seed 2",
    );
    assert!(!root.join("m2").exists());
    // A shard directory holding another shard's record, and --fit-only with a shard: refused
    // before any synthesis.
    refused(
        &specfx(&[
            "calibrate",
            "--targets",
            "ice40",
            "--count",
            "6",
            "--shard",
            "1/3",
            "--data",
            &s(&root.join("shard-0")),
        ]),
        "record 0 is of shard 0/3, not 1/3",
    );
    refused(
        &specfx(&[
            "calibrate",
            "--fit-only",
            "--shard",
            "0/3",
            "--data",
            &s(&root.join("shard-0")),
        ]),
        "--shard: a shard synthesises its part of the sample",
    );
    // A shard that was not run, or a file named as one: a mistake in the command, refused
    // (not merged as "no records") before --data is touched.
    std::fs::write(root.join("afile"), "x").unwrap();
    let before = std::fs::read(out.join("ice40.jsonl")).unwrap();
    for (shard, why) in [
        ("missing", "does not exist"),
        ("afile", "is not a directory"),
    ] {
        refused(
            &specfx(&[
                "calibrate",
                "merge",
                "--data",
                &s(&out),
                &s(&root.join("shard-0")),
                &s(&root.join(shard)),
            ]),
            &format!(
                "calibrate merge: shard {}: {why}, expected a records directory",
                root.join(shard).display()
            ),
        );
    }
    assert_eq!(std::fs::read(out.join("ice40.jsonl")).unwrap(), before);
    // A scheduler's task without {shard} in --data: refused under the flag's own name.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_specfx"))
        .args([
            "calibrate",
            "--targets",
            "ice40",
            "--count",
            "6",
            "--shard",
            "auto/3",
        ])
        .args(["--data", &s(&root.join("cal"))])
        .env("SPECFX_TASK_ID", "0")
        .output()
        .unwrap();
    refused(&o, "--data: expected a {shard} placeholder");
    assert!(!root.join("cal").exists());
}
