//! `specfx sweep`: sharding and merging give the one-shot result, an interrupted sweep resumes
//! without recomputing, and bad spaces are refused.

use crate::common::specfx;

use std::path::{Path, PathBuf};
use std::process::Output;

use specfx::analysis::sweep::{mark_pareto, PointResult};

fn temp(name: &str) -> PathBuf {
    let p = std::env::temp_dir().join(format!("specfx-sweep-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&p);
    let _ = std::fs::remove_file(&p);
    p
}

const SPACE: &str = "n = \"64,200\"\n[vary]\nk = [4, 5]\n\"square.frac\" = [10, 13]\n\"t.rounding\" = [\"TRN\", \"RND\"]\narch = [\"pipelined\", \"folded\"]\n";

fn space_file() -> PathBuf {
    let p = temp("space.toml");
    std::fs::write(&p, SPACE).unwrap();
    p
}

fn run_sweep(space: &Path, out: &Path, shard: Option<&str>) -> Output {
    let mut args = vec![
        "sweep",
        "--space",
        space.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    if let Some(s) = shard {
        args.extend(["--shard", s]);
    }
    let o = specfx(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

#[test]
fn shards_merged_equal_the_one_shot_sweep() {
    let space = space_file();
    let one = temp("one");
    run_sweep(&space, &one, None);
    let shards: Vec<PathBuf> = (0..3).map(|i| temp(&format!("shard{i}"))).collect();
    for (i, dir) in shards.iter().enumerate() {
        run_sweep(&space, dir, Some(&format!("{i}/3")));
    }
    let merged = temp("merged");
    let mut args = vec!["sweep", "merge", "--out", merged.to_str().unwrap()];
    args.extend(shards.iter().map(|p| p.to_str().unwrap()));
    let o = specfx(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for file in ["sweep.csv", "sweep.json"] {
        assert_eq!(
            std::fs::read(one.join(file)).unwrap(),
            std::fs::read(merged.join(file)).unwrap(),
            "{file}"
        );
    }
    let svg = std::fs::read_to_string(one.join("sweep.svg")).unwrap();
    assert!(svg.contains("Pareto front"));
    let png = std::fs::read(one.join("sweep.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(png, std::fs::read(merged.join("sweep.png")).unwrap());
    let csv = std::fs::read_to_string(one.join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 16);
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|&h| h == "pareto").unwrap();
    // The cost columns name their target and unit.
    assert!(header.contains(&"ice40_luts") && header.contains(&"ice40_dsps"));
    // (the values column holds no comma, k=..;.., so it is not quoted)
    assert!(
        csv.lines()
            .skip(1)
            .any(|l| l.split(',').nth(col) == Some("true")),
        "a Pareto front"
    );
    // Two shards are not the whole sweep.
    let partial = temp("partial");
    let o = specfx(&[
        "sweep",
        "merge",
        "--out",
        partial.to_str().unwrap(),
        shards[0].to_str().unwrap(),
        shards[1].to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("missing"));
}

#[test]
fn an_interrupted_sweep_resumes_where_it_stopped() {
    let space = space_file();
    let full = temp("full");
    run_sweep(&space, &full, None);
    // Keep 5 finished points and half of a sixth, as a killed run would leave them.
    let resumed = temp("resumed");
    std::fs::create_dir_all(&resumed).unwrap();
    std::fs::copy(full.join("space.json"), resumed.join("space.json")).unwrap();
    let log = std::fs::read_to_string(full.join("points.jsonl")).unwrap();
    let lines: Vec<&str> = log.lines().collect();
    let torn = format!(
        "{}\n{}",
        lines[..5].join("\n"),
        &lines[5][..lines[5].len() / 2]
    );
    std::fs::write(resumed.join("points.jsonl"), torn).unwrap();
    let o = run_sweep(&space, &resumed, None);
    assert!(String::from_utf8_lossy(&o.stderr).contains("5 already done"));
    assert_eq!(
        std::fs::read(full.join("sweep.csv")).unwrap(),
        std::fs::read(resumed.join("sweep.csv")).unwrap()
    );
    // Another space in the same directory is refused.
    let other = temp("other.toml");
    std::fs::write(&other, SPACE.replace("[4, 5]", "[3, 5]")).unwrap();
    let o = specfx(&[
        "sweep",
        "--space",
        other.to_str().unwrap(),
        "--out",
        resumed.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("another sweep"));
}

#[test]
fn bad_spaces_name_the_axis() {
    let p = temp("bad.toml");
    std::fs::write(&p, "[vary]\n\"sq.frac\" = [1]\n").unwrap();
    let o = specfx(&[
        "sweep",
        "--space",
        p.to_str().unwrap(),
        "--out",
        temp("never").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("vary.sq.frac: unknown axis"), "{err}");
    std::fs::write(&p, "[vary]\ncutoff = [\"sharp\"]\n").unwrap();
    let o = specfx(&[
        "sweep",
        "--space",
        p.to_str().unwrap(),
        "--out",
        temp("never2").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("sharp"));
}

fn point(index: u64, luts: u64, err: f64) -> PointResult {
    point_dsp(index, luts, 0, err)
}

fn point_dsp(index: u64, luts: u64, dsps: u64, err: f64) -> PointResult {
    PointResult {
        index,
        values: String::new(),
        invalid: None,
        shape_total_max_abs: Some(err),
        shape_quant_max_abs: Some(err),
        out_max_ulp: Some(1.0),
        out_correctly_rounded: Some(1.0),
        monotonic: Some(true),
        luts: Some(luts),
        dsps: Some(dsps),
        ffs: Some(1),
        register_bits: Some(1),
        multiplier_bits: Some(1),
        latency: Some(1),
        initiation_interval: Some(1),
        pareto: false,
        yosys_luts: None,
        yosys_ffs: None,
        yosys_dsps: None,
    }
}

#[test]
fn pareto_front_by_hand() {
    // (cost, error): A(10, .5) B(20, .2) C(20, .3) D(30, .2) E(5, .9) F(10, .5) duplicate of A.
    let mut pts = vec![
        point(0, 10, 0.5),
        point(1, 20, 0.2),
        point(2, 20, 0.3),
        point(3, 30, 0.2),
        point(4, 5, 0.9),
        point(5, 10, 0.5),
    ];
    mark_pareto(&mut pts);
    let front: Vec<u64> = pts.iter().filter(|p| p.pareto).map(|p| p.index).collect();
    assert_eq!(front, [0, 1, 4]);
    // With DSP blocks a third cost: G (20 LUTs, 1 DSP, .2) is beaten by B (20, 0, .2); H
    // (8 LUTs, 3 DSPs, .5) trades DSPs for LUTs against A and stays on the front.
    let mut pts = vec![
        point_dsp(0, 10, 1, 0.5),
        point_dsp(1, 20, 0, 0.2),
        point_dsp(2, 20, 1, 0.2),
        point_dsp(3, 8, 3, 0.5),
    ];
    mark_pareto(&mut pts);
    let front: Vec<u64> = pts.iter().filter(|p| p.pareto).map(|p| p.index).collect();
    assert_eq!(front, [0, 1, 3]);
}

#[test]
fn without_a_space_the_built_in_space_is_swept() {
    // Shard 0 of 27 of the built-in 54-point space: points 0 and 27, k = 3 and k = 4 at 10
    // fraction bits with truncation (the space's last axis varies fastest).
    let out = temp("builtin");
    let o = specfx(&["sweep", "--out", out.to_str().unwrap(), "--shard", "0/27"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 2, "{csv}");
    let space = std::fs::read_to_string(out.join("space.json")).unwrap();
    assert!(space.contains("\"n_points\": 54"), "{space}");
}
