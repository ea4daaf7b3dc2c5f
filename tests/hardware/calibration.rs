//! The analytic cost model against its calibration: the committed coefficients are the fit of
//! the committed yosys records, the stated fit error is the error on them, and the DSP count
//! (yosys's mul2dsp rules, not fitted) matches yosys on the records. `calibrate` stores only
//! what yosys synthesised, refuses a fit over nothing, names the records file a full disk
//! stops, and `calibrate`, `cost` and `timing` refuse what they can before any synthesis.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::common::specfx;
use specfx::hdl::calibrate::{calibration, fit, read_records, sample};
use specfx::hdl::cost::{analytic_cost, Target};
use specfx::pipeline::Datapath;

fn records(target: Target) -> Vec<specfx::hdl::calibrate::Record> {
    let path = format!(
        "{}/data/calibration/{}.jsonl",
        env!("CARGO_MANIFEST_DIR"),
        target.name()
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    read_records(&text, &path).unwrap()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-6 * a.abs().max(b.abs()).max(1.0)
}

#[test]
fn committed_coefficients_are_the_fit_of_the_committed_records() {
    for target in [Target::Ice40, Target::Xilinx, Target::GenericFast] {
        let recs = records(target);
        assert!(recs.len() >= 100, "{target}: {} records", recs.len());
        // The records are the sample they claim to be.
        for r in &recs {
            assert_eq!(sample(1, r.index), (r.config.clone(), r.arch), "{target}");
        }
        let (c, e) = fit(&recs, target).unwrap();
        let committed = calibration(target);
        for (i, (&a, &b)) in c
            .logic
            .iter()
            .zip(&committed.coefficients.logic)
            .enumerate()
        {
            assert!(
                close(a, b),
                "{target} coefficient {i}: fitted {a}, committed {b}"
            );
        }
        assert!(close(
            c.ff_per_register_bit,
            committed.coefficients.ff_per_register_bit
        ));
        assert_eq!(e.records, committed.error.records, "{target}");
        assert!(close(e.median_rel, committed.error.median_rel), "{target}");
        assert!(close(e.p90_rel, committed.error.p90_rel), "{target}");
        assert!(close(e.max_rel, committed.error.max_rel), "{target}");
    }
}

#[test]
fn the_model_is_the_fit_on_every_record() {
    // analytic_cost uses the committed coefficients: its LUTs on a record are the weighted
    // features, rounded, and its median relative error is what the calibration states.
    for target in [Target::Ice40, Target::Xilinx] {
        let cal = calibration(target);
        let mut rel: Vec<f64> = records(target)
            .iter()
            .map(|r| {
                let dp = Datapath::new(r.config.clone()).unwrap();
                let a = analytic_cost(&dp, r.arch, target);
                (a.luts as f64 / (r.luts as f64).max(1.0) - 1.0).abs()
            })
            .collect();
        rel.sort_by(f64::total_cmp);
        let median = rel[(rel.len() - 1) / 2];
        // Rounding to whole LUTs moves each figure by at most half a LUT.
        assert!(
            (median - cal.error.median_rel).abs() < 0.02,
            "{target}: {median} against {}",
            cal.error.median_rel
        );
    }
}

#[test]
fn dsp_count_follows_yosys() {
    // The DSP count is not fitted: it follows yosys's mul2dsp rules, and equals yosys's count
    // on most records; the exceptions (about one in eight on iCE40) are where later passes
    // (wreduce, the DSP packer) shrink or merge products beyond mul2dsp's slicing.
    for target in [Target::Ice40, Target::Xilinx] {
        let recs = records(target);
        let exact = recs
            .iter()
            .filter(|r| {
                let dp = Datapath::new(r.config.clone()).unwrap();
                analytic_cost(&dp, r.arch, target).dsps == r.dsps
            })
            .count();
        assert!(
            exact as f64 >= 0.8 * recs.len() as f64,
            "{target}: DSP count exact on {exact} of {}",
            recs.len()
        );
    }
}

/// A fit over fewer records than coefficients says so: its error of 0 is no evidence.
#[test]
fn a_fit_over_fewer_records_than_coefficients_is_warned_about() {
    let data = tempfile::tempdir().unwrap();
    let committed = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/calibration/ice40.jsonl"
    ))
    .unwrap();
    let four: String = committed
        .lines()
        .take(4)
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(data.path().join("ice40.jsonl"), four).unwrap();
    let args = ["calibrate", "--targets", "ice40", "--fit-only", "--data"];
    let o = specfx(&[&args[..], &[data.path().to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.lines()
            .any(|l| l.starts_with("calibrate ice40: 4 records for ")
                && l.contains("coefficients: the fit is underdetermined")),
        "{err}"
    );
    // The committed records are enough: no warning (calibrate_fit_only_refits_...).
}

#[test]
fn calibrate_fit_only_refits_the_committed_records() {
    // --fit-only on the committed records runs no yosys and prints the fit, equal to the
    // committed coefficients.
    let o = specfx(&[
        "calibrate",
        "--fit-only",
        "--data",
        concat!(env!("CARGO_MANIFEST_DIR"), "/data/calibration"),
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Enough records for every coefficient: no warning of an underdetermined fit.
    assert!(!String::from_utf8_lossy(&o.stderr).contains("underdetermined"));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let fits = v.as_array().unwrap();
    assert_eq!(fits.len(), 3);
    for f in fits {
        let (a, b) = (
            &f["fitted"]["coefficients"],
            &f["committed"]["coefficients"],
        );
        for (x, y) in a["logic"]
            .as_array()
            .unwrap()
            .iter()
            .zip(b["logic"].as_array().unwrap())
        {
            assert!(close(x.as_f64().unwrap(), y.as_f64().unwrap()), "{f}");
        }
        assert_eq!(f["failed"], 0, "{f}");
    }
}

const BIN: &str = env!("CARGO_BIN_EXE_specfx");
const HDL_REF: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/hdl_ref");

fn s(p: &Path) -> &str {
    p.to_str().expect("a UTF-8 temporary path")
}

/// Asserts a refusal: exit code 2, nothing on stdout, one line on stderr holding `expect`.
#[track_caller]
fn refused(o: &Output, expect: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        o.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with("specfx: error: "), "{err}");
    assert!(err.contains(expect), "expected '{expect}' in: {err}");
}

/// The committed ice40 lines of the sample's indexes `indexes`, in that order.
fn committed_lines(indexes: impl IntoIterator<Item = u64>) -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/data/calibration/ice40.jsonl");
    let text = std::fs::read_to_string(path).unwrap();
    let by_index: Vec<(u64, &str)> = text
        .lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            (v["index"].as_u64().unwrap(), l)
        })
        .collect();
    indexes
        .into_iter()
        .map(|i| {
            let (_, l) = by_index.iter().find(|(j, _)| *j == i).unwrap();
            format!("{l}\n")
        })
        .collect()
}

