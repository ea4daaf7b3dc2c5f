//! The renderer: one ray per pixel through a [`Scene`], Lambert diffuse plus a normalised
//! specular lobe evaluated three ways (f64 cos^n with its classic coefficient, the f64 model of
//! the configuration's algorithm, the bit-accurate datapath), display codes and error figures.
//!
//! Radiance is `(k_d colour + pi k_s f_s) E` summed over the lights, with `E = intensity
//! max(0, N.L)` and `f_s` the normalised lobe (so a white Lambert surface facing a light of
//! intensity 1 shows 1); shadows are not traced. Display codes are the sRGB encoding of the
//! radiance clamped to [0, 1], rounded to the image's bits.
//!
//! **Invariant:** no I/O; rows are rendered in parallel and the image is the same with any
//! number of threads.

use rayon::prelude::*;

use crate::pipeline::f64_walk::F64Walk;
use crate::pipeline::{Datapath, NConstants, OutputScratch};
use crate::reference::normalisation::{classic_coefficient, Form};
use crate::scene::{add_scaled, cross, dot, norm, normalize, sub, LightKind, Model, Scene, Shape};

/// The three specular paths, in the order of [`Rendered::codes`].
pub const PATHS: [&str; 3] = ["f64_cos_n", "f64_model", "datapath"];

/// A rendered scene: per pixel (row-major, top row first) the material hit and the display
/// codes of each path.
#[derive(Debug, Clone, PartialEq)]
pub struct Rendered {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Bits per channel.
    pub bits: u32,
    /// The material index of each pixel (`None`: background).
    pub material: Vec<Option<u16>>,
    /// `codes[path][pixel]`: RGB display codes.
    pub codes: [Vec<[u16; 3]>; 3],
    /// The datapath inputs the scene produced, per exponent (ascending n).
    pub inputs: Vec<InputsOfN>,
}

/// Bins of the input histograms, over c in [0, 1].
pub const INPUT_BINS: usize = 64;

/// The inputs `(c, n)` a scene feeds the datapath for one exponent: every shaded fragment and
/// light with N.L > 0 gives one (its cosine quantized to the input format).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct InputsOfN {
    /// The exponent.
    pub n: u32,
    /// Inputs evaluated.
    pub count: u64,
    /// The smallest and largest input code.
    pub code_min: i64,
    /// See `code_min`.
    pub code_max: i64,
    /// `histogram[i]`: inputs with c in `[i/64, (i+1)/64)` (the last bin includes 1).
    pub histogram: Vec<u64>,
}

/// Folds `(exponent, code)` pairs into per-exponent input statistics, ascending n.
fn gather_inputs(pairs: impl Iterator<Item = (u32, i64)>, one: i64) -> Vec<InputsOfN> {
    let mut by_n: std::collections::BTreeMap<u32, InputsOfN> = Default::default();
    for (n, code) in pairs {
        let e = by_n.entry(n).or_insert_with(|| InputsOfN {
            n,
            count: 0,
            code_min: i64::MAX,
            code_max: i64::MIN,
            histogram: vec![0; INPUT_BINS],
        });
        e.count += 1;
        e.code_min = e.code_min.min(code);
        e.code_max = e.code_max.max(code);
        // floor(c * 64) with c = code / one, the last bin holding c = 1 too.
        let bin = (code.clamp(0, one) as i128 * INPUT_BINS as i128 / one.max(1) as i128) as usize;
        e.histogram[bin.min(INPUT_BINS - 1)] += 1;
    }
    by_n.into_values().collect()
}

/// The background's linear radiance.
const BACKGROUND: [f64; 3] = [0.02, 0.022, 0.03];

/// A ray hit: distance, outward unit normal, object index.
struct Hit {
    t: f64,
    normal: [f64; 3],
    object: usize,
}

/// The nearest intersection of a ray (unit `dir`) with a sphere, beyond `t_min`.
fn hit_sphere(o: [f64; 3], dir: [f64; 3], center: [f64; 3], radius: f64) -> Option<f64> {
    let oc = sub(o, center);
    let b = dot(oc, dir);
    let c = dot(oc, oc) - radius * radius;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    [-b - s, -b + s].into_iter().find(|&t| t > 1e-9)
}

