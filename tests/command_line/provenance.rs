//! Every result records what determined it, through the binary: the specfx version, the
//! canonical text of its inputs (`inputs.toml`) and that text's sha256 (`provenance.json` and
//! the last line of its documents), checked here with an independent sha256; the same
//! configuration, scene or budget written differently gives the same text and hash, another
//! one another hash; no path is recorded.

use crate::common;
use crate::common::specfx;

use std::path::{Path, PathBuf};
use std::process::Output;

use sha2::{Digest, Sha256};

fn temp(name: &str) -> PathBuf {
    let p = std::env::temp_dir().join(format!("specfx-prov-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&p);
    std::fs::create_dir_all(&p).unwrap();
    p
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

/// sha256 of bytes, lowercase hex, computed here (not by specfx).
fn sha256(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Checks `dir`'s provenance: the version is this crate's, the command is `command`, the
/// recorded hash is the sha256 of `inputs.toml`'s bytes, which name the command and no path
/// of this test. Returns (inputs.toml's text, its hash).
fn provenance(dir: &Path, command: &str) -> (String, String) {
    let p: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("provenance.json")).unwrap()).unwrap();
    let inputs = std::fs::read(dir.join("inputs.toml")).unwrap();
    let hash = sha256(&inputs);
    assert_eq!(p["specfx_version"], env!("CARGO_PKG_VERSION"), "{p}");
    assert_eq!(p["command"], command, "{p}");
    assert_eq!(p["inputs"], "inputs.toml", "{p}");
    assert_eq!(p["inputs_sha256"], hash.as_str(), "{p}");
    let text = String::from_utf8(inputs).unwrap();
    let table: toml::Table = text.parse().unwrap();
    assert_eq!(table["command"].as_str(), Some(command), "{text}");
    let tmp = std::env::temp_dir();
    assert!(!text.contains(s(&tmp)), "a path recorded: {text}");
    (text, hash)
}

/// The document's last line names the version and the inputs' hash.
fn ends_with_line(doc: &Path, command: &str, hash: &str) {
    let text = std::fs::read_to_string(doc).unwrap();
    let last = text
        .lines()
        .rev()
        .find(|l| l.contains("inputs sha256"))
        .unwrap_or_else(|| panic!("{}: no provenance line", doc.display()));
    assert!(
        last.contains(&format!("specfx {}", env!("CARGO_PKG_VERSION")))
            && last.contains(&format!("specfx {command}"))
            && last.contains(hash),
        "{}: {last}",
        doc.display()
    );
    // It is the last thing of the document (before the HTML page's closing tags).
    let after = &text[text.rfind(hash).unwrap()..];
    assert!(after.lines().count() <= 2, "{}: {after}", doc.display());
}

/// One datapath configuration, written so.
const NARROW: &str = r#"name = "narrow"
k = 5
n = "16..40"
[t]
format = "s2.12"
rounding = "TRN"
[square]
format = "u1.12"
"#;

/// The same configuration written otherwise: other key order, comments, quotes and spacing,
/// defaults spelled out, the exponents as `16..=40`, one `[[square]]` per stage.
const NARROW_AGAIN: &str = r#"# the narrow datapath, spelled out
n = '16..=40'   # both ends included either way
cutoff = "clamp"
k=5
name = 'narrow'

[[square]]
format = "u1.12"
[[square]]
format = "u1.12"
rounding = "RND"
[[square]]
format = "u1.12"
overflow = "SAT"
[[square]]
format = "u1.12"
[[square]]
format = "u1.12"

[t]
overflow = "SAT"
rounding   =   "TRN"
format = "s2.12"
"#;

#[test]
fn one_configuration_written_two_ways_has_one_hash() {
    let dir = temp("same");
    let (a, b, c) = (dir.join("a.toml"), dir.join("b.toml"), dir.join("c.toml"));
    std::fs::write(&a, NARROW).unwrap();
    std::fs::write(&b, NARROW_AGAIN).unwrap();
    std::fs::write(&c, NARROW.replace("k = 5", "k = 4")).unwrap();
    let budget = |config: &Path, budget: &str, out: &str| {
        let out = dir.join(out);
        ok(specfx(&[
            "budget",
            "--config",
            s(config),
            "--budget",
            budget,
            "--no-gappa",
            "--out",
            s(&out),
        ]));
        out
    };
    // The same (generous) budget written two ways, too: 64 lsb8 is 64 * 2^-8 = 0.5 * 2^-1.
    let da = budget(&a, "shape_total <= 64 lsb8, out <= 1000000 ulp", "da");
    let db = budget(&b, "out<=1e6ulp and shape_total <= 0.5 lsb1", "db");
    let dc = budget(&c, "shape_total <= 64 lsb8, out <= 1000000 ulp", "dc");
    let (text_a, hash_a) = provenance(&da, "budget");
    let (text_b, hash_b) = provenance(&db, "budget");
    let (_, hash_c) = provenance(&dc, "budget");
    assert_eq!(text_a, text_b);
    assert_eq!(hash_a, hash_b);
    assert_ne!(hash_a, hash_c);
    // The same figures: the two files are one configuration (the texts echoed differ).
    let figures = |d: &Path| {
        let v: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join("budget.json")).unwrap()).unwrap();
        [&v["attribution"], &v["per_n"], &v["headroom"]].map(|x| x.to_string())
    };
    assert!(figures(&da) == figures(&db), "the figures differ");
    // The recorded configuration is complete and exact, in the canonical notation.
    let t: toml::Table = text_a.parse().unwrap();
    let cfg = &t["config"].as_array().unwrap()[0];
    assert_eq!(cfg["name"].as_str(), Some("narrow"));
    assert_eq!(cfg["k"].as_integer(), Some(5));
    assert_eq!(cfg["n"].as_str(), Some("16..=40"));
    assert_eq!(cfg["t"]["format"].as_str(), Some("s2.12"));
    assert_eq!(cfg["t"]["rounding"].as_str(), Some("TRN"));
    let squares = cfg["square"].as_array().unwrap();
    assert_eq!(squares.len(), 5);
    for sq in squares {
        assert_eq!(sq["format"].as_str(), Some("u1.12"));
        assert_eq!(sq["rounding"].as_str(), Some("RND"));
        assert_eq!(sq["overflow"].as_str(), Some("SAT"));
    }
    let options = t["options"].as_table().unwrap();
    assert_eq!(options["no_gappa"].as_bool(), Some(true));
    let bounds: Vec<&str> = options["budget"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b.as_str().unwrap())
        .collect();
    assert_eq!(bounds, ["out <= 1000000", "shape_total <= 0.25"]);
    // The documents end with the line.
    for doc in ["budget.md", "budget.html"] {
        ends_with_line(&da.join(doc), "budget", &hash_a);
    }
    // `sha256sum` agrees, where it is installed.
    if let Ok(o) = std::process::Command::new("sha256sum")
        .arg(da.join("inputs.toml"))
        .output()
    {
        let out = String::from_utf8_lossy(&o.stdout);
        assert_eq!(
            out.split_whitespace().next(),
            Some(hash_a.as_str()),
            "{out}"
        );
    }
}