/// A directory with a reference Verilog that passes for one (rtl/*.v, specfx_dut.v) but that
/// yosys cannot read: every synthesis fails, fast.
fn broken_hdl_ref(root: &Path) -> PathBuf {
    let dir = root.join("broken_hdl");
    std::fs::create_dir_all(dir.join("rtl")).unwrap();
    std::fs::write(dir.join("rtl/specfx_bad.v"), "module specfx_bad(;\n").unwrap();
    std::fs::write(dir.join("specfx_dut.v"), "module specfx_dut(\n").unwrap();
    dir
}

#[test]
fn calibrate_refuses_a_reference_verilog_it_cannot_use_before_any_work() {
    let root = tempfile::tempdir().unwrap();
    let data = root.path().join("data");
    let file = root.path().join("file");
    std::fs::write(&file, "").unwrap();
    let empty = root.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let no_dut = root.path().join("no_dut");
    std::fs::create_dir_all(no_dut.join("rtl")).unwrap();
    std::fs::write(no_dut.join("rtl/a.v"), "module a; endmodule\n").unwrap();
    let nosuch = root.path().join("nosuch");
    for (hdl, expect) in [
        (&nosuch, "got no such directory"),
        (&file, "got a file"),
        (&empty, "but it has no rtl/*.v"),
        (&no_dut, "but it has no specfx_dut.v"),
    ] {
        let o = specfx(&[
            "calibrate",
            "--targets",
            "ice40",
            "--count",
            "1",
            "--data",
            s(&data),
            "--hdl-ref",
            s(hdl),
        ]);
        refused(
            &o,
            &format!(
                "--hdl-ref {}: expected the reference Verilog directory",
                s(hdl)
            ),
        );
        refused(&o, expect);
        assert!(!data.exists(), "{hdl:?}: --data was created");
    }
    // The same directory from the environment is named as such; an empty one is unset.
    let o = Command::new(BIN)
        .args(["calibrate", "--targets", "ice40", "--data", s(&data)])
        .env("SPECFX_HDL_REF", &nosuch)
        .output()
        .unwrap();
    refused(&o, &format!("SPECFX_HDL_REF={}: expected", s(&nosuch)));
    let o = Command::new(BIN)
        .args(["calibrate", "--targets", "ice40", "--data", s(&data)])
        .env("SPECFX_HDL_REF", "")
        .env("PATH", s(&empty))
        .output()
        .unwrap();
    refused(&o, "yosys not found: install it");
    assert!(!data.exists());
}