/// Signed distance to a shape (exact for the capsule and the torus).
fn distance(shape: &Shape, p: [f64; 3]) -> f64 {
    match *shape {
        Shape::Sphere { center, radius } => norm(sub(p, center)) - radius,
        Shape::Capsule { a, b, radius } => norm(sub(p, closest_on_segment(p, a, b))) - radius,
        Shape::Torus {
            center,
            axis,
            major,
            minor,
        } => {
            let (h, radial) = torus_coords(p, center, axis);
            ((radial - major).powi(2) + h * h).sqrt() - minor
        }
        Shape::Mesh { .. } => unreachable!("meshes are ray cast, not traced"),
    }
}

fn closest_on_segment(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    let s = if len2 == 0.0 {
        0.0
    } else {
        (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0)
    };
    add_scaled(a, s, ab)
}

/// Height along the axis and distance from it.
fn torus_coords(p: [f64; 3], center: [f64; 3], axis: [f64; 3]) -> (f64, f64) {
    let q = sub(p, center);
    let a = normalize(axis);
    let h = dot(q, a);
    let radial = add_scaled(q, -h, a);
    (h, norm(radial))
}

/// The outward unit normal of a shape at a point on its surface.
fn normal(shape: &Shape, p: [f64; 3]) -> [f64; 3] {
    match *shape {
        Shape::Sphere { center, .. } => normalize(sub(p, center)),
        Shape::Capsule { a, b, .. } => normalize(sub(p, closest_on_segment(p, a, b))),
        Shape::Torus {
            center,
            axis,
            major,
            ..
        } => {
            let q = sub(p, center);
            let a = normalize(axis);
            let radial = add_scaled(q, -dot(q, a), a);
            let ring = add_scaled(center, major / norm(radial).max(1e-300), radial);
            normalize(sub(p, ring))
        }
        Shape::Mesh { .. } => unreachable!("a mesh hit carries its face normal"),
    }
}

/// A sphere enclosing a shape.
fn bound(shape: &Shape) -> ([f64; 3], f64) {
    match *shape {
        Shape::Sphere { center, radius } => (center, radius),
        Shape::Capsule { a, b, radius } => {
            let mid = add_scaled(a, 0.5, sub(b, a));
            (mid, 0.5 * norm(sub(b, a)) + radius)
        }
        Shape::Torus {
            center,
            major,
            minor,
            ..
        } => (center, major + minor),
        Shape::Mesh { .. } => unreachable!("a mesh has its own hierarchy"),
    }
}

/// The nearest hit of a ray with one shape: analytic for the sphere, sphere tracing (on the
/// exact distance) inside the bounding sphere for the others.
fn hit_shape(shape: &Shape, o: [f64; 3], dir: [f64; 3]) -> Option<f64> {
    if let Shape::Sphere { center, radius } = *shape {
        return hit_sphere(o, dir, center, radius);
    }
    let (c, r) = bound(shape);
    let oc = sub(o, c);
    let b = dot(oc, dir);
    let disc = b * b - (dot(oc, oc) - r * r);
    if disc < 0.0 {
        return None;
    }
    let (t0, t1) = (-b - disc.sqrt(), -b + disc.sqrt());
    let mut t = t0.max(0.0);
    let eps = 1e-7 * r;
    for _ in 0..512 {
        if t > t1 {
            return None;
        }
        let d = distance(shape, add_scaled(o, t, dir));
        if d < eps {
            return Some(t);
        }
        t += d;
    }
    None
}

fn nearest(scene: &Scene, o: [f64; 3], dir: [f64; 3]) -> Option<Hit> {
    let mut best: Option<(f64, usize, Option<[f64; 3]>)> = None;
    for (i, obj) in scene.objects.iter().enumerate() {
        let hit = match obj.shape {
            Shape::Mesh { mesh } => scene.meshes[mesh].hit(o, dir).map(|(t, n)| (t, Some(n))),
            ref shape => hit_shape(shape, o, dir).map(|t| (t, None)),
        };
        if let Some((t, n)) = hit {
            if best.is_none_or(|(bt, _, _)| t < bt) {
                best = Some((t, i, n));
            }
        }
    }
    best.map(|(t, object, n)| Hit {
        t,
        normal: n.unwrap_or_else(|| normal(&scene.objects[object].shape, add_scaled(o, t, dir))),
        object,
    })
}

/// A path's specular lobe `f_s(material, c)` for a cosine `c` in [0, 1].
pub type Lobe<'a> = dyn Fn(usize, f64) -> f64 + Sync + 'a;