#[test]
fn every_result_directory_records_version_and_inputs() {
    let dir = temp("every");
    let cfg = dir.join("narrow.toml");
    std::fs::write(&cfg, NARROW).unwrap();
    let scene = dir.join("sphere.toml");
    std::fs::write(&scene, common::sphere_scene(0.5, 64, 1.0, 0.03)).unwrap();
    let out = |name: &str| dir.join(name);
    let runs: [(&str, Vec<&str>, Option<&str>); 7] = [
        (
            "stability",
            vec![
                "stability",
                "--n",
                "1..=32",
                "--c-bits",
                "8",
                "--float",
                "powf",
                "--config",
                s(&cfg),
                "--out",
            ],
            Some("stability.md"),
        ),
        (
            "furnace",
            vec![
                "furnace",
                "--n",
                "16,32",
                "--angles",
                "0,60",
                "--config",
                s(&cfg),
                "--out",
            ],
            Some("furnace.md"),
        ),
        (
            "render",
            vec!["render", "--scene", s(&scene), "--config", s(&cfg), "--out"],
            Some("render.md"),
        ),
        (
            "fit",
            vec![
                "fit",
                "--scene",
                s(&scene),
                "--analytic-only",
                "--budget",
                "max_lsb <= 4",
                "--out",
            ],
            Some("fit.md"),
        ),
        (
            "tradeoff",
            vec!["tradeoff", "--n", "64", "--ladder", "2", "--out"],
            None,
        ),
        (
            "vectors",
            vec![
                "vectors",
                "--config",
                s(&cfg),
                "--cases",
                "random:50",
                "--out",
            ],
            None,
        ),
        ("sweep", vec!["sweep", "--shard", "0/27", "--out"], None),
    ];
    for (command, mut args, doc) in runs {
        let d = out(command);
        args.push(s(&d));
        ok(specfx(&args));
        let (text, hash) = provenance(&d, command);
        if let Some(doc) = doc {
            ends_with_line(&d.join(doc), command, &hash);
        }
        let t: toml::Table = text.parse().unwrap();
        match command {
            "stability" => {
                assert_eq!(t["options"]["n"].as_str(), Some("1..=32"));
                assert_eq!(t["options"]["c_bits"].as_integer(), Some(8));
                assert_eq!(t["options"]["tol"].as_float(), Some(1.0 / 256.0));
                assert_eq!(t["config"][0]["name"].as_str(), Some("narrow"));
            }
            "render" | "fit" => {
                assert_eq!(t["scene"]["material"][0]["n"].as_integer(), Some(64));
                assert_eq!(t["scene"]["object"][0]["radius"].as_float(), Some(1.0));
            }
            "furnace" => assert_eq!(t["options"]["angles"][1].as_float(), Some(60.0)),
            "tradeoff" => assert_eq!(t["options"]["n"].as_str(), Some("64")),
            "vectors" => {
                // The manifest lists both files with their hashes; corner cases are always in.
                assert_eq!(t["options"]["cases"].as_str(), Some("corner,random:50"));
                let m: serde_json::Value =
                    serde_json::from_slice(&std::fs::read(d.join("manifest.json")).unwrap())
                        .unwrap();
                assert_eq!(m["sha256"]["inputs.toml"], hash.as_str());
                let p = std::fs::read(d.join("provenance.json")).unwrap();
                assert_eq!(m["sha256"]["provenance.json"], sha256(&p).as_str());
            }
            "sweep" => assert_eq!(t["options"]["shard"].as_str(), Some("0/27")),
            _ => {}
        }
    }
    // optimize writes one configuration file: its provenance is in comments, the canonical
    // inputs on the lines starting with '#|' (a few exponents: the format does not depend on
    // the search's size).
    let file = out("optimized.toml");
    ok(specfx(&[
        "optimize",
        "--k",
        "5",
        "--variants",
        "minimax",
        "--n",
        "16..=24",
        "--out",
        s(&file),
    ]));
    let text = std::fs::read_to_string(&file).unwrap();
    let inputs: String = text
        .lines()
        .filter_map(|l| l.strip_prefix("#|"))
        .map(|l| format!("{}\n", l.strip_prefix(' ').unwrap_or(l)))
        .collect();
    let hash = sha256(inputs.as_bytes());
    let head = text.lines().find(|l| l.contains("inputs sha256")).unwrap();
    assert!(
        head.contains(&format!("specfx {}", env!("CARGO_PKG_VERSION")))
            && head.contains("specfx optimize")
            && head.contains(&hash),
        "{head}"
    );
    let t: toml::Table = inputs.parse().unwrap();
    assert_eq!(
        t["options"]["budget"][0].as_str(),
        Some("shape_total <= 0.00390625")
    );
    assert_eq!(t["config"][0]["n"].as_str(), Some("16..=24"));
    // ... and it is still a configuration file.
    ok(specfx(&["check", "--config", s(&file), "--n", "16"]));
}

