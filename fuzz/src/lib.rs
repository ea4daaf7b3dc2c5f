//! The checks of specfx's fuzz targets, one function per parser: each feeds the bytes to the
//! parser the command line uses and panics when a property fails (a panic inside the parser
//! itself, an error that is empty or spans lines, a printed value that parses to something
//! else). The fuzz targets (`fuzz/fuzz_targets/`) call them, and so does
//! `tests/fuzz_corpus.rs` on the committed corpus and reproducers, which includes this file as
//! a module: it uses only `specfx` and `serde_json`.

use std::fmt::Display;

use specfx::analysis::budget_expr::Budget;
use specfx::analysis::sweep::{Space, MAX_POINTS};
use specfx::cycle::compare::compare;
use specfx::fixed::{Format, Overflow, Rounding};
use specfx::golden::verify::{VerifiedManifest, CSV_FILE};
use specfx::hdl::testbench::parse_log;
use specfx::nset::{NSet, N_MAX};
use specfx::pipeline::{Config, Datapath};
use specfx::scene::fit::ImageBudget;
use specfx::scene::mesh::{Mesh, MeshFormat};
use specfx::scene::Scene;

/// A target's check: panics when a property fails; returns whether the input was accepted.
pub type Check = fn(&[u8]) -> bool;

/// Every target with its check, by name (the names of `fuzz/corpus/<target>/`). A check
/// returns whether the input was accepted (by any of the parsers it feeds).
pub const TARGETS: &[(&str, Check)] = &[
    ("config", config),
    ("space", space),
    ("scene", scene),
    ("nset", nset),
    ("budget", budget),
    ("format", format),
    ("manifest", manifest),
    ("mesh_obj", mesh_obj),
    ("mesh_stl", mesh_stl),
    ("trace", trace),
    ("testbench_log", testbench_log),
];

/// A refused input: its error is one line; not accepted.
fn refused(input: &str, err: &impl Display) -> bool {
    assert_one_line(input, err);
    false
}

/// An error a user sees: one non-empty line (the command prints it after `specfx: error:`).
fn assert_one_line(input: &str, err: &impl Display) {
    let message = err.to_string();
    assert!(
        !message.trim().is_empty(),
        "empty error message for {input:?}"
    );
    assert!(
        !message.contains(['\n', '\r']),
        "error message spans lines for {input:?}: {message:?}"
    );
}

/// The text of a text input: the command refuses a file that is not UTF-8 before parsing it
/// (and clap an argument), so other bytes test nothing here.
fn text(data: &[u8]) -> Option<&str> {
    std::str::from_utf8(data).ok()
}

/// A datapath configuration file (`--config FILE`): `Config::from_toml`, then
/// `Datapath::new`. A configuration read back from its TOML (`Config::to_toml`, which `fit`
/// and `optimize` write) is the same configuration.
pub fn config(data: &[u8]) -> bool {
    let Some(text) = text(data) else {
        return false;
    };
    let config = match Config::from_toml(text) {
        Ok(c) => c,
        Err(e) => return refused(text, &e),
    };
    let printed = config.to_toml();
    match Config::from_toml(&printed) {
        Ok(again) => assert_eq!(again, config, "{text:?} printed as {printed:?}"),
        Err(e) => panic!("{text:?} printed as {printed:?} does not parse: {e}"),
    }
    datapath(text, config)
}

/// Validates a configuration: whether it is valid; an error is one line.
fn datapath(input: &str, config: Config) -> bool {
    match Datapath::new(config) {
        Ok(_) => true,
        Err(e) => refused(input, &e),
    }
}