#[test]
fn calibrate_refuses_what_it_cannot_do_before_any_synthesis() {
    let root = tempfile::tempdir().unwrap();
    let data = root.path().join("data");
    let empty = root.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    // No yosys: refused once, not recorded as 240 failed syntheses.
    let o = Command::new(BIN)
        .args(["calibrate", "--targets", "ice40", "--data", s(&data)])
        .env("PATH", s(&empty))
        .output()
        .unwrap();
    refused(&o, "yosys not found: install it");
    assert!(!data.exists());
    // The second target's records are unreadable: refused before the first target's work.
    std::fs::create_dir(&data).unwrap();
    std::fs::write(data.join("xilinx.jsonl"), "not json\n").unwrap();
    let o = Command::new(BIN)
        .args(["calibrate", "--targets", "ice40,xilinx", "--data", s(&data)])
        .env("PATH", s(&empty))
        .output()
        .unwrap();
    refused(&o, "xilinx.jsonl: line 1: not a calibration record");
    // A records file that is a device is refused, not read for ever.
    std::fs::remove_file(data.join("xilinx.jsonl")).unwrap();
    std::os::unix::fs::symlink("/dev/full", data.join("ice40.jsonl")).unwrap();
    let o = specfx(&[
        "calibrate",
        "--targets",
        "ice40",
        "--fit-only",
        "--data",
        s(&data),
    ]);
    refused(&o, "ice40.jsonl: expected a regular file, got a device");
    // --data that is a file, and a target named twice.
    let o = specfx(&["calibrate", "--data", s(&data.join("ice40.jsonl"))]);
    refused(&o, "--data");
    let o = specfx(&["calibrate", "--targets", "ice40,ice40", "--fit-only"]);
    refused(&o, "--targets: expected each target once, got ice40 twice");
}

#[test]
fn a_failed_synthesis_is_not_a_record_and_a_fit_over_nothing_is_an_error() {
    let root = tempfile::tempdir().unwrap();
    let hdl = broken_hdl_ref(root.path());
    let run = |data: &Path, count: &str| {
        specfx(&[
            "calibrate",
            "--quiet",
            "--targets",
            "ice40",
            "--count",
            count,
            "--data",
            s(data),
            "--hdl-ref",
            s(&hdl),
        ])
    };
    // Every synthesis fails: nothing to fit, and nothing written.
    let data = root.path().join("none");
    let o = run(&data, "2");
    refused(
        &o,
        "ice40.jsonl: no calibration records to fit: yosys failed on all 2 configurations",
    );
    assert!(!data.exists(), "a directory was made for no record");
    // Three records there, the fourth fails: the fit is over the three, the failure is not
    // stored, and the next run tries it again.
    let data = root.path().join("some");
    std::fs::create_dir(&data).unwrap();
    let three = committed_lines(1..=3);
    std::fs::write(data.join("ice40.jsonl"), &three).unwrap();
    for _ in 0..2 {
        let o = run(&data, "4");
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(
            out.starts_with(
                "ice40 (3 records; yosys failed on 1 more, tried again by the next run)"
            ),
            "{out}"
        );
        assert_eq!(
            std::fs::read_to_string(data.join("ice40.jsonl")).unwrap(),
            three
        );
    }
    // A failure an earlier specfx stored is not a record either: tried again, and dropped
    // from the file.
    let stored = three.clone()
        + r#"{"index":0,"arch":"pipelined","config":{"name":"cal0"},"luts":0,"carries":0,"dsps":0,"ffs":0,"failed":"no rtl"}"#
        + "\n";
    std::fs::write(data.join("ice40.jsonl"), stored).unwrap();
    let o = run(&data, "4");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        String::from_utf8_lossy(&o.stdout).starts_with("ice40 (3 records; yosys failed on 1 more")
    );
    assert_eq!(
        std::fs::read_to_string(data.join("ice40.jsonl")).unwrap(),
        three
    );
}

