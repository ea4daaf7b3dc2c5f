//! The microarchitecture a configuration records (its `arch` key): `optimize` writes the one
//! its answer was costed with, and every command that reads the file takes it as its default
//! while `--arch` still overrides it.

use crate::common::specfx;

use std::path::PathBuf;

fn temp_path(name: &str) -> PathBuf {
    let p = std::env::temp_dir().join(format!("specfx-arch-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&p);
    let _ = std::fs::remove_file(&p);
    p
}

fn ok_stdout(args: &[&str]) -> String {
    let o = specfx(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap()
}

fn json(args: &[&str]) -> serde_json::Value {
    serde_json::from_str(&ok_stdout(args)).unwrap()
}

/// k = 6 minimax pipelined needs k + 2 = 8 multipliers, one DSP block each at the least, and
/// its widest products take more: it does not fit the UP5K's 8 DSP blocks, so the answer is
/// folded (one shared multiplier), and the file says so; `cost` then costs it folded, as
/// `optimize` did, unless `--arch pipelined` is given.
#[test]
fn the_answer_records_its_architecture_and_cost_reads_it() {
    let out = temp_path("k6.toml");
    let out_s = out.to_str().unwrap();
    let o = specfx(&[
        "optimize",
        "--n",
        "64",
        "--k",
        "6",
        "--variants",
        "minimax",
        "--out",
        out_s,
    ]);
    let (stdout, stderr) = (
        String::from_utf8(o.stdout).unwrap(),
        String::from_utf8(o.stderr).unwrap(),
    );
    assert!(o.status.success(), "{stderr}");
    assert!(stdout.contains("best: k = 6, minimax, folded"), "{stdout}");
    // The progress names each pass's architecture: the pipelined answer does not fit the
    // UP5K, the folded one does.
    let pipelined = stderr
        .lines()
        .position(|l| l.starts_with("optimize: k = 6 minimax, pipelined: nothing meets"));
    let folded = stderr
        .lines()
        .position(|l| l.starts_with("optimize: k = 6 minimax, folded: "));
    assert!(pipelined.is_some() && folded > pipelined, "{stderr}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.lines().any(|l| l == "arch = \"folded\""), "{text}");
    let folded = json(&["cost", "--config", out_s, "--analytic-only", "--json"]);
    assert_eq!(folded["arch"], "folded");
    assert!(
        folded["over_limit"].as_array().unwrap().is_empty(),
        "{folded}"
    );
    let dsps = folded["analytic"]["dsps"].as_u64().unwrap();
    assert!(dsps <= 8, "{dsps}");
    let piped = json(&[
        "cost",
        "--config",
        out_s,
        "--analytic-only",
        "--json",
        "--arch",
        "pipelined",
    ]);
    assert_eq!(piped["arch"], "pipelined");
    assert!(piped["analytic"]["dsps"].as_u64().unwrap() > 8, "{piped}");
    // An earlier answer as the base: its architecture is optimize's own default.
    let again = temp_path("k6-again.toml");
    let stdout = ok_stdout(&[
        "optimize",
        "--config",
        out_s,
        "--k",
        "6",
        "--variants",
        "minimax",
        "--device",
        "none",
        "--out",
        again.to_str().unwrap(),
    ]);
    assert!(stdout.contains("best: k = 6, minimax, folded"), "{stdout}");
    let _ = std::fs::remove_file(&out);
    let _ = std::fs::remove_file(&again);
}

/// A hand-written configuration with `arch = "folded"`: `hdl params`, `sim` and `cost` default
/// to folded (`SPECFX_ARCH` 1, `docs/cycle.md`), `--arch pipelined` overrides each; the vector
/// directory written from it records it, and `hdl stimulus` on those vectors runs folded.
#[test]
fn every_command_that_reads_the_file_defaults_to_its_arch() {
    let cfg = temp_path("folded.toml");
    std::fs::write(&cfg, "arch = \"folded\"\nk = 3\nn = \"16..=64\"\n").unwrap();
    let c = cfg.to_str().unwrap();
    let define = |extra: &[&str]| {
        let mut args = vec!["hdl", "params", "--config", c];
        args.extend_from_slice(extra);
        let text = ok_stdout(&args);
        text.lines()
            .find(|l| l.starts_with("`define SPECFX_ARCH "))
            .unwrap()
            .to_string()
    };
    assert_eq!(define(&[]), "`define SPECFX_ARCH 1");
    assert_eq!(define(&["--arch", "pipelined"]), "`define SPECFX_ARCH 0");
    let sim = |extra: &[&str]| {
        let mut args = vec!["sim", "--config", c, "--cycles", "50", "--json"];
        args.extend_from_slice(extra);
        json(&args)["arch"].clone()
    };
    assert_eq!(sim(&[]), "folded");
    assert_eq!(sim(&["--arch", "pipelined"]), "pipelined");
    let cost = json(&["cost", "--config", c, "--analytic-only", "--json"]);
    assert_eq!(cost["arch"], "folded");
    // Folded: k + 2 = 5 products on one multiplier, one latency each, one input every 5 cycles.
    assert_eq!(cost["analytic"]["initiation_interval"], 5);

    let vec_dir = temp_path("vectors");
    let v = vec_dir.to_str().unwrap();
    ok_stdout(&["vectors", "--config", c, "--cases", "corner", "--out", v]);
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(vec_dir.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["config"]["arch"], "folded");
    let stim = temp_path("stim");
    let s = stim.to_str().unwrap();
    let line = ok_stdout(&["hdl", "stimulus", "--vectors", v, "--out", s]);
    assert!(line.contains("(folded, "), "{line}");
    let line = ok_stdout(&[
        "hdl",
        "stimulus",
        "--vectors",
        v,
        "--out",
        s,
        "--arch",
        "pipelined",
    ]);
    assert!(line.contains("(pipelined, "), "{line}");
    let _ = std::fs::remove_file(&cfg);
    let _ = std::fs::remove_dir_all(&vec_dir);
    let _ = std::fs::remove_dir_all(&stim);
}

/// A bad `arch` key is refused with one line naming the file, the key and the two values.
#[test]
fn a_bad_arch_key_is_refused_by_name() {
    let cfg = temp_path("bad-arch.toml");
    std::fs::write(&cfg, "k = 3\narch = \"fold\"\n").unwrap();
    let o = specfx(&["cost", "--config", cfg.to_str().unwrap(), "--analytic-only"]);
    assert_eq!(o.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        stderr.trim_end(),
        format!(
            "specfx: error: config {}: line 2: arch: expected \"pipelined\" or \"folded\" (the microarchitecture), got \"fold\"",
            cfg.display()
        )
    );
    let _ = std::fs::remove_file(&cfg);
}

/// `budget` counts a cost ceiling on the configuration's architecture: k = 3 pipelined has
/// k + 2 = 5 multipliers, each at least one DSP block, so `dsps <= 4` fails; the same datapath
/// recorded folded shares one multiplier and passes.
#[test]
fn budget_counts_cost_ceilings_on_the_recorded_arch() {
    for (arch_line, code) in [("", 1), ("arch = \"folded\"\n", 0)] {
        let cfg = temp_path(&format!("budget{code}.toml"));
        std::fs::write(&cfg, format!("{arch_line}k = 3\nn = \"16..=64\"\n")).unwrap();
        let out = temp_path(&format!("budget-out{code}"));
        let o = specfx(&[
            "budget",
            "--config",
            cfg.to_str().unwrap(),
            "--budget",
            "dsps <= 4",
            "--no-gappa",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(code), "{arch_line:?}");
        let _ = std::fs::remove_file(&cfg);
        let _ = std::fs::remove_dir_all(&out);
    }
}

/// A design space whose base records an architecture: its points take it (and record it),
/// unless `arch` is an axis; a base without one gives pipelined points that record none.
#[test]
fn sweep_points_take_the_base_arch() {
    use specfx::analysis::sweep::Space;
    use specfx::pipeline::Arch;
    let s = Space::from_toml("[base]\narch = \"folded\"\n[vary]\nk = [3, 4]\n").unwrap();
    let (cfg, arch) = s.point(1).unwrap();
    assert_eq!(
        (cfg.k, arch, cfg.arch),
        (4, Arch::Folded, Some(Arch::Folded))
    );
    let s =
        Space::from_toml("[base]\narch = \"folded\"\n[vary]\narch = [\"pipelined\"]\n").unwrap();
    let (cfg, arch) = s.point(0).unwrap();
    assert_eq!((arch, cfg.arch), (Arch::Pipelined, Some(Arch::Pipelined)));
    let s = Space::from_toml("[vary]\nk = [3]\n").unwrap();
    let (cfg, arch) = s.point(0).unwrap();
    assert_eq!((arch, cfg.arch), (Arch::Pipelined, None));
}