/// A vector directory (`--config DIR`, `--vectors DIR`) in one input: the text of its
/// `manifest.json`, then `vectors.csv` and the hex files in the order of the manifest's ports,
/// separated by NUL bytes; checked as the command line checks a directory
/// (`golden::verify::VerifiedManifest`), except that a sha256 mismatch (which the command
/// refuses first) does not stop the other checks. Every error is one line; an accepted
/// manifest's configuration is valid and reads back from the JSON `specfx vectors` writes;
/// an accepted CSV has `n_vectors` rows of one value per port, each n in the set; an accepted
/// hex file has a line per vector.
pub fn manifest(data: &[u8]) -> bool {
    let mut parts = data.split(|&b| b == 0);
    let Some(text) = parts.next().and_then(text) else {
        return false;
    };
    let m = match VerifiedManifest::parse(text, "manifest.json") {
        Ok(m) => m,
        Err(e) => return refused(text, &e),
    };
    let config = m.config().clone();
    let printed = serde_json::to_string(&config).expect("a configuration serialises");
    match serde_json::from_str::<Config>(&printed) {
        Ok(again) => assert_eq!(again, config, "{text:?} printed as {printed:?}"),
        Err(e) => panic!("{text:?} printed as {printed:?} does not parse: {e}"),
    }
    if let Err(e) = Datapath::new(config) {
        panic!("{text:?}: a verified manifest holds an invalid configuration: {e}");
    }
    let csv = parts.next().unwrap_or(b"");
    if let Err(e) = m.check_sha256(CSV_FILE, csv, CSV_FILE) {
        assert_one_line(text, &e);
    }
    let rows = match m.read_csv(csv, CSV_FILE) {
        Ok(rows) => rows,
        Err(e) => return refused(text, &e),
    };
    let n_ports = m.ports().len() as u64;
    assert_eq!(rows.len() as u64, m.n_vectors() * n_ports, "{text:?}");
    let inputs = match m.inputs(&rows, CSV_FILE) {
        Ok(inputs) => inputs,
        Err(e) => return refused(text, &e),
    };
    assert_eq!(inputs.len() as u64, m.n_vectors(), "{text:?}");
    assert!(inputs
        .iter()
        .all(|(n, _)| m.config().n.values().binary_search(n).is_ok()));
    for (j, port) in m.ports().iter().enumerate() {
        let hex = parts.next().unwrap_or(b"");
        match m.check_hex(j, hex, &port.file_name(), &rows) {
            Ok(()) => {
                let lines = std::str::from_utf8(hex)
                    .expect("accepted hex is text")
                    .lines();
                assert_eq!(lines.count() as u64, m.n_vectors(), "{text:?}");
            }
            Err(e) => return refused(text, &e),
        }
    }
    true
}

/// A design space (`specfx sweep --space FILE`): `Space::from_toml`. A space has 1 to
/// `MAX_POINTS` points, its first and last points are built or refused in one line, and the
/// space reads back from the `space.json` a sweep writes (resuming compares the two).
pub fn space(data: &[u8]) -> bool {
    let Some(text) = text(data) else {
        return false;
    };
    let space = match Space::from_toml(text) {
        Ok(s) => s,
        Err(e) => return refused(text, &e),
    };
    let n_points = space.n_points();
    assert!(
        (1..=MAX_POINTS).contains(&n_points),
        "{text:?}: {n_points} points"
    );
    for index in [0, n_points - 1] {
        match space.point(index) {
            Ok((config, _arch)) => {
                datapath(text, config);
            }
            Err(e) => assert_one_line(text, &e),
        }
    }
    let json = serde_json::to_string(&space).expect("a space serialises");
    let again: Space = serde_json::from_str(&json)
        .unwrap_or_else(|e| panic!("{text:?} as space.json {json:?} does not read back: {e}"));
    assert_eq!(again, space, "{text:?} as space.json {json:?}");
    true
}

/// The mesh files a fuzzed scene names: a tetrahedron in either format, and no other file.
fn scene_loader(name: &str) -> std::io::Result<Vec<u8>> {
    match MeshFormat::of(name) {
        Some(MeshFormat::Obj) if name.starts_with("tetra") => Ok(
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n".to_vec(),
        ),
        Some(MeshFormat::Stl) if name.starts_with("tetra") => Ok(b"solid t
facet normal 0 0 -1
outer loop
vertex 0 0 0
vertex 0 1 0
vertex 1 0 0
endloop
endfacet
facet normal 0 -1 0
outer loop
vertex 0 0 0
vertex 1 0 0
vertex 0 0 1
endloop
endfacet
endsolid t
"
        .to_vec()),
        _ => Err(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            "no such file",
        )),
    }
}