#[test]
fn a_scene_is_recorded_by_its_content_not_its_files() {
    let dir = temp("scene");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let text = std::fs::read_to_string(root.join("scenes/meshes.toml"))
        .unwrap()
        .replace("width = 512\nheight = 384", "width = 16\nheight = 12");
    assert!(
        text.contains("width = 16"),
        "the example's image size changed"
    );
    // As shipped: meshes in ../meshes/ beside the scene's directory.
    std::fs::create_dir_all(dir.join("a/scenes")).unwrap();
    std::fs::create_dir_all(dir.join("a/meshes")).unwrap();
    for m in ["cell.obj", "bone.stl"] {
        std::fs::copy(root.join("meshes").join(m), dir.join("a/meshes").join(m)).unwrap();
    }
    std::fs::write(dir.join("a/scenes/s.toml"), &text).unwrap();
    // The same scene elsewhere: meshes renamed beside it (the OBJ with a comment more), the
    // file commented and the default up vector spelled out.
    std::fs::create_dir_all(dir.join("b")).unwrap();
    let obj = std::fs::read_to_string(root.join("meshes/cell.obj")).unwrap();
    std::fs::write(
        dir.join("b/my cell.obj"),
        format!("# exported again\n{obj}"),
    )
    .unwrap();
    std::fs::copy(root.join("meshes/bone.stl"), dir.join("b/shaft.stl")).unwrap();
    let again = text
        .replace("../meshes/cell.obj", "my cell.obj")
        .replace(
            "file = \"../meshes/bone.stl\"",
            "file = \"shaft.stl\"\nscale = 1.0 # the default",
        )
        .replace(
            "fov_deg = 36.0",
            "fov_deg = 36.0\nup = [0.0, 1.0, 0.0] # the default",
        );
    assert!(again.contains("scale = 1.0 # the default\n"), "{again}");
    assert_ne!(again, text);
    std::fs::write(dir.join("b/s.toml"), format!("# another copy\n{again}")).unwrap();
    // Another scene: one mesh scaled.
    let scaled = again.replacen("scale = 1.1", "scale = 1.2", 1);
    assert_ne!(scaled, again);
    std::fs::write(dir.join("b/scaled.toml"), &scaled).unwrap();
    let render = |scene: &Path, out: &str| {
        let out = dir.join(out);
        ok(specfx(&["render", "--scene", s(scene), "--out", s(&out)]));
        provenance(&out, "render")
    };
    let (ta, ha) = render(&dir.join("a/scenes/s.toml"), "ra");
    let (tb, hb) = render(&dir.join("b/s.toml"), "rb");
    let (_, hc) = render(&dir.join("b/scaled.toml"), "rc");
    assert_eq!(ta, tb);
    assert_eq!(ha, hb);
    assert_ne!(ha, hc);
    assert!(!ta.contains("cell.obj") && !ta.contains("meshes"), "{ta}");
    assert!(ta.contains("triangles_sha256"), "{ta}");
}
