//! End-to-end tests of `specfx timing` through the built binary: yosys and nextpnr-ice40 on the
//! reference Verilog inside the place-and-route harness (three nextpnr runs, a few seconds each).

use crate::common::specfx;

use std::process::Output;

fn json(o: &Output) -> serde_json::Value {
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| {
        panic!(
            "JSON on stdout ({e}); stderr: {}",
            String::from_utf8_lossy(&o.stderr)
        )
    })
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * b.abs().max(1.0)
}

#[test]
fn baseline_fits_a_up5k_with_a_plausible_fmax_in_both_architectures() {
    // Latency and initiation interval from docs/cycle.md for baseline (k = 4, every register
    // latency 1): pipelined L = sub + add + (k + 2) mul = 8, II = 1; folded L = (k + 2) + 1 = 7,
    // II = k + 2 = 6.
    for (arch, latency, ii) in [("pipelined", 8u64, 1u64), ("folded", 7, 6)] {
        let o = specfx(&["timing", "--arch", arch, "--device", "up5k", "--json"]);
        assert!(
            o.status.success(),
            "{arch}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let v = json(&o);
        assert_eq!(v["device"], "up5k");
        assert_eq!(v["fits"], true, "{arch}");
        assert_eq!(v["over_limit"].as_array().unwrap().len(), 0, "{arch}");
        let fmax = v["fmax_mhz"].as_f64().unwrap();
        assert!((5.0..300.0).contains(&fmax), "{arch}: Fmax {fmax} MHz");
        // The reported Fmax never exceeds nextpnr's, nor what the DSP segments allow.
        let nextpnr = v["nextpnr_fmax_mhz"].as_f64().unwrap();
        assert!(fmax <= nextpnr);
        // With DSP blocks (both architectures on a UP5K), Fmax is an upper bound.
        assert!(v["synthesis"]["dsps"].as_u64().unwrap() > 0);
        assert_eq!(v["fmax_is_upper_bound"], true);
        if let Some(u) = v["untimed_dsp"].as_object() {
            for seg in ["into_ns", "out_of_ns"] {
                if let Some(ns) = u[seg].as_f64() {
                    assert!(fmax <= 1000.0 / ns + 1e-9, "{arch}: {seg} {ns} ns");
                }
            }
        }
        assert_eq!(v["latency_cycles"], latency, "{arch}");
        assert_eq!(v["initiation_interval"], ii, "{arch}");
        let latency_ns = v["latency_ns"].as_f64().unwrap();
        assert!(close(latency_ns, latency as f64 * 1000.0 / fmax), "{arch}");
        let throughput = v["throughput_samples_per_s"].as_f64().unwrap();
        assert!(close(throughput, fmax * 1e6 / ii as f64), "{arch}");
        // The clock's critical path is a register-to-register path no faster than Fmax
        // allows: its delay is 1000 / nextpnr's Fmax.
        let p = &v["critical_path"];
        let delay = p["delay_ns"].as_f64().unwrap();
        assert!(
            (delay - 1000.0 / nextpnr).abs() < 0.01,
            "{arch}: {delay} ns"
        );
        assert!(p["logic_levels"].as_u64().unwrap() >= 1);
        assert!(p["start"]["cell"].as_str().unwrap().starts_with("u_dut."));
        // Utilisation: the DSPs and logic cells nextpnr placed, within the UP5K's.
        let used = |r: &str| {
            let u = v["utilisation"]
                .as_array()
                .unwrap()
                .iter()
                .find(|u| u["resource"] == r)
                .unwrap_or_else(|| panic!("{arch}: no {r}"))
                .clone();
            (
                u["used"].as_u64().unwrap(),
                u["available"].as_u64().unwrap(),
            )
        };
        let (dsps, dsps_available) = used("ICESTORM_DSP");
        assert_eq!(dsps_available, 8);
        assert_eq!(dsps, v["synthesis"]["dsps"].as_u64().unwrap());
        let (lcs, lcs_available) = used("ICESTORM_LC");
        assert_eq!(lcs_available, 5280);
        assert!(lcs >= v["synthesis"]["luts"].as_u64().unwrap());
        // The harness: one flip-flop per DUT port bit (71 in, 26 out for baseline).
        assert_eq!(v["harness_ffs"], 97);
        assert!(v["synthesis"]["ffs"].as_u64().unwrap() > 97);
        assert_eq!(used("SB_IO").0, 3, "clk, sin, sout");
    }
}

#[test]
fn seven_wide_squarings_need_more_dsps_than_a_up5k_has() {
    // k = 7 with baseline's 17-bit squarings: `specfx cost --target ice40` counts 10 SB_MAC16
    // (the 16 x 11 t product, seven 17 x 17 squares, the 17 x 24 output product in two).
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("k7.toml");
    std::fs::write(&config, "name = \"k7_wide\"\nk = 7\n").unwrap();
    let config = config.to_str().unwrap();
    let o = specfx(&["timing", "--config", config, "--json"]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v = json(&o);
    assert_eq!(v["fits"], false);
    assert!(v["fmax_mhz"].is_null());
    assert!(v["throughput_samples_per_s"].is_null());
    let dsps = v["synthesis"]["dsps"].as_u64().unwrap();
    assert!(dsps > 8, "{dsps} DSPs");
    assert_eq!(
        v["over_limit"][0].as_str().unwrap(),
        format!("{dsps} DSPs > 8 on iCE40 UP5K")
    );
    let text = specfx(&["timing", "--config", config]);
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(
        text.contains(&format!("OVER LIMIT: {dsps} DSPs > 8 on iCE40 UP5K")),
        "{text}"
    );
}

#[test]
fn bad_device_is_one_line_and_exit_code_2() {
    let o = specfx(&["timing", "--device", "ecp5"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    // clap's error, naming the devices (`--device` lists and completes them).
    assert!(err.contains("[possible values: up5k, hx8k]"), "{err}");
}