/// A scene (`specfx render --scene FILE`, `specfx fit`): `Scene::from_toml_with`, meshes read
/// by a loader that knows `tetra.obj` and `tetra.stl`. What it accepts is valid everywhere:
/// every mesh vertex is finite after its scale and translation.
pub fn scene(data: &[u8]) -> bool {
    let Some(text) = text(data) else {
        return false;
    };
    let scene = match Scene::from_toml_with(text, &scene_loader) {
        Ok(s) => s,
        Err(e) => return refused(text, &e),
    };
    assert!(!scene.exponents().is_empty(), "{text:?}: no material");
    for mesh in &scene.meshes {
        check_mesh(text, mesh);
    }
    true
}

/// What a parsed mesh guarantees the renderer: triangles, all finite, a finite bound, and a
/// ray cast through its hierarchy that returns a hit ahead with a unit normal, or none.
fn check_mesh(input: &str, mesh: &Mesh) {
    assert!(!mesh.triangles.is_empty(), "{input:?}: no triangle");
    assert!(
        mesh.triangles
            .iter()
            .flatten()
            .flatten()
            .all(|x| x.is_finite()),
        "{input:?}: a vertex is not finite"
    );
    let (centre, radius) = mesh.bound();
    assert!(
        centre.iter().all(|x| x.is_finite()) && radius.is_finite() && radius >= 0.0,
        "{input:?}: bound {centre:?} {radius}"
    );
    let origin = [centre[0] + 2.0 * radius + 1.0, centre[1], centre[2]];
    if let Some((dist, normal)) = mesh.hit(origin, [-1.0, 0.0, 0.0]) {
        assert!(dist > 0.0, "{input:?}: hit behind the ray at {dist}");
        let len = normal.iter().map(|x| x * x).sum::<f64>().sqrt();
        // A degenerate triangle's normal is NaN; the renderer skips a NaN normal's shading.
        assert!(
            len.is_nan() || (len - 1.0).abs() < 1e-9,
            "{input:?}: normal {normal:?}"
        );
    }
}

/// A mesh file in `format`, as a scene's `kind = "mesh"` object reads it (scale 1, at the
/// origin).
fn mesh_file(data: &[u8], format: MeshFormat, name: &str) -> bool {
    let input = String::from_utf8_lossy(data);
    match Mesh::parse(data, format, 1.0, [0.0; 3], name) {
        Ok(mesh) => {
            check_mesh(&input, &mesh);
            true
        }
        Err(e) => refused(&input, &e),
    }
}

/// A Wavefront OBJ mesh file: `Mesh::parse`.
pub fn mesh_obj(data: &[u8]) -> bool {
    mesh_file(data, MeshFormat::Obj, "object[0].file (m.obj)")
}

/// An STL mesh file, binary or ASCII: `Mesh::parse`.
pub fn mesh_stl(data: &[u8]) -> bool {
    mesh_file(data, MeshFormat::Stl, "object[0].file (m.stl)")
}

/// An n set (`--n SET`, `n = "..."` in configurations and spaces): `NSet::from_str`. The
/// values are ascending, distinct and in 1..=N_MAX; the printed set parses to the same set,
/// and so does the set rebuilt from its values.
pub fn nset(data: &[u8]) -> bool {
    let Some(text) = text(data) else {
        return false;
    };
    let set = match text.parse::<NSet>() {
        Ok(s) => s,
        Err(e) => return refused(text, &e),
    };
    let values = set.values();
    assert!(!values.is_empty(), "{text:?}: empty set");
    assert!(
        values.windows(2).all(|w| w[0] < w[1]),
        "{text:?}: not ascending and distinct"
    );
    assert!(
        set.min() >= 1 && set.max() <= N_MAX,
        "{text:?}: {}..={}",
        set.min(),
        set.max()
    );
    let printed = set.to_string();
    assert_eq!(printed.parse::<NSet>().as_ref(), Ok(&set), "{text:?}");
    let rebuilt = NSet::from_values(values).expect("values of a set");
    assert_eq!(rebuilt.values(), values, "{text:?} rebuilt as {rebuilt}");
    true
}