/// The input code the datapath receives for a cosine `c` in [0, 1]: rounded to the nearest
/// code of the input format, clamped to its codes.
pub fn input_code(dp: &Datapath, c: f64) -> i64 {
    let codes = dp.input_codes();
    ((c / dp.config().c.format.lsb()).round() as i64).clamp(*codes.start(), *codes.end())
}

/// The datapath's lobe as a table: per material, the output (as a value) of every input code.
pub struct DatapathLobe<'a> {
    dp: &'a Datapath,
    /// `table[material][code - first code]`.
    table: Vec<Vec<f64>>,
}

impl<'a> DatapathLobe<'a> {
    /// Evaluates the datapath on every input code of every material's exponent.
    ///
    /// # Panics
    /// If the datapath lacks a material's exponent.
    pub fn new(dp: &'a Datapath, scene: &Scene) -> DatapathLobe<'a> {
        let codes = dp.input_codes();
        let out = dp.config().out.format;
        let mut by_n: std::collections::BTreeMap<u32, Vec<f64>> = Default::default();
        let table = scene
            .materials
            .iter()
            .map(|m| {
                by_n.entry(m.n)
                    .or_insert_with(|| {
                        let nc = dp
                            .constants_for(m.n)
                            .expect("the datapath holds every material's exponent");
                        let mut raw = vec![0; (codes.end() - codes.start() + 1) as usize];
                        dp.eval_outputs_range(
                            nc,
                            *codes.start()..*codes.end() + 1,
                            &mut raw,
                            &mut OutputScratch::default(),
                        );
                        raw.into_iter().map(|r| out.to_f64(r)).collect()
                    })
                    .clone()
            })
            .collect();
        DatapathLobe { dp, table }
    }

    /// The lobe of material `m` at cosine `c`.
    pub fn eval(&self, m: usize, c: f64) -> f64 {
        let first = *self.dp.input_codes().start();
        self.table[m][(input_code(self.dp, c) - first) as usize]
    }
}

/// The f64 model of a datapath's algorithm and coefficient, per material (the datapath's
/// lobe without quantization).
pub struct ModelLobe<'a> {
    dp: &'a Datapath,
    /// Per material: its exponent's constants.
    per_material: Vec<&'a NConstants>,
}

impl<'a> ModelLobe<'a> {
    /// The model of `dp` for the scene's materials.
    ///
    /// # Panics
    /// If the datapath lacks a material's exponent.
    pub fn new(dp: &'a Datapath, scene: &Scene) -> ModelLobe<'a> {
        ModelLobe {
            dp,
            per_material: scene
                .materials
                .iter()
                .map(|m| {
                    dp.constants_for(m.n)
                        .expect("the datapath holds every material's exponent")
                })
                .collect(),
        }
    }

    /// The lobe of material `m` at cosine `c`.
    pub fn eval(&self, m: usize, c: f64) -> f64 {
        let nc = self.per_material[m];
        let one = self.dp.one_code() as f64;
        let below = nc.threshold.is_some_and(|thr| c * one < thr as f64);
        F64Walk::new(self.dp, nc, c, below, 0).run().1
    }
}

/// The f64 cos^n lobe of a scene's materials, with the classic coefficient of `form`.
pub fn cos_n_lobe(scene: &Scene, form: Form) -> impl Fn(usize, f64) -> f64 + Sync + use<> {
    let per_material: Vec<(f64, f64)> = scene
        .materials
        .iter()
        .map(|m| {
            let n = f64::from(m.n);
            (n, classic_coefficient(form, n))
        })
        .collect();
    move |m, c| per_material[m].1 * c.powf(per_material[m].0)
}

/// sRGB encoding of a linear value in [0, 1].
fn srgb(x: f64) -> f64 {
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// The display code of a linear radiance channel.
pub fn display_code(x: f64, bits: u32) -> u16 {
    let max = f64::from((1u32 << bits) - 1);
    (srgb(x.clamp(0.0, 1.0)) * max).round() as u16
}

/// One light's specular term in a pixel: the material's lobe at cosine `c`, times `weight`
/// (`pi k_s intensity colour N.L`, per channel).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Term {
    /// The material index.
    pub material: u16,
    /// The lobe's cosine (N.H or R.V), clamped to [0, 1].
    pub c: f64,
    /// What the lobe is multiplied by, per channel.
    pub weight: [f64; 3],
}

/// A traced scene: everything about each pixel but its specular lobes, so any path (any
/// datapath) is shaded from it without tracing again.
#[derive(Debug, Clone, PartialEq)]
pub struct Fragments {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Bits per channel.
    pub bits: u32,
    /// The material index of each pixel (`None`: background).
    pub material: Vec<Option<u16>>,
    /// Linear radiance without the specular terms (ambient and diffuse; the background).
    pub base: Vec<[f64; 3]>,
    /// `terms[start[p]..start[p + 1]]` are pixel p's specular terms, in light order.
    pub start: Vec<u32>,
    /// Every specular term.
    pub terms: Vec<Term>,
}

impl Fragments {
    /// The specular terms of pixel `p`.
    pub fn terms_of(&self, p: usize) -> &[Term] {
        &self.terms[self.start[p] as usize..self.start[p + 1] as usize]
    }