#[test]
fn a_full_disk_names_the_records_file_and_keeps_it_whole() {
    // Records 0..=78 are there; 79 (about the smallest iCE40 design of the sample) is
    // synthesised, and its line does not fit under the file-size limit: one line naming the
    // file, exit code 2, the file as it was (the part of the line that fitted taken back).
    let root = tempfile::tempdir().unwrap();
    let data = root.path().join("data");
    std::fs::create_dir(&data).unwrap();
    let before = committed_lines(0..79);
    std::fs::write(data.join("ice40.jsonl"), &before).unwrap();
    // In the 512-byte blocks of sh's ulimit: the file and part of one more line.
    let blocks = before.len() / 512 + 1;
    let line = format!(
        "ulimit -f {blocks}; exec '{BIN}' calibrate --quiet --targets ice40 --count 80 --data '{}' --hdl-ref '{HDL_REF}'",
        s(&data)
    );
    let o = Command::new("sh").args(["-c", &line]).output().unwrap();
    refused(
        &o,
        &format!(
            "cannot write {}: File too large",
            s(&data.join("ice40.jsonl"))
        ),
    );
    assert_eq!(
        std::fs::read_to_string(data.join("ice40.jsonl")).unwrap(),
        before
    );
    let names: Vec<_> = std::fs::read_dir(&data)
        .unwrap()
        .flatten()
        .map(|e| e.file_name())
        .collect();
    assert_eq!(names, ["ice40.jsonl"]);
}

#[test]
fn cost_and_timing_refuse_what_they_can_before_any_synthesis() {
    let root = tempfile::tempdir().unwrap();
    // No tool on the PATH: a refusal that needs no tool comes first.
    let empty = root.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let without_tools = |args: &[&str]| {
        Command::new(BIN)
            .args(args)
            .env("PATH", s(&empty))
            .output()
            .unwrap()
    };
    refused(
        &without_tools(&["cost", "--target", "xilinx", "--timing"]),
        "--timing: place and route is available for --target ice40 only (nextpnr-ice40), got --target xilinx",
    );
    refused(
        &without_tools(&["cost", "--timing", "--analytic-only"]),
        "cannot be used with",
    );
    refused(
        &without_tools(&[
            "cost",
            "--target",
            "xilinx",
            "--device",
            "hx8k",
            "--analytic-only",
        ]),
        "--device hx8k: the device check is for --target ice40 only, got --target xilinx",
    );
    let nosuch = root.path().join("nosuch");
    for cmd in ["cost", "timing"] {
        refused(
            &without_tools(&[cmd, "--hdl-ref", s(&nosuch)]),
            &format!(
                "--hdl-ref {}: expected the reference Verilog directory",
                s(&nosuch)
            ),
        );
    }
    refused(&without_tools(&["cost"]), "yosys not found: install it");
    refused(&without_tools(&["timing"]), "yosys not found: install it");
    // A yosys but no nextpnr: `cost --timing` says so before its synthesis.
    let bin = root.path().join("bin");
    std::fs::create_dir(&bin).unwrap();
    let ran = root.path().join("ran");
    let yosys = bin.join("yosys");
    std::fs::write(
        &yosys,
        format!(
            "#!/bin/sh\nif [ \"$1\" = -V ]; then echo 'Yosys 0.0 (stand-in)'; exit 0; fi\n: > '{}'\nexit 1\n",
            s(&ran)
        ),
    )
    .unwrap();
    std::fs::set_permissions(&yosys, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    let o = Command::new(BIN)
        .args(["cost", "--timing"])
        .env("PATH", s(&bin))
        .output()
        .unwrap();
    refused(&o, "nextpnr-ice40 not found: install it");
    assert!(!ran.exists(), "yosys synthesised before the refusal");
}
