//! Scenes and rendering: the scene parser's errors, pixels checked against closed forms, and
//! `specfx render` through the binary.

use crate::common;

use specfx::pipeline::{Config, Datapath};
use specfx::scene::render::{render, PATHS};
use specfx::scene::Scene;

fn code(x: f64) -> u16 {
    common::srgb8(x)
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
    let scene = Scene::from_toml(&common::sphere_scene(k_s, n, intensity, ambient)).unwrap();
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
    let scene = Scene::from_toml(&common::sphere_scene(0.0, 16, 1.0, 0.0)).unwrap();
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
    // The inputs the scene fed the datapath: the five covered pixels, one light each. The
    // centre's Phong cosine is 1; the four edge pixels' is R.V with R = 2 (N.L) N - L, N = p,
    // clamped to [0, 1] (near the rim R turns away from the eye) and rounded to u1.15.
    let n_dot_l = p[2];
    let refl = [
        2.0 * n_dot_l * p[0],
        2.0 * n_dot_l * p[1],
        2.0 * n_dot_l * p[2] - 1.0,
    ];
    let c = -(refl[0] * d[0] + refl[1] * d[1] + refl[2] * d[2]);
    assert_eq!(r.inputs.len(), 1);
    let e = &r.inputs[0];
    assert_eq!((e.n, e.count), (16, 5));
    assert_eq!(e.code_max, 32768);
    let edge = (c.clamp(0.0, 1.0) * 32768.0).round() as i64;
    assert_eq!(e.code_min, edge);
    let mut want = vec![0u64; 64];
    want[63] += 1;
    // Bin floor(64 c), c = edge / 2^15.
    want[((edge as f64 / 32768.0) * 64.0).floor().min(63.0) as usize] += 4;
    assert_eq!(e.histogram, want);
}

/// FLIP of an image against itself is 0 everywhere; against a different one it is not.
#[test]
fn flip_is_zero_exactly_where_the_images_agree() {
    use specfx::scene::render::{flip_errors, image_error};
    let scene = Scene::from_toml(
        &common::sphere_scene(0.02, 500, 1.0, 0.03)
            .replace("width = 3\nheight = 3", "width = 64\nheight = 48"),
    )
    .unwrap();
    let mut r = render(&scene, &datapath_for(&scene), &|_, _| {});
    assert!(flip_errors(&r, 2, 2).iter().all(|&f| f == 0.0));
    // Darken one channel of a block of covered pixels in path 2.
    for y in 20..28 {
        for x in 28..36 {
            r.codes[2][y * 64 + x][0] /= 2;
        }
    }
    let flip = flip_errors(&r, 2, 0);
    assert!(flip[24 * 64 + 32] > 0.05);
    let e = image_error(&r, 2, 0, None, &flip);
    assert!(e.flip_mean > 0.0 && e.max_lsb > 10);
}

#[test]
fn the_default_scene_and_the_examples_are_valid() {
    let s = Scene::default_scene();
    let ns = s.exponents();
    assert!(ns.len() >= 3 && ns[0] >= 16 && *ns.last().unwrap() <= 1024);
    for entry in std::fs::read_dir("examples/scenes").unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let load = |f: &str| std::fs::read(std::path::Path::new("examples/scenes").join(f));
        Scene::from_toml_with(&text, &load).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    }
}