    /// The display codes of one path: each pixel's base radiance plus its terms' lobes.
    pub fn shade(&self, lobe: &Lobe<'_>) -> Vec<[u16; 3]> {
        let enc = Encoder::of(self.bits);
        (0..self.base.len())
            .into_par_iter()
            .map(|p| {
                let mut rad = self.base[p];
                for t in self.terms_of(p) {
                    let f_s = lobe(usize::from(t.material), t.c);
                    for (r, w) in rad.iter_mut().zip(t.weight) {
                        *r += f_s * w;
                    }
                }
                rad.map(|x| enc.encode(x))
            })
            .collect()
    }

    /// The datapath inputs `(n, code)` the terms produce, per exponent.
    pub fn inputs(&self, scene: &Scene, dp: &Datapath) -> Vec<InputsOfN> {
        gather_inputs(
            self.terms.iter().map(|t| {
                (
                    scene.materials[usize::from(t.material)].n,
                    input_code(dp, t.c),
                )
            }),
            dp.one_code(),
        )
    }
}

/// [`display_code`] by table: the smallest linear value of each code above 0, found once per
/// bit depth by bisection over the ordered f64s, so encoding is a binary search instead of a
/// `powf` (equal to [`display_code`] for every f64, tested).
pub struct Encoder {
    /// `thresholds[j]`: the smallest x with `display_code(x) >= j + 1`.
    thresholds: Vec<f64>,
}

impl Encoder {
    /// The encoder of a bit depth (8 or 10), built once and shared.
    pub fn of(bits: u32) -> &'static Encoder {
        static E8: std::sync::OnceLock<Encoder> = std::sync::OnceLock::new();
        static E10: std::sync::OnceLock<Encoder> = std::sync::OnceLock::new();
        let cell = match bits {
            8 => &E8,
            10 => &E10,
            _ => panic!("display bits are 8 or 10"),
        };
        cell.get_or_init(|| Encoder::new(bits))
    }

