//! Inputs are verified and never destroyed, through the real binary: every reader of a vector
//! directory refuses a tampered one; no command writes over one of its inputs; an existing
//! file is replaced only when it is the command's own earlier result or with --force; heat-map
//! names are unique; Markdown outputs carry no raw HTML from user strings.

use crate::common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Output;

use sha2::{Digest, Sha256};

fn run_in(dir: &Path, args: &[&str]) -> Output {
    common::specfx_in(dir, args)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Asserts exit code 2 and one error line holding `expect`.
fn assert_refused(o: &Output, expect: &str, label: &str) {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{label}: {e}");
    assert_eq!(
        e.lines().count(),
        1,
        "{label}: expected one line, got {e:?}"
    );
    assert!(e.contains(expect), "{label}: expected {expect:?} in {e:?}");
}

/// Every file under `dir` with its bytes.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(p.clone(), std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Writes a small vector directory `v` of the baseline (c in u1.15) for n = 16 and 64.
fn vectors(dir: &Path) -> PathBuf {
    let o = run_in(
        dir,
        &["vectors", "--n", "16,64", "--cases", "corner", "--out", "v"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    dir.join("v")
}

/// Rewrites `file` of the vector directory and, with `rehash`, its hash in the manifest, as
/// someone covering their tracks would.
fn tamper(v: &Path, file: &str, edit: impl Fn(&str) -> String, rehash: bool) {
    let path = v.join(file);
    let text = edit(&std::fs::read_to_string(&path).unwrap());
    std::fs::write(&path, &text).unwrap();
    if rehash {
        let mpath = v.join("manifest.json");
        let mut m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&mpath).unwrap()).unwrap();
        m["sha256"][file] = serde_json::Value::String(sha256_hex(text.as_bytes()));
        std::fs::write(&mpath, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    }
}

fn edit_manifest(v: &Path, edit: impl Fn(&mut serde_json::Value)) {
    let mpath = v.join("manifest.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&mpath).unwrap()).unwrap();
    edit(&mut m);
    std::fs::write(&mpath, serde_json::to_string_pretty(&m).unwrap()).unwrap();
}

/// The commands that read a vector directory, each given `v`.
fn readers() -> Vec<Vec<&'static str>> {
    vec![
        vec!["hdl", "stimulus", "--vectors", "v", "--out", "stim"],
        vec!["hdl", "params", "--vectors", "v"],
        vec!["check", "--config", "v"],
        vec!["check", "--config", "v/manifest.json"],
        vec!["cosim", "--vectors", "v"],
    ]
}

#[test]
fn every_reader_verifies_a_vector_directory_first() {
    let base = tempfile::tempdir().unwrap();
    let original = vectors(base.path());
    let csv = std::fs::read_to_string(original.join("vectors.csv")).unwrap();
    let n_rows = csv.lines().count() - 1;
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |port: &str| {
        header
            .iter()
            .position(|h| h.starts_with(&format!("{port}:")))
            .unwrap()
    };
    let (i_c, i_n) = (col("in_c"), col("in_n"));
    assert_eq!(header[i_c], "in_c:u1.15", "the baseline's input format");
    // Row 1's cell `j` replaced by `value`.
    let set_cell = move |j: usize, value: &'static str| {
        move |text: &str| {
            let mut lines: Vec<String> = text.lines().map(String::from).collect();
            let mut cells: Vec<String> = lines[1].split(',').map(String::from).collect();
            cells[j] = value.to_string();
            lines[1] = cells.join(",");
            lines.join("\n") + "\n"
        }
    };
    type Tamper = Box<dyn Fn(&Path)>;
    let cases: Vec<(&str, Tamper, String)> = vec![
        (
            "one digit of vectors.csv changed",
            Box::new(move |v: &Path| tamper(v, "vectors.csv", set_cell(i_c, "1"), false)),
            "differs from the manifest's".into(),
        ),
        (
            "a header-only vectors.csv, hash updated",
            Box::new(|v: &Path| {
                tamper(
                    v,
                    "vectors.csv",
                    |t| format!("{}\n", t.lines().next().unwrap()),
                    true,
                )
            }),
            format!("the manifest says {n_rows} vectors, the file has 0 rows"),
        ),
        (
            "c_raw 99999999999, hash updated",
            Box::new(move |v: &Path| tamper(v, "vectors.csv", set_cell(i_c, "99999999999"), true)),
            // u1.15 holds raw codes 0..=2^16-1.
            "raw code 99999999999 is outside u1.15 (0..=65535)".into(),
        ),
        (
            "n = 17, not in the n set, hash updated",
            Box::new(move |v: &Path| tamper(v, "vectors.csv", set_cell(i_n, "17"), true)),
            "in_n = 17 is not in the configuration's n set".into(),
        ),
        (
            "a hex word changed, hash updated",
            Box::new(|v: &Path| {
                tamper(
                    v,
                    "in_c.hex",
                    |t| {
                        let mut lines: Vec<&str> = t.lines().collect();
                        let flipped = if lines[0] == "0000" { "0001" } else { "0000" };
                        lines[0] = flipped;
                        lines.join("\n") + "\n"
                    },
                    true,
                )
            }),
            "in_c.hex line 1: expected the word".into(),
        ),
        (
            "an unknown configuration key in the manifest",
            Box::new(|v: &Path| edit_manifest(v, |m| m["config"]["bogus"] = 1.into())),
            "key 'config.bogus': unknown field `bogus`".into(),
        ),
        (
            "an unknown key in a stage of the manifest's configuration",
            Box::new(|v: &Path| edit_manifest(v, |m| m["config"]["t"]["formt"] = "s1.2".into())),
            "key 'config.t.formt'".into(),
        ),
        (
            "an unknown top-level key",
            Box::new(|v: &Path| edit_manifest(v, |m| m["extra"] = true.into())),
            "key 'extra': unknown field".into(),
        ),
        (
            "a wrong number of vectors",
            Box::new(|v: &Path| edit_manifest(v, |m| m["n_vectors"] = 5.into())),
            "the manifest says 5 vectors, the file has more rows".into(),
        ),
        (
            "a hash missing",
            Box::new(|v: &Path| {
                edit_manifest(v, |m| {
                    m["sha256"].as_object_mut().unwrap().remove("in_n.hex");
                })
            }),
            "key 'sha256': no hash for in_n.hex".into(),
        ),
        (
            "a listed file missing",
            Box::new(|v: &Path| std::fs::remove_file(v.join("expected_out.hex")).unwrap()),
            "expected_out.hex: cannot read it".into(),
        ),
        (
            "ports that do not match the configuration",
            Box::new(|v: &Path| edit_manifest(v, |m| m["ports"][0]["width"] = 15.into())),
            "key 'ports': expected the configuration's ports".into(),
        ),
    ];
    for (what, apply, expect) in &cases {
        let work = tempfile::tempdir().unwrap();
        let v = work.path().join("v");
        std::fs::create_dir(&v).unwrap();
        for e in std::fs::read_dir(&original).unwrap().flatten() {
            std::fs::copy(e.path(), v.join(e.file_name())).unwrap();
        }
        apply(&v);
        for args in readers() {
            let o = run_in(work.path(), &args);
            assert_refused(&o, expect, &format!("{what}: specfx {}", args.join(" ")));
        }
        assert!(
            !work.path().join("stim").exists(),
            "{what}: no stimulus written"
        );
    }
    // The untouched directory passes every reader but the co-simulation (which needs a
    // simulator and is covered by tests/hardware/cosim.rs).
    for args in readers().into_iter().filter(|a| a[0] != "cosim") {
        let o = run_in(base.path(), &args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
    }
}

#[test]
fn no_command_writes_over_one_of_its_inputs() {
    let work = tempfile::tempdir().unwrap();
    let dir = work.path();
    std::fs::write(dir.join("c.toml"), "k = 4\n").unwrap();
    vectors(dir);
    std::fs::write(dir.join("s.toml"), common::sphere_scene(0.1, 16, 1.0, 0.03)).unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["optimize", "--config", "c.toml", "--out", "c.toml"],
            "--out c.toml: is the input --config c.toml",
        ),
        (
            &[
                "optimize", "--config", "c.toml", "--out", "c.toml", "--force",
            ],
            "is the input --config c.toml",
        ),
        (
            &["hdl", "params", "--config", "c.toml", "--out", "./c.toml"],
            "is the input --config c.toml",
        ),
        (
            &[
                "hdl", "rom", "--config", "c.toml", "--out", "c.toml", "--force",
            ],
            "is the input",
        ),
        (
            &["sim", "--config", "c.toml", "--vcd", "c.toml"],
            "--vcd c.toml: is the input --config c.toml",
        ),
        (
            &["hdl", "params", "--config", "v", "--out", "v/manifest.json"],
            "is the input --config v/manifest.json",
        ),
        (
            &[
                "hdl",
                "params",
                "--vectors",
                "v",
                "--out",
                "v/in_c.hex",
                "--force",
            ],
            "is the input --vectors v/in_c.hex",
        ),
        (
            &[
                "hdl",
                "stimulus",
                "--vectors",
                "v",
                "--out",
                "st",
                "--vcd",
                "v/expected_out.hex",
            ],
            "--vcd v/expected_out.hex: is inside the input --vectors directory v",
        ),
        (
            &[
                "budget",
                "--config",
                "v",
                "--out",
                "v",
                "--no-gappa",
                "--force",
            ],
            "--out v: would replace the directory that holds the input --config",
        ),
        (
            &["stability", "--config", "c.toml", "--out", ".", "--force"],
            "--out .: would replace the directory that holds the input --config c.toml",
        ),
        (
            &[
                "render",
                "--scene",
                "s.toml",
                "--out",
                dir.to_str().unwrap(),
            ],
            "would replace the directory that holds the input --scene s.toml",
        ),
        (
            &["furnace", "--config", "c.toml", "--out", "c.toml"],
            "is the input --config c.toml",
        ),
    ];
    for (args, expect) in cases {
        let before = snapshot(dir);
        let o = run_in(dir, args);
        assert_refused(&o, expect, &format!("specfx {}", args.join(" ")));
        assert!(
            snapshot(dir) == before,
            "specfx {}: changed files",
            args.join(" ")
        );
    }
}

