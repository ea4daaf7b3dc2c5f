//! `hdl_ref/manifest.schema.json` against the manifests the built binary writes: every
//! configuration the tests co-simulate, both orders, and manifests broken on purpose.

use crate::common::specfx;

use std::path::Path;

use serde_json::Value;

fn schema() -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("hdl_ref/manifest.schema.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn validator() -> jsonschema::Validator {
    let schema = schema();
    jsonschema::meta::validate(&schema).expect("the schema is a valid JSON Schema");
    assert_eq!(
        schema["$schema"],
        "https://json-schema.org/draft/2020-12/schema"
    );
    jsonschema::draft202012::new(&schema).expect("the schema compiles")
}

/// The errors of a manifest, one per line (empty when valid).
fn errors(v: &jsonschema::Validator, manifest: &Value) -> String {
    v.iter_errors(manifest)
        .map(|e| format!("{} at {}", e, e.instance_path()))
        .collect::<Vec<_>>()
        .join("\n")
}

fn write_manifest(dir: &Path, args: &[&str]) -> Value {
    let out = dir.join("v");
    let mut a = vec!["vectors", "--out", out.to_str().unwrap(), "--force"];
    a.extend_from_slice(args);
    let o = specfx(&a);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap()
}

#[test]
fn manifests_of_every_test_configuration_follow_the_schema() {
    let v = validator();
    let dir = tempfile::tempdir().unwrap();
    // A minimax datapath with the paper cutoff, and one whose small n give only zeros (a
    // non-empty n_without_nonzero).
    let minimax = dir.path().join("minimax_paper.toml");
    std::fs::write(
        &minimax,
        "variant = \"minimax\"\ncutoff = \"paper\"\nk = 5\nn = \"16..=20,300\"\n",
    )
    .unwrap();
    let zeros = dir.path().join("zeros.toml");
    std::fs::write(
        &zeros,
        "n = \"1,2,300\"\n[c]\nformat = \"u1.10\"\n[d]\nformat = \"s1.10\"\n[out]\nformat = \"u4.-1\"\n",
    )
    .unwrap();
    let mut runs: Vec<Vec<String>> = vec![
        vec![],
        vec!["--order".into(), "sorted".into()],
        vec![
            "--n".into(),
            "16,100,1024".into(),
            "--cases".into(),
            "exhaustive".into(),
        ],
        vec![
            "--config".into(),
            minimax.to_string_lossy().into_owned(),
            "--cases".into(),
            "corner,random:50".into(),
        ],
        vec![
            "--config".into(),
            zeros.to_string_lossy().into_owned(),
            "--order".into(),
            "sorted".into(),
        ],
    ];
    // A wrapping t on a 2^30-code input: cutoff switches by bisection, the rounding boundaries
    // searched near 1.0 only (not exhaustive).
    let wide = dir.path().join("wide_wrap.toml");
    std::fs::write(
        &wide,
        "n = \"17,1024\"\n[c]\nformat = \"u1.30\"\n[d]\nformat = \"s1.30\"\n[t]\noverflow = \"WRAP\"\n",
    )
    .unwrap();
    runs.push(vec![
        "--config".into(),
        wide.to_string_lossy().into_owned(),
        "--cases".into(),
        "random:10".into(),
    ]);
    // A configuration that records its microarchitecture (the manifest's config.arch).
    let folded = dir.path().join("folded.toml");
    std::fs::write(&folded, "arch = \"folded\"\nk = 3\nn = \"16..=20\"\n").unwrap();
    runs.push(vec![
        "--config".into(),
        folded.to_string_lossy().into_owned(),
        "--cases".into(),
        "corner".into(),
    ]);
    let mut configs: Vec<String> =
        std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/configs"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .map(|p| p.to_string_lossy().into_owned())
            .collect();
    configs.sort();
    assert!(configs.len() >= 6, "{configs:?}");
    for (i, c) in configs.iter().enumerate() {
        let order = if i % 2 == 0 { "interleaved" } else { "sorted" };
        runs.push(vec![
            "--config".into(),
            c.clone(),
            "--cases".into(),
            "corner,random:100".into(),
            "--order".into(),
            order.into(),
        ]);
    }
    let mut orders = std::collections::BTreeSet::new();
    let mut some_without = false;
    let mut directed = std::collections::BTreeSet::new();
    for args in &runs {
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        let m = write_manifest(dir.path(), &a);
        assert_eq!(errors(&v, &m), "", "{args:?}");
        orders.insert(m["order"].as_str().unwrap().to_string());
        some_without |= !m["coverage"]["n_without_nonzero"]
            .as_array()
            .unwrap()
            .is_empty();
        let d = &m["coverage"]["directed"];
        directed.insert(if d.is_null() {
            "null".to_string()
        } else {
            format!("exhaustive {}", d["ties"]["exhaustive"])
        });
    }
    assert_eq!(orders.len(), 2);
    assert!(some_without);
    // An exhaustive selection, directed cases searched exhaustively and near 1.0 only.
    assert_eq!(directed.len(), 3, "{directed:?}");
}

#[test]
fn broken_manifests_fail_the_schema() {
    let v = validator();
    let dir = tempfile::tempdir().unwrap();
    let good = write_manifest(dir.path(), &["--n", "16,100", "--cases", "corner"]);
    assert_eq!(errors(&v, &good), "");
    type Break = fn(&mut Value);
    let breaks: [(&str, Break); 16] = [
        ("no directed cases", |m| {
            m["coverage"].as_object_mut().unwrap().remove("directed");
        }),
        ("a stage without its boundary count", |m| {
            m["coverage"]["stages"][1]
                .as_object_mut()
                .unwrap()
                .remove("at_boundary");
        }),
        ("an unknown rounding", |m| {
            m["coverage"]["stages"][1]["rounding"] = "ROUND".into()
        }),
        ("a tie search without its extent", |m| {
            m["coverage"]["directed"]["ties"]
                .as_object_mut()
                .unwrap()
                .remove("exhaustive");
        }),
        ("no coverage", |m| {
            m.as_object_mut().unwrap().remove("coverage");
        }),
        ("no order", |m| {
            m.as_object_mut().unwrap().remove("order");
        }),
        ("n_vectors a string", |m| m["n_vectors"] = "58".into()),
        ("an unknown order", |m| m["order"] = "random".into()),
        ("an extra key", |m| m["comment"] = "hello".into()),
        ("a stage without saturated", |m| {
            m["coverage"]["stages"][1]
                .as_object_mut()
                .unwrap()
                .remove("saturated");
        }),
        ("a negative count", |m| m["coverage"]["cut"] = (-1).into()),
        ("a share above 1", |m| {
            m["coverage"]["nonzero_share"] = 1.5.into()
        }),
        ("a bad format", |m| {
            m["csv"]["columns"][0]["format"] = "x1.15".into()
        }),
        ("a column without width", |m| {
            m["csv"]["columns"][2]
                .as_object_mut()
                .unwrap()
                .remove("width");
        }),
        ("a short hash", |m| {
            m["sha256"]["vectors.csv"] = "abc".into()
        }),
        ("a config key misspelled", |m| {
            let c = m["config"].as_object_mut().unwrap();
            let k = c.remove("k").unwrap();
            c.insert("K".into(), k);
        }),
    ];
    for (what, f) in breaks {
        let mut m = good.clone();
        f(&mut m);
        assert_ne!(m, good, "{what}");
        assert!(!v.is_valid(&m), "{what}: the schema accepts it");
    }
}
