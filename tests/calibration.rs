//! The analytic cost model against its calibration: the committed coefficients are the fit of
//! the committed yosys records, the stated fit error is the error on them, and the DSP count
//! (yosys's mul2dsp rules, not fitted) matches yosys on the records.

mod common;

use common::specfx;
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
            .filter(|r| r.failed.is_none())
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
        let recs: Vec<_> = records(target)
            .into_iter()
            .filter(|r| r.failed.is_none())
            .collect();
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

#[test]
fn calibrate_with_its_defaults_refits_the_committed_records() {
    // The committed sample is complete: the defaults synthesise nothing and print the fit,
    // equal to the committed coefficients.
    let o = specfx(&[
        "calibrate",
        "--data",
        concat!(env!("CARGO_MANIFEST_DIR"), "/data/calibration"),
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
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
    }
}