    fn new(bits: u32) -> Encoder {
        let max = (1u32 << bits) - 1;
        let thresholds = (1..=max)
            .map(|j| {
                // Non-negative f64s are ordered like their bit patterns: bisect on those.
                let (mut lo, mut hi) = (0u64, 1.0f64.to_bits());
                while hi - lo > 1 {
                    let mid = lo + (hi - lo) / 2;
                    if u32::from(display_code(f64::from_bits(mid), bits)) >= j {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                f64::from_bits(hi)
            })
            .collect();
        Encoder { thresholds }
    }

    /// The display code of a linear value.
    pub fn encode(&self, x: f64) -> u16 {
        self.thresholds.partition_point(|&t| t <= x) as u16
    }
}

/// Traces one primary ray per pixel; `progress(rows done, rows)` is called as rows finish.
pub fn trace(scene: &Scene, progress: &(dyn Fn(usize, usize) + Sync)) -> Fragments {
    let (w, h) = (scene.image.width as usize, scene.image.height as usize);
    let cam = &scene.camera;
    let forward = normalize(sub(cam.look_at, cam.position));
    let right = normalize(cross(forward, cam.up));
    let up = cross(right, forward);
    let half = (cam.fov_deg.to_radians() / 2.0).tan();
    let aspect = w as f64 / h as f64;
    let material_of: Vec<usize> = scene
        .objects
        .iter()
        .map(|o| scene.material_index(&o.material).expect("validated"))
        .collect();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let rows: Vec<Vec<Fragment>> = (0..h)
        .into_par_iter()
        .map(|y| {
            let row = (0..w)
                .map(|x| {
                    let sx = (2.0 * (x as f64 + 0.5) / w as f64 - 1.0) * half * aspect;
                    let sy = (1.0 - 2.0 * (y as f64 + 0.5) / h as f64) * half;
                    let dir = normalize(add_scaled(add_scaled(forward, sx, right), sy, up));
                    fragment(scene, &material_of, cam.position, dir)
                })
                .collect();
            let now = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress(now, h);
            row
        })
        .collect();
    let mut f = Fragments {
        width: scene.image.width,
        height: scene.image.height,
        bits: scene.image.bits,
        material: Vec::with_capacity(w * h),
        base: Vec::with_capacity(w * h),
        start: Vec::with_capacity(w * h + 1),
        terms: Vec::new(),
    };
    for (m, base, terms) in rows.into_iter().flatten() {
        f.start.push(f.terms.len() as u32);
        f.material.push(m);
        f.base.push(base);
        f.terms.extend(terms);
    }
    f.start.push(f.terms.len() as u32);
    f
}

/// Renders a scene through a datapath whose n set holds every material's exponent (the
/// caller builds it so); `progress(rows done, rows)` is called as rows finish.
///
/// # Panics
/// If the datapath lacks a material's exponent.
pub fn render(scene: &Scene, dp: &Datapath, progress: &(dyn Fn(usize, usize) + Sync)) -> Rendered {
    let frags = trace(scene, progress);
    render_fragments(scene, &frags, dp)
}

/// Shades traced fragments with the three paths.
///
/// # Panics
/// If the datapath lacks a material's exponent.
pub fn render_fragments(scene: &Scene, frags: &Fragments, dp: &Datapath) -> Rendered {
    let cos_n = cos_n_lobe(scene, dp.config().coef.form);
    let model = ModelLobe::new(dp, scene);
    let table = DatapathLobe::new(dp, scene);
    Rendered {
        width: frags.width,
        height: frags.height,
        bits: frags.bits,
        material: frags.material.clone(),
        codes: [
            frags.shade(&cos_n),
            frags.shade(&|m, c| model.eval(m, c)),
            frags.shade(&|m, c| table.eval(m, c)),
        ],
        inputs: frags.inputs(scene, dp),
    }
}

/// One pixel's material (`None`: background), base radiance and specular terms.
type Fragment = (Option<u16>, [f64; 3], Vec<Term>);

/// One primary ray: the material hit, the base radiance and the specular terms.
fn fragment(scene: &Scene, material_of: &[usize], eye: [f64; 3], dir: [f64; 3]) -> Fragment {
    let Some(hit) = nearest(scene, eye, dir) else {
        return (None, BACKGROUND, Vec::new());
    };
    let mi = material_of[hit.object];
    let mat = &scene.materials[mi];
    let p = add_scaled(eye, hit.t, dir);
    let v = [-dir[0], -dir[1], -dir[2]];
    let mut n = hit.normal;
    if dot(n, v) < 0.0 {
        n = n.map(|x| -x);
    }
    let amb = scene.shading.ambient;
    let mut base = mat.colour.map(|c| amb * c);
    let mut terms = Vec::with_capacity(scene.lights.len());
    for light in &scene.lights {
        let l = match light.kind {
            LightKind::Directional => normalize(light.direction.expect("validated")),
            LightKind::Point => normalize(sub(light.position.expect("validated"), p)),
        };
        let ndotl = dot(n, l);
        if ndotl <= 0.0 {
            continue;
        }
        let c = match scene.shading.model {
            Model::BlinnPhong => dot(n, normalize([l[0] + v[0], l[1] + v[1], l[2] + v[2]])),
            Model::Phong => {
                let r = add_scaled(l.map(|x| -x), 2.0 * ndotl, n);
                dot(r, v)
            }
        }
        .clamp(0.0, 1.0);
        let mut weight = [0.0; 3];
        for ch in 0..3 {
            let e = light.intensity * light.colour[ch] * ndotl;
            base[ch] += mat.k_d * mat.colour[ch] * e;
            weight[ch] = std::f64::consts::PI * mat.k_s * e;
        }
        terms.push(Term {
            material: mi as u16,
            c,
            weight,
        });
    }
    (Some(mi as u16), base, terms)
}

/// NVIDIA's FLIP (LDR) of path `test` against path `reference`, per pixel in [0, 1], at the
/// default 67 pixels per degree (a 0.7 m viewing distance from a 24-inch 4K screen). FLIP
/// reads 8-bit sRGB: 10-bit codes are rounded to 8 bits first.
pub fn flip_errors(r: &Rendered, test: usize, reference: usize) -> Vec<f32> {
    flip_of(
        (r.width, r.height, r.bits),
        &r.codes[test],
        &r.codes[reference],
    )
}

/// [`flip_errors`] of two images of `(width, height, bits)`.
pub fn flip_of(size: (u32, u32, u32), test: &[[u16; 3]], reference: &[[u16; 3]]) -> Vec<f32> {
    let (width, height, bits) = size;
    let image = |codes: &[[u16; 3]]| {
        let max = u32::from((1u16 << bits) - 1);
        let bytes: Vec<u8> = codes
            .iter()
            .flat_map(|c| c.map(|x| ((u32::from(x) * 255 + max / 2) / max) as u8))
            .collect();
        nv_flip::FlipImageRgb8::with_data(width, height, &bytes)
    };
    nv_flip::flip(
        image(reference),
        image(test),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    )
    .to_vec()
}

/// The error figures of one material (or of the whole image): the datapath's display codes
/// against a reference path's.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ImageError {
    /// Pixels covered.
    pub pixels: u64,
    /// Largest difference of any channel, in display LSBs.
    pub max_lsb: u32,
    /// Mean over pixels of the largest channel difference, in display LSBs.
    pub mean_lsb: f64,
    /// Share of pixels with any channel different.
    pub differing: f64,
    /// Mean FLIP error over the pixels (0: identical to the eye, 1: as different as can be).
    pub flip_mean: f64,
}

/// The largest channel difference of each pixel between two paths, in display LSBs.
pub fn difference(r: &Rendered, a: usize, b: usize) -> Vec<u32> {
    difference_of(&r.codes[a], &r.codes[b])
}

/// The largest channel difference of each pixel between two images, in display LSBs.
pub fn difference_of(a: &[[u16; 3]], b: &[[u16; 3]]) -> Vec<u32> {
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            (0..3)
                .map(|ch| u32::from(x[ch].abs_diff(y[ch])))
                .max()
                .unwrap_or(0)
        })
        .collect()
}