#[test]
fn an_existing_file_is_replaced_only_when_it_is_an_earlier_result_or_with_force() {
    let work = tempfile::tempdir().unwrap();
    let dir = work.path();
    // Each single-file output: run twice (the second replaces the first), then onto a
    // foreign file (refused, unchanged), then with --force (replaced).
    let commands: &[&[&str]] = &[
        &["hdl", "params", "--out", "out.file"],
        &["hdl", "params", "--format", "instance", "--out", "out.file"],
        &["hdl", "rom", "--out", "out.file"],
        &["sim", "--cycles", "50", "--vcd", "out.file"],
    ];
    for args in commands {
        let label = args.join(" ");
        let _ = std::fs::remove_file(dir.join("out.file"));
        for _ in 0..2 {
            let o = run_in(dir, args);
            assert!(o.status.success(), "{label}: {}", stderr(&o));
        }
        let written = std::fs::read(dir.join("out.file")).unwrap();
        std::fs::write(dir.join("out.file"), "my notes\n").unwrap();
        let o = run_in(dir, args);
        assert_refused(&o, "--", &format!("{label} onto a foreign file"));
        assert!(stderr(&o).contains("pass --force to replace it"), "{label}");
        assert_eq!(std::fs::read(dir.join("out.file")).unwrap(), b"my notes\n");
        let forced: Vec<&str> = args.iter().copied().chain(["--force"]).collect();
        let o = run_in(dir, &forced);
        assert!(o.status.success(), "{label} --force: {}", stderr(&o));
        assert_eq!(
            std::fs::read(dir.join("out.file")).unwrap(),
            written,
            "{label}"
        );
    }
    // JSON parameters have no comment to recognise them by: a second run needs --force.
    let json = ["hdl", "params", "--format", "json", "--out", "p.json"];
    assert!(run_in(dir, &json).status.success());
    assert_refused(&run_in(dir, &json), "pass --force", "json twice");

    // A stimulus goes into a directory of its own (never the vector directory) and may be
    // written again; a foreign file of a stimulus name is refused.
    vectors(dir);
    for _ in 0..2 {
        let o = run_in(dir, &["hdl", "stimulus", "--vectors", "v", "--out", "own"]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    std::fs::create_dir(dir.join("st")).unwrap();
    std::fs::write(dir.join("st/stim_valid.hex"), "mine\n").unwrap();
    let o = run_in(dir, &["hdl", "stimulus", "--vectors", "v", "--out", "st"]);
    assert_refused(
        &o,
        "--out st/stim_valid.hex: already exists",
        "foreign stimulus",
    );
    assert_eq!(
        std::fs::read(dir.join("st/stim_valid.hex")).unwrap(),
        b"mine\n"
    );

    // An output path that is a directory leaves nothing behind.
    std::fs::create_dir(dir.join("d")).unwrap();
    let o = run_in(dir, &["hdl", "params", "--out", "d", "--force"]);
    assert_refused(&o, "--out d: is a directory", "onto a directory");
    assert_eq!(std::fs::read_dir(dir.join("d")).unwrap().count(), 0);
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn heat_maps_of_paths_with_the_same_name_do_not_overwrite_each_other() {
    let work = tempfile::tempdir().unwrap();
    let dir = work.path();
    // Two datapaths named like the float path `powi`, and like each other.
    std::fs::write(dir.join("a.toml"), "name = \"powi\"\n").unwrap();
    std::fs::write(dir.join("b.toml"), "name = \"POWI\"\nk = 5\n").unwrap();
    let o = run_in(
        dir,
        &[
            "stability",
            "--float",
            "powi",
            "--config",
            "a.toml",
            "--config",
            "b.toml",
            "--n",
            "16,32",
            "--c-bits",
            "8",
            "--out",
            "st",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("is shown as 'powi-2'") && e.contains("is shown as 'POWI-3'"),
        "{e}"
    );
    for stem in ["heatmap_powi", "heatmap_powi-2", "heatmap_POWI-3"] {
        assert!(
            dir.join("st").join(format!("{stem}.png")).is_file(),
            "{stem}"
        );
    }
    let md = std::fs::read_to_string(dir.join("st/stability.md")).unwrap();
    for name in ["| powi |", "| powi-2 |", "| POWI-3 |"] {
        assert!(md.contains(name), "{name} in stability.md");
    }
}

#[test]
fn markdown_outputs_carry_no_raw_html_from_user_strings() {
    let work = tempfile::tempdir().unwrap();
    let dir = work.path();
    // A scene whose file name is HTML: render.md names the scene.
    let name = "<img src=x onerror=alert(1)>[a](javascript:x).toml";
    std::fs::write(dir.join(name), common::sphere_scene(0.1, 16, 1.0, 0.03)).unwrap();
    let o = run_in(dir, &["render", "--scene", name, "--out", "r"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let md = std::fs::read_to_string(dir.join("r/render.md")).unwrap();
    assert!(!md.contains("<img"), "{md}");
    assert!(
        md.contains("&lt;img src=x onerror=alert(1)&gt;\\[a\\](javascript:x).toml"),
        "{md}"
    );
    // Names, which reach budget.md and stability.md, cannot hold markup at all.
    std::fs::write(dir.join("c.toml"), "name = \"<script>x</script>\"\n").unwrap();
    let o = run_in(
        dir,
        &["budget", "--config", "c.toml", "--out", "b", "--no-gappa"],
    );
    assert_refused(&o, "name: expected", "a name with markup");
}

#[test]
fn tradeoff_replaces_only_its_own_earlier_result() {
    let work = tempfile::tempdir().unwrap();
    let dir = work.path();
    std::fs::create_dir(dir.join("mine")).unwrap();
    std::fs::write(dir.join("mine/notes.txt"), "keep me\n").unwrap();
    // (`--ladder none`: what is replaced is the question, not the frontier's minutes.)
    let o = run_in(
        dir,
        &[
            "tradeoff", "--n", "16..=32", "--ladder", "none", "--out", "mine",
        ],
    );
    assert_refused(
        &o,
        "mine already exists and is not an earlier `specfx tradeoff` result",
        "tradeoff",
    );
    assert_eq!(std::fs::read_dir(dir.join("mine")).unwrap().count(), 1);
    for _ in 0..2 {
        let o = run_in(
            dir,
            &[
                "tradeoff", "--n", "16..=32", "--ladder", "none", "--out", "t",
            ],
        );
        assert!(o.status.success(), "{}", stderr(&o));
    }
    assert!(dir.join("t/tradeoff.csv").is_file());
}

#[test]
fn vectors_never_write_over_a_directory_that_is_not_theirs() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::create_dir(dir.join("vz")).unwrap();
    std::fs::write(dir.join("precious.txt"), "mine").unwrap();
    std::fs::create_dir(dir.join("mydata.partial")).unwrap();
    std::fs::write(dir.join("mydata.partial/thesis.tex"), "mine").unwrap();
    let vectors = ["vectors", "--n", "16", "--cases", "corner", "--out"];
    fn with<'a>(vectors: &[&'a str], out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
        [vectors, &[out], extra].concat()
    }
    let with = |out: &'static str, extra: &[&'static str]| with(&vectors, out, extra);
    // Paths without a directory name of their own: refused before anything is touched.
    for out in [".", "..", "vz/.."] {
        let o = run_in(dir, &with(out, &["--force"]));
        assert_refused(&o, "expected a directory name", out);
    }
    // A vector directory given as the configuration is not replaced, even with --force.
    assert!(run_in(dir, &with("v", &[])).status.success());
    std::fs::write(dir.join("v/notes.txt"), "mine").unwrap();
    for config in ["v", "v/manifest.json"] {
        let mut args = with("v", &["--force"]);
        args.extend(["--config", config]);
        let o = run_in(dir, &args);
        assert_refused(&o, "the input --config", config);
    }
    // A trailing slash names the same directory; the earlier result is replaced without
    // --force, and nobody's `<name>.partial` is touched.
    assert!(run_in(dir, &with("mydata/", &[])).status.success());
    assert!(run_in(dir, &with("mydata", &[])).status.success());
    for kept in ["precious.txt", "mydata.partial/thesis.tex", "v/notes.txt"] {
        assert_eq!(
            std::fs::read_to_string(dir.join(kept)).unwrap(),
            "mine",
            "{kept}"
        );
    }
    assert!(dir.join("mydata/manifest.json").is_file());
    let hidden: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "staging left behind: {hidden:?}");
}
