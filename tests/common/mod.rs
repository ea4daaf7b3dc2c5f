//! Helpers shared by the integration tests that drive the built `specfx` binary.

/// The independent big-integer oracle of the datapath (`docs/arithmetic.md` alone).
pub mod oracle;

use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Runs the built `specfx` binary with `args` and returns its output.
#[allow(dead_code)]
pub fn specfx(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_specfx"))
        .args(args)
        .output()
        .expect("the specfx binary runs")
}

/// Runs the built `specfx` binary with `args` in the working directory `dir`.
#[allow(dead_code)]
pub fn specfx_in(dir: &std::path::Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_specfx"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the specfx binary runs")
}

/// The 8-bit sRGB display code of a linear value clamped to [0, 1], written from the standard
/// (IEC 61966-2-1): the tests' oracle of the renderer's encoding.
#[allow(dead_code)]
pub fn srgb8(x: f64) -> u16 {
    let x = x.clamp(0.0, 1.0);
    let s = if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u16
}

/// The path of a configuration in `tests/configs/`, as an argument for `--config`.
#[allow(dead_code)]
pub fn config_path(name: &str) -> String {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/configs")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

/// Every file under `dir` (relative path, bytes), sorted; `measured_*` files left out.
#[allow(dead_code)]
pub fn snapshot(dir: &std::path::Path) -> Vec<(std::path::PathBuf, Vec<u8>)> {
    fn walk(
        root: &std::path::Path,
        dir: &std::path::Path,
        out: &mut Vec<(std::path::PathBuf, Vec<u8>)>,
    ) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else if !p
                .file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("measured_")
            {
                out.push((
                    p.strip_prefix(root).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                ));
            }
        }
    }
    let mut v = Vec::new();
    walk(dir, dir, &mut v);
    v.sort();
    v
}

/// Runs `specfx args...` with its file size limited to `blocks` 512-byte blocks (SIGXFSZ
/// ignored, so a write past the limit fails with EFBIG as on a full disk), killed if it runs
/// for more than a minute; returns its output and whether it finished by itself.
#[allow(dead_code)]
pub fn limited(blocks: u32, args: &[&str]) -> (Output, bool) {
    let mut line = format!(
        "trap '' XFSZ; ulimit -f {blocks}; exec '{}'",
        env!("CARGO_BIN_EXE_specfx")
    );
    for a in args {
        line.push_str(&format!(" '{a}'"));
    }
    run_guarded(Command::new("sh").args(["-c", &line]))
}

/// Runs a command, killing it after a minute: (output, finished by itself).
#[allow(dead_code)]
pub fn run_guarded(cmd: &mut Command) -> (Output, bool) {
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let finished = loop {
        if child.try_wait().unwrap().is_some() {
            break true;
        }
        if start.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            break false;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    (child.wait_with_output().unwrap(), finished)
}

/// A unit sphere at the origin seen from (0, 0, 5) in a 3x3 image, lit from the camera.
#[allow(dead_code)]
pub fn sphere_scene(k_s: f64, n: u32, intensity: f64, ambient: f64) -> String {
    format!(
        r#"
[image]
width = 3
height = 3

[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov_deg = 30.0

[shading]
model = "phong"
ambient = {ambient}

[[light]]
kind = "directional"
direction = [0.0, 0.0, 1.0]
colour = [1.0, 0.5, 0.25]
intensity = {intensity}

[[material]]
name = "m"
n = {n}
k_s = {k_s}
k_d = 0.5
colour = [0.8, 0.6, 0.4]

[[object]]
kind = "sphere"
material = "m"
center = [0.0, 0.0, 0.0]
radius = 1.0
"#
    )
}

/// The directory holding the C library `libspecfx_c.a`/`.so` (capi/) of this build profile:
/// the test binary's `target/<profile>/`. `cargo test` and `./scripts/test` build it with the
/// tests; a test needing it fails with one clear line when it is missing.
#[allow(dead_code)]
pub fn capi_dir() -> std::path::PathBuf {
    let exe = std::env::current_exe().expect("the test binary's path");
    let deps = exe.parent().expect("target/<profile>/deps/<test>");
    let profile = deps.parent().expect("target/<profile>/deps");
    // `cargo build` puts the library in target/<profile>/; `cargo test` alone builds it as
    // the C crate's tests' dependency, in deps/.
    [profile, deps]
        .into_iter()
        .find(|d| d.join("libspecfx_c.a").is_file())
        .unwrap_or_else(|| {
            panic!(
                "{}: no libspecfx_c.a; build the C library with `cargo build` (a plain `cargo test` builds it too)",
                profile.display()
            )
        })
        .to_path_buf()
}

/// The flags that link a program against `libspecfx_c.a` (rustc's native-static-libs: the
/// C++ of nv-flip needs libstdc++).
#[allow(dead_code)]
pub const CAPI_LINK_FLAGS: &[&str] = &["-lstdc++", "-lpthread", "-lm", "-ldl"];

/// The Python of the virtual environment `./scripts/test` makes (cocotb, FuseSoC, numpy and the
/// specfx wheel): `$SPECFX_COCOTB_PYTHON`, else `target/cocotb-venv/bin/python`; a test
/// needing it fails with one clear line when it is missing.
#[allow(dead_code)]
pub fn venv_python() -> std::path::PathBuf {
    let python = std::env::var_os("SPECFX_COCOTB_PYTHON")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| {
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/cocotb-venv/bin/python")
        });
    assert!(
        python.is_file(),
        "{}: no Python with cocotb and FuseSoC; ./scripts/test makes it (or: python3 -m venv \
         target/cocotb-venv && target/cocotb-venv/bin/pip install -r \
         hdl_ref/cocotb/requirements.txt), or set SPECFX_COCOTB_PYTHON",
        python.display()
    );
    python
}
