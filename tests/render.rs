//! Scenes and rendering: the scene parser's errors, pixels checked against closed forms, and
//! `specfx render` through the binary.

mod common;

use specfx::pipeline::{Config, Datapath};
use specfx::scene::render::{render, PATHS};
use specfx::scene::Scene;

/// sRGB encoding, written from the standard (IEC 61966-2-1).
fn srgb(x: f64) -> f64 {
    if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

fn code(x: f64) -> u16 {
    (srgb(x.clamp(0.0, 1.0)) * 255.0).round() as u16
}

/// A unit sphere at the origin seen from (0, 0, 5) in a 3x3 image, lit from the camera.
fn sphere_scene(k_s: f64, n: u32, intensity: f64, ambient: f64) -> String {
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

fn datapath_for(scene: &Scene) -> Datapath {
    let mut cfg = Config::baseline();
    cfg.n = specfx::nset::NSet::from_values(&scene.exponents()).unwrap();
    Datapath::new(cfg).unwrap()
}

/// The centre pixel's ray hits the sphere at (0, 0, 1) head on: N = L = V, so N.L = 1 and the
/// Phong cosine R.V = 1, where every lobe is 1 and the specular term is pi k_s coef. Radiance
/// per channel: ambient colour + (k_d colour + pi k_s coef) light colour intensity. The
/// corners' rays (15 degrees off axis at most, the sphere subtends 11.5) miss: background.
#[test]
fn a_sphere_lit_head_on_has_the_closed_form_centre_pixel() {
    let (k_s, n, intensity, ambient) = (0.002, 100, 0.4, 0.05);
    let scene = Scene::from_toml(&sphere_scene(k_s, n, intensity, ambient)).unwrap();
    let dp = datapath_for(&scene);
    let r = render(&scene, &dp, &|_, _| {});
    let light = [1.0, 0.5, 0.25];
    let colour = [0.8, 0.6, 0.4];
    let pi = std::f64::consts::PI;
    // Phong's classic coefficient, (n + 1) / (2 pi).
    let classic = (f64::from(n) + 1.0) / (2.0 * pi);
    let nc = dp.constants_for(n).unwrap();
    let datapath_coef = dp
        .config()
        .out
        .format
        .to_f64(dp.eval(dp.one_code(), nc).values[dp.stage_out()]);
    for (path, coef) in [(0, classic), (1, nc.coef), (2, datapath_coef)] {
        let want: Vec<u16> = (0..3)
            .map(|ch| {
                code(
                    ambient * colour[ch]
                        + (0.5 * colour[ch] + pi * k_s * coef) * light[ch] * intensity,
                )
            })
            .collect();
        assert_eq!(r.codes[path][4].to_vec(), want, "path {}", PATHS[path]);
    }
    assert_eq!(r.material[4], Some(0));
    for corner in [0, 2, 6, 8] {
        assert_eq!(r.material[corner], None);
    }
    // The edge pixels' rays are 10.7 degrees off axis: they hit (the sphere subtends 11.5).
    assert_eq!(r.material[1], Some(0));
}

/// Off centre, the hit point and normal follow from the ray-sphere intersection in closed
/// form; with k_s = 0 every path is the Lambert term, max(0, N.L) k_d colour.
#[test]
fn a_diffuse_sphere_matches_lambert_off_centre() {
    let scene = Scene::from_toml(&sphere_scene(0.0, 16, 1.0, 0.0)).unwrap();
    let dp = datapath_for(&scene);
    let r = render(&scene, &dp, &|_, _| {});
    // Pixel (x = 1, y = 0): screen y = (1 - 2 * 0.5 / 3) tan(15 deg), direction (0, sy, -1)
    // normalised; hit where |o + t d| = 1.
    let sy = (1.0 - 1.0 / 3.0) * (15f64.to_radians()).tan();
    let len = (sy * sy + 1.0).sqrt();
    let d = [0.0, sy / len, -1.0 / len];
    let o = [0.0, 0.0, 5.0];
    let b = o[2] * d[2];
    let t = -b - (b * b - (25.0 - 1.0)).sqrt();
    let p = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
    let ndotl = p[2]; // N = p on the unit sphere, L = (0, 0, 1)
    let want: Vec<u16> = [0.8 * 1.0, 0.6 * 0.5, 0.4 * 0.25]
        .iter()
        .map(|&c| code(0.5 * c * ndotl))
        .collect();
    for (codes, name) in r.codes.iter().zip(PATHS) {
        assert_eq!(codes[1].to_vec(), want, "path {name}");
    }
}

#[test]
fn the_default_scene_and_the_examples_are_valid() {
    let s = Scene::default_scene();
    let ns = s.exponents();
    assert!(ns.len() >= 3 && ns[0] >= 16 && *ns.last().unwrap() <= 1024);
    for entry in std::fs::read_dir("examples/scenes").unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        Scene::from_toml(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    }
}

/// Every bad scene names the key (or line) at fault.
#[test]
fn bad_scenes_name_what_is_wrong() {
    let good = sphere_scene(0.1, 64, 1.0, 0.03);
    for (from, to, expect) in [
        ("radius = 1.0", "radius = nan", "object[0].radius"),
        ("radius = 1.0", "radius = 0.0", "object[0].radius"),
        ("radius = 1.0", "major = 1.0", "object[0].major"),
        (
            "radius = 1.0",
            "radius = 1.0\naxis = [0.0, 1.0, 0.0]",
            "object[0].axis",
        ),
        ("kind = \"sphere\"", "kind = \"cube\"", "object[0].kind"),
        (
            "material = \"m\"\ncenter",
            "material = \"x\"\ncenter",
            "object[0].material",
        ),
        ("n = 64", "n = 0", "material[0].n"),
        ("k_s = 0.1", "k_s = -0.1", "material[0].k_s"),
        ("colour = [0.8, 0.6, 0.4]", "colour = [0.8, 0.6]", "line"),
        (
            "colour = [0.8, 0.6, 0.4]",
            "colour = [0.8, 0.6, 1.5]",
            "material[0].colour",
        ),
        ("width = 3", "width = 0", "image.width"),
        ("width = 3", "width = 3\nbits = 12", "image.bits"),
        ("fov_deg = 30.0", "fov_deg = 180.0", "camera.fov_deg"),
        (
            "look_at = [0.0, 0.0, 0.0]",
            "look_at = [0.0, 0.0, 5.0]",
            "camera.look_at",
        ),
        (
            "direction = [0.0, 0.0, 1.0]",
            "direction = [0.0, 0.0, 0.0]",
            "light[0].direction",
        ),
        (
            "kind = \"directional\"",
            "kind = \"point\"",
            "light[0].position",
        ),
        ("intensity = 1", "intensity = inf", "light[0].intensity"),
        ("[shading]", "[shading]\nglow = 1", "line"),
    ] {
        assert!(good.contains(from), "{from}");
        let bad = good.replacen(from, to, 1);
        let err = Scene::from_toml(&bad).unwrap_err().to_string();
        assert!(err.contains(expect), "{to}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}

#[test]
fn render_writes_the_images_and_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(
        &scene,
        sphere_scene(0.05, 300, 1.0, 0.03)
            .replace("width = 3\nheight = 3", "width = 40\nheight = 30"),
    )
    .unwrap();
    let out = dir.path().join("out");
    let o = common::specfx(&[
        "render",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v[0]["material"], "m");
    assert_eq!(v[0]["n"], 300);
    assert!(v[0]["total"]["pixels"].as_u64().unwrap() > 100);
    for f in [
        "f64_cos_n.png",
        "f64_model.png",
        "datapath.png",
        "diff_vs_cos_n.png",
        "diff_vs_f64_model.png",
        "render.md",
        "render.json",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    // A bad scene: one line, exit 2, nothing written.
    std::fs::write(&scene, "[image]\nwidth = 1\n").unwrap();
    let out2 = dir.path().join("out2");
    let o = common::specfx(&[
        "render",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        out2.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(String::from_utf8_lossy(&o.stderr).lines().count(), 1);
    assert!(!out2.exists());
}