/// A budget expression: `Budget::from_str` (`specfx optimize --budget`, `specfx budget
/// --budget`) and `ImageBudget::from_str` (`specfx fit --budget`). Every limit is finite and
/// non-negative, and the printed budget parses to the same budget.
pub fn budget(data: &[u8]) -> bool {
    let Some(text) = text(data) else {
        return false;
    };
    let datapath_budget = match text.parse::<Budget>() {
        Ok(b) => {
            assert!(!b.bounds.is_empty(), "{text:?}: no bound");
            for bound in &b.bounds {
                assert!(
                    bound.limit.is_finite() && bound.limit >= 0.0,
                    "{text:?}: {bound:?}"
                );
            }
            assert_eq!(b.to_string().parse::<Budget>().as_ref(), Ok(&b), "{text:?}");
            true
        }
        Err(e) => refused(text, &e),
    };
    let image_budget = match text.parse::<ImageBudget>() {
        Ok(b) => {
            assert!(!b.bounds.is_empty(), "{text:?}: no bound");
            for bound in &b.bounds {
                assert!(
                    bound.limit.is_finite() && bound.limit >= 0.0,
                    "{text:?}: {bound:?}"
                );
            }
            assert_eq!(
                b.to_string().parse::<ImageBudget>().as_ref(),
                Ok(&b),
                "{text:?}"
            );
            true
        }
        Err(e) => refused(text, &e),
    };
    datapath_budget || image_budget
}

/// A fixed-point format (`u1.15`, in configurations and spaces) and the rounding and overflow
/// mode names: `FromStr`. A format's notation is canonical, so it prints back as the very
/// text; a mode prints as its name in upper case. The raw range is the width's.
pub fn format(data: &[u8]) -> bool {
    let Some(text) = text(data) else {
        return false;
    };
    let format = match text.parse::<Format>() {
        Ok(f) => {
            assert_eq!(f.to_string(), text);
            assert!(
                (1..=64).contains(&f.width()),
                "{text:?}: width {}",
                f.width()
            );
            let magnitude_bits = f.width() - u32::from(f.is_signed());
            let span = i128::from(f.max_raw()) - i128::from(f.min_raw()) + 1;
            assert_eq!(span, 1i128 << f.width(), "{text:?}: raw range");
            assert_eq!(
                i128::from(f.max_raw()),
                (1i128 << magnitude_bits) - 1,
                "{text:?}: largest raw"
            );
            assert!(f.lsb() > 0.0 && f.lsb().is_finite(), "{text:?}: lsb");
            true
        }
        Err(e) => refused(text, &e),
    };
    let rounding = match text.parse::<Rounding>() {
        Ok(r) => {
            assert_eq!(r.to_string(), text.to_ascii_uppercase());
            true
        }
        Err(e) => refused(text, &e),
    };
    let overflow = match text.parse::<Overflow>() {
        Ok(o) => {
            assert_eq!(o.to_string(), text.to_ascii_uppercase());
            true
        }
        Err(e) => refused(text, &e),
    };
    format || rounding || overflow
}

/// A VCD trace (`specfx trace compare`): the trace compared with itself. It is read without a
/// panic or a stack overflow and refused with one line, or it agrees with itself: no width
/// differs and no known bit does.
pub fn trace(data: &[u8]) -> bool {
    match compare(data, data) {
        Err(e) => refused(&String::from_utf8_lossy(data), &e),
        Ok(c) => {
            assert!(
                c.first_difference.is_none() && c.width_mismatches.is_empty(),
                "a trace differs from itself: {c:?}"
            );
            true
        }
    }
}

/// A simulator's log of the reference testbench (`specfx cosim`): `hdl::testbench::parse_log`.
/// A log without a summary is refused with one line; an accepted log's problems are exactly
/// its lines that begin with a problem's word or with the DPI testbench's `coverage:`, and a
/// summary line appended to any log is the one read.
pub fn testbench_log(data: &[u8]) -> bool {
    let log = String::from_utf8_lossy(data);
    let problems = log
        .lines()
        .filter(|l| {
            ["mismatch", "protocol", "unexpected", "timeout", "coverage:"]
                .iter()
                .any(|p| l.starts_with(p))
        })
        .count();
    let appended = format!("{log}\n7 passed, 3 failed\n");
    let tally = parse_log(&appended).expect("a log ending with its summary");
    assert_eq!((tally.passed, tally.failed), (7, 3), "{log:?}");
    assert_eq!(tally.problems.len(), problems, "{log:?}");
    match parse_log(&log) {
        Ok(t) => {
            assert_eq!(t.problems.len(), problems, "{log:?}");
            true
        }
        Err(e) => refused(&log, &e),
    }
}