/// Error figures of path `a` against path `b` over the pixels of material `m` (`None`: every
/// covered pixel), with `flip` the per-pixel FLIP of `a` against `b` ([`flip_errors`]).
pub fn image_error(r: &Rendered, a: usize, b: usize, m: Option<u16>, flip: &[f32]) -> ImageError {
    image_error_of(&r.material, &difference(r, a, b), m, flip)
}

/// Error figures over the pixels of material `m` (`None`: every covered pixel) from each
/// pixel's material, its difference in display LSBs ([`difference_of`]) and its FLIP (empty:
/// not computed, the mean is 0).
pub fn image_error_of(
    material: &[Option<u16>],
    diff: &[u32],
    m: Option<u16>,
    flip: &[f32],
) -> ImageError {
    let mut e = ImageError {
        pixels: 0,
        max_lsb: 0,
        mean_lsb: 0.0,
        differing: 0.0,
        flip_mean: 0.0,
    };
    let mut sum = 0u64;
    let mut differing = 0u64;
    let mut flip_sum = 0.0f64;
    for (i, (d, mat)) in diff.iter().zip(material).enumerate() {
        let covered = match m {
            Some(m) => *mat == Some(m),
            None => mat.is_some(),
        };
        if covered {
            e.pixels += 1;
            e.max_lsb = e.max_lsb.max(*d);
            sum += u64::from(*d);
            differing += u64::from(*d > 0);
            flip_sum += flip.get(i).map_or(0.0, |&f| f64::from(f));
        }
    }
    if e.pixels > 0 {
        e.mean_lsb = sum as f64 / e.pixels as f64;
        e.differing = differing as f64 / e.pixels as f64;
        e.flip_mean = flip_sum / e.pixels as f64;
    }
    e
}
/// What determines a render, for its provenance: the scene and the datapath.
pub fn inputs(scene: &Scene, dp: &Datapath) -> crate::provenance::Inputs {
    crate::provenance::Inputs::new("render")
        .table("scene", scene.canonical())
        .config(dp.config())
}
