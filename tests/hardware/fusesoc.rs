//! The FuseSoC core `hdl_ref/specfx.core` run by FuseSoC itself (pinned in
//! `hdl_ref/cocotb/requirements.txt`, installed by `./scripts/test` in `target/cocotb-venv`):
//! its lint (Verilator), sim (Icarus, the vector testbench) and dpi (Verilator, the DPI
//! scoreboard) targets on the baseline with the core's defaults, a generated configuration
//! through `specfx hdl params --format fusesoc`, and a lint warning that fails the lint target.

use crate::common::{capi_dir, config_path, specfx, venv_python};

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const CORE: &str = "specfx:specfx:specfx_top";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn temp_dir(name: &str) -> PathBuf {
    let p = std::env::temp_dir().join(format!("specfx-fusesoc-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&p);
    std::fs::create_dir_all(&p).unwrap();
    p
}

/// `fusesoc --cores-root CORES run --work-root WORK --target TARGET specfx_top ARGS`, with
/// FuseSoC's own configuration and cache under WORK (nothing written in the home directory).
fn fusesoc(cores: &Path, work: &Path, target: &str, args: &[String]) -> Output {
    let bin = venv_python().with_file_name("fusesoc");
    assert!(
        bin.is_file(),
        "{}: no FuseSoC; ./scripts/test installs it from hdl_ref/cocotb/requirements.txt",
        bin.display()
    );
    Command::new(bin)
        .arg("--cores-root")
        .arg(cores)
        .arg("run")
        .arg("--work-root")
        .arg(work.join(target))
        .args(["--target", target, CORE])
        .args(args)
        .env("XDG_CONFIG_HOME", work.join("xdg-config"))
        .env("XDG_CACHE_HOME", work.join("xdg-cache"))
        .env("XDG_DATA_HOME", work.join("xdg-data"))
        .env("SPECFX_DPI_LIB", capi_dir().join("libspecfx_c.a"))
        .current_dir(work)
        .output()
        .expect("fusesoc runs")
}

fn text(o: &Output) -> String {
    format!(
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The testbench's `N passed, N failed` line.
fn summary(o: &Output) -> (u64, u64) {
    let t = text(o);
    t.lines()
        .find_map(|l| {
            let (p, f) = l.trim().split_once(" passed, ")?;
            Some((p.parse().ok()?, f.strip_suffix(" failed")?.parse().ok()?))
        })
        .unwrap_or_else(|| panic!("no `N passed, N failed` line:\n{t}"))
}

fn ok(o: &Output) -> bool {
    o.status.success()
}

/// Vectors for `args` and their stimulus for the architecture `arch` in `work`; returns the
/// sim target's flags for them (`--NVEC`, `--NCYC` from the manifest and stim.json,
/// `--vectors`, `--stimulus`).
fn vectors(work: &Path, args: &[&str], arch: &str) -> Vec<String> {
    let (vec, stim) = (work.join("vec"), work.join("stim"));
    let mut all = vec!["vectors", "--out", vec.to_str().unwrap()];
    all.extend_from_slice(args);
    let o = specfx(&all);
    assert!(ok(&o), "{}", text(&o));
    let o = specfx(&[
        "hdl",
        "stimulus",
        "--vectors",
        vec.to_str().unwrap(),
        "--out",
        stim.to_str().unwrap(),
        "--arch",
        arch,
        "--seed",
        "5",
        "--bubble",
        "0.3",
        "--stall",
        "0.3",
    ]);
    assert!(ok(&o), "{}", text(&o));
    let json = |p: PathBuf| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
    };
    let nvec = json(vec.join("manifest.json"))["n_vectors"]
        .as_u64()
        .unwrap();
    let ncyc = json(stim.join("stim.json"))["n_cycles"].as_u64().unwrap();
    vec![
        format!("--NVEC={nvec}"),
        format!("--NCYC={ncyc}"),
        format!("--vectors={}", vec.display()),
        format!("--stimulus={}", stim.display()),
    ]
}

/// `specfx hdl params ARGS --format fusesoc`, one flag per line.
fn params(args: &[&str]) -> Vec<String> {
    let mut all = vec!["hdl", "params", "--format", "fusesoc"];
    all.extend_from_slice(args);
    let o = specfx(&all);
    assert!(ok(&o), "{}", text(&o));
    String::from_utf8(o.stdout)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

#[test]
fn the_core_lists_every_rtl_file() {
    let core = std::fs::read_to_string(root().join("hdl_ref/specfx.core")).unwrap();
    let mut listed: Vec<&str> = core
        .lines()
        .filter_map(|l| l.trim().strip_prefix("- rtl/"))
        .collect();
    listed.sort_unstable();
    let mut on_disk: Vec<String> = std::fs::read_dir(root().join("hdl_ref/rtl"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".v"))
        .collect();
    on_disk.sort_unstable();
    assert_eq!(listed, on_disk, "hdl_ref/specfx.core's rtl fileset");
}

/// The core's defaults are the baseline: each target runs with no parameter flag.
#[test]
fn fusesoc_runs_lint_sim_and_dpi_on_the_baseline() {
    let work = temp_dir("baseline");
    let cores = root().join("hdl_ref");
    let o = fusesoc(&cores, &work, "lint", &[]);
    assert!(ok(&o), "lint:\n{}", text(&o));

    let sim = vectors(
        &work,
        &["--n", "16,17,100,1024", "--seed", "3"],
        "pipelined",
    );
    let nvec: u64 = sim[0].strip_prefix("--NVEC=").unwrap().parse().unwrap();
    let o = fusesoc(&cores, &work, "sim", &sim);
    assert!(ok(&o), "sim:\n{}", text(&o));
    assert_eq!(summary(&o), (nvec, 0), "sim:\n{}", text(&o));

    let o = fusesoc(
        &cores,
        &work,
        "dpi",
        &["--nvec=3000".into(), "--seed=9".into()],
    );
    assert!(ok(&o), "dpi:\n{}", text(&o));
    let (passed, failed) = summary(&o);
    assert!(passed > 3000 && failed == 0, "dpi:\n{}", text(&o));
    assert!(text(&o).contains("coverage: "), "dpi:\n{}", text(&o));
    let _ = std::fs::remove_dir_all(&work);
}

/// A generated configuration's parameters reach the RTL through `specfx hdl params --format
/// fusesoc`: with them every vector passes; with the core's defaults (the baseline) the same
/// vectors fail, so the flags are what made them pass.
#[test]
fn the_core_takes_a_configuration_through_hdl_params() {
    let work = temp_dir("config");
    let cores = root().join("hdl_ref");
    let config = config_path("every_mode.toml");
    let cfg = ["--config", config.as_str(), "--n", "16,40"];
    let sim = vectors(&work, &cfg, "folded");
    let flags = params(&[&cfg[..2], &["--arch", "folded"]].concat());
    assert!(flags.iter().any(|f| f == "--ARCH=1"), "{flags:?}");

    let o = fusesoc(&cores, &work, "lint", &flags);
    assert!(ok(&o), "lint:\n{}", text(&o));
    let o = fusesoc(&cores, &work, "sim", &[sim.clone(), flags].concat());
    let nvec: u64 = sim[0].strip_prefix("--NVEC=").unwrap().parse().unwrap();
    assert_eq!(summary(&o), (nvec, 0), "sim:\n{}", text(&o));
    let o = fusesoc(&cores, &work, "sim", &sim);
    let (_, failed) = summary(&o);
    assert!(
        failed > 0,
        "the baseline's RTL passed another configuration's vectors"
    );
    let _ = std::fs::remove_dir_all(&work);
}

/// The lint target is `verilator --lint-only -Wall`: one truncating assignment fails it.
#[test]
fn the_lint_target_fails_on_a_warning() {
    let work = temp_dir("lint");
    let cores = work.join("hdl_ref");
    std::fs::create_dir_all(cores.join("rtl")).unwrap();
    std::fs::copy(
        root().join("hdl_ref/specfx.core"),
        cores.join("specfx.core"),
    )
    .unwrap();
    for e in std::fs::read_dir(root().join("hdl_ref/rtl")).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, cores.join("rtl").join(p.file_name().unwrap())).unwrap();
    }
    let top = cores.join("rtl/specfx_top.v");
    let src = std::fs::read_to_string(&top).unwrap();
    let at = src.rfind("endmodule").unwrap();
    let broken = format!(
        "{}    wire [3:0] specfx_narrow = {{in_c, 1'b0}};\n{}",
        &src[..at],
        &src[at..]
    );
    std::fs::write(&top, broken).unwrap();
    let o = fusesoc(&cores, &work, "lint", &[]);
    assert!(
        !ok(&o),
        "lint passed a truncating assignment:\n{}",
        text(&o)
    );
    assert!(text(&o).contains("%Warning-WIDTH"), "{}", text(&o));
    let _ = std::fs::remove_dir_all(&work);
}

/// A copy of `hdl_ref/` (the core, the RTL, the testbenches) under `work`, with the output
/// multiplier of the pipelined core taking the previous stage's coefficient (a coefficient
/// register skipped).
fn broken_core(work: &Path) -> PathBuf {
    let cores = work.join("hdl_ref");
    for sub in ["rtl", "tb", "dpi"] {
        std::fs::create_dir_all(cores.join(sub)).unwrap();
        for e in std::fs::read_dir(root().join("hdl_ref").join(sub)).unwrap() {
            let p = e.unwrap().path();
            std::fs::copy(&p, cores.join(sub).join(p.file_name().unwrap())).unwrap();
        }
    }
    std::fs::copy(
        root().join("hdl_ref/specfx.core"),
        cores.join("specfx.core"),
    )
    .unwrap();
    let file = cores.join("rtl/specfx_pipelined.v");
    let text = std::fs::read_to_string(&file).unwrap();
    let (from, to) = (
        ".coef(coefs[K*COEF_W +: COEF_W])",
        ".coef(coefs[(K-1)*COEF_W +: COEF_W])",
    );
    assert_eq!(text.matches(from).count(), 1, "the mutated piece moved");
    std::fs::write(&file, text.replace(from, to)).unwrap();
    cores
}

/// A CI job can trust FuseSoC's exit code: with a broken RTL, the sim and dpi targets count
/// failed vectors and end with a failing status (the testbenches' `$fatal`); and the sim
/// target without `--NVEC`/`--NCYC` refuses to run (it used to check one vector and pass).
#[test]
fn fusesoc_fails_on_a_broken_rtl_and_without_the_vector_count() {
    let work = temp_dir("broken");
    let cores = broken_core(&work);
    let sim = vectors(
        &work,
        &["--n", "16,17,100,1024", "--seed", "3"],
        "pipelined",
    );
    let o = fusesoc(&cores, &work, "sim", &sim);
    let (_, failed) = summary(&o);
    assert!(failed > 0 && !ok(&o), "sim on a broken RTL:\n{}", text(&o));

    let o = fusesoc(
        &cores,
        &work,
        "dpi",
        &["--nvec=200".into(), "--seed=9".into()],
    );
    let (_, failed) = summary(&o);
    assert!(failed > 0 && !ok(&o), "dpi on a broken RTL:\n{}", text(&o));

    // The unbroken core without the counts: a refusal naming what to pass, not a pass (in a
    // build root of its own: FuseSoC would reuse the broken core's build, docs: README).
    let good = root().join("hdl_ref");
    let fresh = work.join("unbroken");
    std::fs::create_dir_all(&fresh).unwrap();
    for (drop, name, want) in [
        ("--NVEC=", "NVEC", "n_vectors of manifest.json"),
        ("--NCYC=", "NCYC", "n_cycles of stim.json"),
    ] {
        let flags: Vec<String> = sim
            .iter()
            .filter(|f| !f.starts_with(drop))
            .cloned()
            .collect();
        let o = fusesoc(&good, &fresh, "sim", &flags);
        assert!(!ok(&o), "sim without {name}:\n{}", text(&o));
        assert!(
            text(&o).contains(&format!("tb_specfx: {name} is not set: expected {want}")),
            "sim without {name}:\n{}",
            text(&o)
        );
        assert!(!text(&o).contains(" passed, "), "{}", text(&o));
    }
    let _ = std::fs::remove_dir_all(&work);
}