/// Every bad scene names the key (or line) at fault.
#[test]
fn bad_scenes_name_what_is_wrong() {
    let good = common::sphere_scene(0.1, 64, 1.0, 0.03);
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
        // Material names end up in budgets and file headers: the configuration-name rule.
        (
            "name = \"m\"",
            "name = \"m\\nmax_lsb = 1\"",
            "material[0].name: expected 1..=64 ASCII letters",
        ),
        ("name = \"m\"", "name = \"a]b\"", "material[0].name"),
    ] {
        assert!(good.contains(from), "{from}");
        let bad = good.replacen(from, to, 1);
        let err = Scene::from_toml(&bad).unwrap_err().to_string();
        assert!(err.contains(expect), "{to}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}

/// The limits on lights and on pixels x lights hold at their edges: 256 lights pass and 257
/// do not; 8192 x 8192 pixels pass with one light and not with two.
#[test]
fn lights_are_limited_before_any_work() {
    let good = common::sphere_scene(0.1, 64, 1.0, 0.03);
    let light = "[[light]]\nkind = \"directional\"\ndirection = [0.0, 0.0, 1.0]\n";
    let with = |lights: usize, size: u32| {
        let size = format!("width = {size}\nheight = {size}");
        format!(
            "{}{}",
            good.replacen("width = 3\nheight = 3", &size, 1),
            light.repeat(lights - 1)
        )
    };
    assert!(Scene::from_toml(&with(256, 3)).is_ok());
    let err = Scene::from_toml(&with(257, 3)).unwrap_err().to_string();
    assert!(
        err.contains("light: expected 1 to 256 [[light]] tables, got 257"),
        "{err}"
    );
    assert!(Scene::from_toml(&with(1, 8192)).is_ok());
    let err = Scene::from_toml(&with(2, 8192)).unwrap_err().to_string();
    assert!(
        err.contains("is 134217728, above the limit of 67108864"),
        "{err}"
    );
}

/// A scene without `[shading]` gets what an empty `[shading]` gets, as documented: ambient
/// 0.03 and Blinn-Phong.
#[test]
fn a_scene_without_shading_gets_the_documented_defaults() {
    let good = common::sphere_scene(0.1, 64, 1.0, 0.5);
    let table = "[shading]\nmodel = \"phong\"\nambient = 0.5\n";
    assert!(good.contains(table));
    let without = Scene::from_toml(&good.replacen(table, "", 1)).unwrap();
    let empty = Scene::from_toml(&good.replacen(table, "[shading]\n", 1)).unwrap();
    assert_eq!(without.shading.ambient, 0.03);
    assert_eq!(without.shading, empty.shading);
    assert_eq!(without.shading.model, specfx::scene::Model::BlinnPhong);
}

/// A scene path holding line breaks and Markdown cannot add a heading or a table row to
/// `render.md`: the path is shown on its title line, escaped.
#[test]
fn the_scene_path_cannot_inject_markdown() {
    let dir = std::env::temp_dir().join(format!("specfx-render-md-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let sub = dir.join("d\n\n# INJECTED\n| a | b |\n");
    std::fs::create_dir_all(&sub).unwrap();
    let scene = sub.join("s.toml");
    std::fs::write(&scene, common::sphere_scene(0.1, 16, 1.0, 0.03)).unwrap();
    let out = dir.join("out");
    let o = common::specfx(&[
        "render",
        "-q",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(out.join("render.md")).unwrap();
    let title = md.lines().next().unwrap();
    assert!(
        title.starts_with("# ") && title.contains("INJECTED"),
        "{title}"
    );
    assert!(
        !md.lines()
            .skip(1)
            .any(|l| l.contains("INJECTED") || l.starts_with("| a |")),
        "{md}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn render_writes_the_images_and_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(
        &scene,
        common::sphere_scene(0.05, 300, 1.0, 0.03)
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
    let flip = v[0]["total"]["flip_mean"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&flip));
    for f in [
        "f64_cos_n.png",
        "f64_model.png",
        "datapath.png",
        "diff_vs_cos_n.png",
        "diff_vs_f64_model.png",
        "flip_vs_cos_n.png",
        "flip_vs_f64_model.png",
        "render.md",
        "render.json",
        "inputs.csv",
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

mod meshes {
    use proptest::prelude::*;
    use specfx::scene::mesh::{Mesh, MeshFormat};

    fn obj(text: &str) -> Result<Mesh, String> {
        Mesh::parse(text.as_bytes(), MeshFormat::Obj, 1.0, [0.0; 3], "m.obj")
            .map_err(|e| e.to_string())
    }

    /// A binary STL of the given triangles, written from the format's definition (80-byte
    /// header, u32 count, per triangle a normal, three vertices and a u16).
    fn stl(tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut b = vec![b' '; 80];
        b.extend((tris.len() as u32).to_le_bytes());
        for t in tris {
            b.extend([0u8; 12]);
            for v in t {
                for x in v {
                    b.extend(x.to_le_bytes());
                }
            }
            b.extend([0u8; 2]);
        }
        b
    }

    #[test]
    fn bad_meshes_get_clear_errors() {
        let nan = obj("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n").unwrap_err();
        assert!(
            nan.contains("line 2: expected `v x y z` (three numbers within the 32-bit float range"),
            "{nan}"
        );
        let range = obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap_err();
        assert!(range.contains("m.obj"), "{range}");
        let none = obj("v 0 0 0\nv 1 0 0\n").unwrap_err();
        assert!(none.contains("no triangles"), "{none}");
        let good = stl(&[[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; 3]);
        assert_eq!(
            Mesh::parse(&good, MeshFormat::Stl, 1.0, [0.0; 3], "m.stl")
                .unwrap()
                .triangles
                .len(),
            3
        );
        let truncated = Mesh::parse(
            &good[..good.len() - 20],
            MeshFormat::Stl,
            1.0,
            [0.0; 3],
            "m.stl",
        )
        .unwrap_err()
        .to_string();
        assert!(truncated.contains("m.stl"), "{truncated}");
        let nan_stl = stl(&[[[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]]]);
        let e = Mesh::parse(&nan_stl, MeshFormat::Stl, 1.0, [0.0; 3], "m.stl").unwrap_err();
        assert!(e.to_string().contains("not finite"), "{e}");
        let empty = stl(&[]);
        let e = Mesh::parse(&empty, MeshFormat::Stl, 1.0, [0.0; 3], "m.stl").unwrap_err();
        assert!(e.to_string().contains("no triangles"), "{e}");
    }

    /// The distance to a triangle along a ray, by the plane equation and barycentric
    /// coordinates (an oracle independent of Moller-Trumbore).
    fn brute(tris: &[[[f64; 3]; 3]], o: [f64; 3], d: [f64; 3]) -> Option<f64> {
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let mut best: Option<f64> = None;
        for t in tris {
            let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
            let denom = dot(n, d);
            if denom.abs() < 1e-12 {
                continue;
            }
            let s = dot(n, sub(t[0], o)) / denom;
            if s <= 1e-9 {
                continue;
            }
            let p = [o[0] + s * d[0], o[1] + s * d[1], o[2] + s * d[2]];
            let inside =
                (0..3).all(|k| dot(cross(sub(t[(k + 1) % 3], t[k]), sub(p, t[k])), n) >= 0.0);
            if inside && best.is_none_or(|b| s < b) {
                best = Some(s);
            }
        }
        best
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// The hierarchy finds the nearest triangle a brute-force scan finds.
        #[test]
        fn the_bvh_hits_what_brute_force_hits(
            tris in prop::collection::vec(prop::array::uniform3(prop::array::uniform3(-2.0f64..2.0)), 1..200),
            o in prop::array::uniform3(-1.0f64..1.0),
            dir in prop::array::uniform3(-1.0f64..1.0),
        ) {
            let len = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
            prop_assume!(len > 0.1);
            let d = dir.map(|x| x / len);
            let o = [o[0], o[1], o[2] - 4.0];
            let mesh = Mesh::new(tris.clone());
            let got = mesh.hit(o, d).map(|h| h.0);
            let want = brute(&tris, o, d);
            match (got, want) {
                (Some(g), Some(w)) => prop_assert!((g - w).abs() <= 1e-7 * w.max(1.0), "{} vs {}", g, w),
                // A ray through an edge may be counted by one test and not the other.
                (g, w) => prop_assert_eq!(g.is_some(), w.is_some()),
            }
        }
    }
}

/// A square of two triangles facing the camera, lit head on: its pixels are the Lambert term
/// in closed form, and the scene reads the mesh through the loader the command gives it.
#[test]
fn a_mesh_facing_the_camera_is_lambert() {
    let text = common::sphere_scene(0.0, 16, 1.0, 0.0).replace(
        "kind = \"sphere\"\nmaterial = \"m\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0",
        "kind = \"mesh\"\nmaterial = \"m\"\nfile = \"sq.obj\"\nscale = 2.0",
    );
    let square = b"v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n".to_vec();
    let scene = Scene::from_toml_with(&text, &|f| {
        assert_eq!(f, "sq.obj");
        Ok(square.clone())
    })
    .unwrap();
    assert_eq!(scene.meshes[0].triangles.len(), 2);
    let r = render(&scene, &datapath_for(&scene), &|_, _| {});
    let want: Vec<u16> = [0.8, 0.3, 0.1].iter().map(|&c| code(0.5 * c)).collect();
    for px in 0..9 {
        assert_eq!(r.codes[2][px].to_vec(), want, "pixel {px}");
    }
    // Without a loader a mesh cannot be read, and the error says so.
    let e = Scene::from_toml(&text).unwrap_err().to_string();
    assert!(e.contains("object[0].file"), "{e}");
}
