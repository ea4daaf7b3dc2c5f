//! Scenes: the TOML description of what `specfx render` draws (image, camera, lights,
//! materials, objects), its validation, and the built-in biomedical-style default scene.
//!
//! Vectors are `[x, y, z]` arrays; colours are linear RGB in `[0, 1]`. A directional light's
//! `direction` points from the surface towards the light. Every value is checked when the scene
//! is read, with an error naming its key (`object[2].radius`), so rendering cannot fail.

pub mod fit;
pub mod fitting;
pub mod mesh;
pub mod render;

use serde::{Deserialize, Serialize};

use crate::error::Error;

/// The most lights a scene may have.
pub const MAX_LIGHTS: usize = 256;

/// The most pixels x lights a scene may have (2^26: an 8192 x 8192 image with one light, or
/// 1024 x 1024 with 64); each lit pixel keeps a specular term per light until it is shaded.
pub const MAX_PIXEL_LIGHTS: u64 = 1 << 26;

/// A validated scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The image to render.
    pub image: Image,
    /// The pinhole camera.
    pub camera: Camera,
    /// Which cosine the specular lobe takes.
    pub shading: Shading,
    /// The lights (at least one).
    pub lights: Vec<Light>,
    /// The materials (at least one), referred to by name.
    pub materials: Vec<Material>,
    /// The objects (at least one).
    pub objects: Vec<Object>,
    /// The meshes that `Shape::Mesh` objects refer to.
    pub meshes: Vec<mesh::Mesh>,
}

/// A scene file as written: objects keep every key any shape may have, so that a missing or
/// misplaced key gets an error naming the object.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    image: Image,
    camera: Camera,
    #[serde(default)]
    shading: Shading,
    #[serde(rename = "light", default)]
    lights: Vec<Light>,
    #[serde(rename = "material", default)]
    materials: Vec<Material>,
    #[serde(rename = "object", default)]
    objects: Vec<ObjectFile>,
}

/// An `[[object]]` table as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectFile {
    kind: String,
    material: String,
    center: Option<[f64; 3]>,
    radius: Option<f64>,
    a: Option<[f64; 3]>,
    b: Option<[f64; 3]>,
    axis: Option<[f64; 3]>,
    major: Option<f64>,
    minor: Option<f64>,
    file: Option<String>,
    scale: Option<f64>,
    translate: Option<[f64; 3]>,
}

impl ObjectFile {
    /// The object, or an error naming `object[i].<key>`; a mesh is read with `load` and
    /// pushed onto `meshes`.
    fn build(
        &self,
        i: usize,
        load: Loader<'_>,
        meshes: &mut Vec<mesh::Mesh>,
    ) -> Result<Object, Error> {
        let key = |k: &str| format!("object[{i}].{k}");
        let present: Vec<&str> = [
            ("center", self.center.is_some()),
            ("radius", self.radius.is_some()),
            ("a", self.a.is_some()),
            ("b", self.b.is_some()),
            ("axis", self.axis.is_some()),
            ("major", self.major.is_some()),
            ("minor", self.minor.is_some()),
            ("file", self.file.is_some()),
            ("scale", self.scale.is_some()),
            ("translate", self.translate.is_some()),
        ]
        .into_iter()
        .filter_map(|(k, p)| p.then_some(k))
        .collect();
        let wants: &[&str] = match self.kind.as_str() {
            "sphere" => &["center", "radius"],
            "capsule" => &["a", "b", "radius"],
            "torus" => &["center", "axis", "major", "minor"],
            "mesh" => &["file", "scale", "translate"],
            other => {
                return Err(Error::Config {
                    key: key("kind"),
                    problem: format!(
                        "expected sphere, capsule, torus or mesh, got '{}'",
                        other.escape_debug()
                    ),
                });
            }
        };
        if let Some(extra) = present.iter().find(|k| !wants.contains(k)) {
            return Err(Error::Config {
                key: key(extra),
                problem: format!(
                    "a {} has no {extra} (it takes {})",
                    self.kind,
                    wants.join(", ")
                ),
            });
        }
        // A mesh's scale and translation are optional.
        let optional = ["scale", "translate"];
        if let Some(missing) = wants
            .iter()
            .find(|k| !present.contains(k) && !optional.contains(k))
        {
            return Err(Error::Config {
                key: key(missing),
                problem: format!("a {} needs {}", self.kind, wants.join(", ")),
            });
        }
        let shape = match self.kind.as_str() {
            "sphere" => Shape::Sphere {
                center: self.center.expect("checked"),
                radius: self.radius.expect("checked"),
            },
            "capsule" => Shape::Capsule {
                a: self.a.expect("checked"),
                b: self.b.expect("checked"),
                radius: self.radius.expect("checked"),
            },
            "mesh" => {
                let file = self.file.as_deref().expect("checked");
                let scale = self.scale.unwrap_or(1.0);
                positive(&key("scale"), scale)?;
                let translate = self.translate.unwrap_or([0.0; 3]);
                vector(&key("translate"), translate, false)?;
                let format = mesh::MeshFormat::of(file).ok_or_else(|| Error::Config {
                    key: key("file"),
                    problem: format!(
                        "expected a .obj or .stl file, got '{}'",
                        file.escape_debug()
                    ),
                })?;
                let bytes = load(file).map_err(|e| Error::Config {
                    key: key("file"),
                    problem: format!("cannot read '{}': {e}", file.escape_debug()),
                })?;
                let what = format!("{} ({})", key("file"), file.escape_debug());
                meshes.push(mesh::Mesh::parse(&bytes, format, scale, translate, &what)?);
                Shape::Mesh {
                    mesh: meshes.len() - 1,
                }
            }
            _ => Shape::Torus {
                center: self.center.expect("checked"),
                axis: self.axis.expect("checked"),
                major: self.major.expect("checked"),
                minor: self.minor.expect("checked"),
            },
        };
        Ok(Object {
            material: self.material.clone(),
            shape,
        })
    }
}

/// Image size and display depth.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Image {
    /// Width in pixels (1..=8192).
    pub width: u32,
    /// Height in pixels (1..=8192).
    pub height: u32,
    /// Bits per channel of the display: 8 or 10.
    #[serde(default = "default_bits")]
    pub bits: u32,
}

fn default_bits() -> u32 {
    8
}

/// A pinhole camera.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    /// The eye.
    pub position: [f64; 3],
    /// The point looked at (the image centre).
    pub look_at: [f64; 3],
    /// Which way is up (need not be orthogonal to the view direction).
    #[serde(default = "default_up")]
    pub up: [f64; 3],
    /// Vertical field of view in degrees (1..=170).
    pub fov_deg: f64,
}

fn default_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

/// The cosine of the specular lobe.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Model {
    /// Blinn-Phong: N.H, H the half vector of L and V.
    #[default]
    BlinnPhong,
    /// Phong: R.V, R the reflection of L about N.
    Phong,
}

/// How surfaces are shaded.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Shading {
    /// `blinn_phong` (default) or `phong`.
    #[serde(default)]
    pub model: Model,
    /// Ambient light, a fraction of each material's colour (default 0.03).
    #[serde(default = "default_ambient")]
    pub ambient: f64,
}

fn default_ambient() -> f64 {
    0.03
}

impl Default for Shading {
    /// What a scene without `[shading]` gets, the same as an empty `[shading]`: Blinn-Phong,
    /// ambient 0.03.
    fn default() -> Shading {
        Shading {
            model: Model::default(),
            ambient: default_ambient(),
        }
    }
}

/// The kind of a light.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LightKind {
    /// Parallel light from `direction`.
    Directional,
    /// Light from `position`, without falloff (a studio lamp).
    Point,
}

/// A light.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Light {
    /// `directional` or `point`.
    pub kind: LightKind,
    /// For a directional light: from the surface towards the light.
    pub direction: Option<[f64; 3]>,
    /// For a point light: where it is.
    pub position: Option<[f64; 3]>,
    /// Linear RGB colour (default white).
    #[serde(default = "white")]
    pub colour: [f64; 3],
    /// Irradiance scale (default 1).
    #[serde(default = "one")]
    pub intensity: f64,
}

fn white() -> [f64; 3] {
    [1.0; 3]
}

fn one() -> f64 {
    1.0
}

/// A material: Lambert diffuse plus a normalised specular lobe of exponent `n`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// The name objects use.
    pub name: String,
    /// The specular exponent (1..=65535).
    pub n: u32,
    /// Specular weight.
    pub k_s: f64,
    /// Diffuse weight.
    pub k_d: f64,
    /// Linear RGB diffuse colour.
    pub colour: [f64; 3],
}

/// The shape of an object (`kind = "sphere"`, `"capsule"` or `"torus"` in the file).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// A sphere.
    Sphere {
        /// Centre.
        center: [f64; 3],
        /// Radius.
        radius: f64,
    },
    /// A capsule (a tube with round ends) around the segment `a`-`b`.
    Capsule {
        /// One end of the axis.
        a: [f64; 3],
        /// The other end.
        b: [f64; 3],
        /// Radius.
        radius: f64,
    },
    /// A triangle mesh (`kind = "mesh"`, `file = "x.obj"` or `.stl`, optional `scale` and
    /// `translate`): index into [`Scene::meshes`].
    Mesh {
        /// Which mesh.
        mesh: usize,
    },
    /// A torus around `axis` through `center`.
    Torus {
        /// Centre.
        center: [f64; 3],
        /// The axis of symmetry.
        axis: [f64; 3],
        /// Distance from the centre to the tube's centre line.
        major: f64,
        /// The tube's radius (less than `major`).
        minor: f64,
    },
}

/// An object: a shape and the name of its material.
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    /// The material's name.
    pub material: String,
    /// The shape.
    pub shape: Shape,
}

/// A scene's part as a TOML value (for [`Scene::canonical`]).
fn toml_value(what: &str, v: &impl Serialize) -> toml::Value {
    toml::Value::try_from(v).unwrap_or_else(|e| panic!("{what} serialises to TOML: {e}"))
}

/// Reads a mesh file named in a scene: its bytes.
pub type Loader<'a> = &'a dyn Fn(&str) -> std::io::Result<Vec<u8>>;

/// The built-in scene's text: a cluster of cells, a vessel segment and a bone-like ring, with
/// shininess 16 to 1024.
pub const DEFAULT_SCENE: &str = include_str!("default.toml");

impl Scene {
    /// Reads and validates a scene from TOML text.
    ///
    /// # Examples
    /// ```
    /// use specfx::scene::Scene;
    /// let s = Scene::from_toml(specfx::scene::DEFAULT_SCENE).unwrap();
    /// assert!(s.materials.iter().any(|m| m.n == 1024));
    /// let bad = specfx::scene::DEFAULT_SCENE.replace("radius = 0.55", "radius = -1");
    /// assert!(Scene::from_toml(&bad).unwrap_err().to_string().contains(".radius"));
    /// ```
    pub fn from_toml(text: &str) -> Result<Scene, Error> {
        Scene::from_toml_with(text, &|_| {
            Err(std::io::Error::other(
                "meshes are read by `specfx render` (Scene::from_toml_with)",
            ))
        })
    }

    /// [`Scene::from_toml`], reading each mesh file's bytes with `load` (the command reads
    /// them relative to the scene file; the library does no I/O).
    pub fn from_toml_with(text: &str, load: Loader<'_>) -> Result<Scene, Error> {
        let file: SceneFile = crate::error::parse_toml(text)?;
        let mut meshes = Vec::new();
        let objects = file
            .objects
            .iter()
            .enumerate()
            .map(|(i, o)| o.build(i, load, &mut meshes))
            .collect::<Result<Vec<_>, _>>()?;
        let scene = Scene {
            image: file.image,
            camera: file.camera,
            shading: file.shading,
            lights: file.lights,
            materials: file.materials,
            objects,
            meshes,
        };
        scene.validate()?;
        Ok(scene)
    }

    /// The built-in default scene.
    pub fn default_scene() -> Scene {
        Scene::from_toml(DEFAULT_SCENE).expect("the built-in scene is valid")
    }

    /// The scene in one canonical form, for a result's recorded inputs: every key of the
    /// validated scene (defaults filled in) in a fixed order; a mesh object as the number and
    /// the sha256 of its triangles (little-endian f64, after its scale and translation), so
    /// that no file name or path is recorded.
    ///
    /// # Examples
    /// ```
    /// use specfx::scene::Scene;
    /// let a = Scene::default_scene();
    /// // The same scene with a comment, and without the up vector it spells out (the default).
    /// let text = format!("# commented\n{}", specfx::scene::DEFAULT_SCENE)
    ///     .replacen("up = [0.0, 1.0, 0.0]\n", "", 1);
    /// assert_ne!(text.len(), specfx::scene::DEFAULT_SCENE.len() + 12);
    /// let b = Scene::from_toml(&text).unwrap();
    /// assert_eq!(a.canonical(), b.canonical());
    /// assert!(a.canonical().contains_key("material"));
    /// ```
    pub fn canonical(&self) -> toml::Table {
        let mut t = toml::Table::new();
        t.insert("image".into(), toml_value("image", &self.image));
        t.insert("camera".into(), toml_value("camera", &self.camera));
        t.insert("shading".into(), toml_value("shading", &self.shading));
        t.insert("light".into(), toml_value("lights", &self.lights));
        t.insert("material".into(), toml_value("materials", &self.materials));
        let objects = self
            .objects
            .iter()
            .map(|o| {
                let mut ot = toml::Table::new();
                let v3 = |x: [f64; 3]| toml_value("a vector", &x);
                let put = |ot: &mut toml::Table, k: &str, v: toml::Value| {
                    ot.insert(k.into(), v);
                };
                ot.insert("material".into(), o.material.clone().into());
                match o.shape {
                    Shape::Sphere { center, radius } => {
                        put(&mut ot, "kind", "sphere".into());
                        put(&mut ot, "center", v3(center));
                        put(&mut ot, "radius", radius.into());
                    }
                    Shape::Capsule { a, b, radius } => {
                        put(&mut ot, "kind", "capsule".into());
                        put(&mut ot, "a", v3(a));
                        put(&mut ot, "b", v3(b));
                        put(&mut ot, "radius", radius.into());
                    }
                    Shape::Torus {
                        center,
                        axis,
                        major,
                        minor,
                    } => {
                        put(&mut ot, "kind", "torus".into());
                        put(&mut ot, "center", v3(center));
                        put(&mut ot, "axis", v3(axis));
                        put(&mut ot, "major", major.into());
                        put(&mut ot, "minor", minor.into());
                    }
                    Shape::Mesh { mesh } => {
                        let tris = &self.meshes[mesh].triangles;
                        let bytes: Vec<u8> = tris
                            .iter()
                            .flatten()
                            .flatten()
                            .flat_map(|x| x.to_le_bytes())
                            .collect();
                        put(&mut ot, "kind", "mesh".into());
                        put(&mut ot, "triangles", (tris.len() as i64).into());
                        put(
                            &mut ot,
                            "triangles_sha256",
                            crate::provenance::sha256_hex(&bytes).into(),
                        );
                    }
                }
                toml::Value::Table(ot)
            })
            .collect();
        t.insert("object".into(), toml::Value::Array(objects));
        t
    }

    /// The index of a material by name.
    pub fn material_index(&self, name: &str) -> Option<usize> {
        self.materials.iter().position(|m| m.name == name)
    }

    /// The distinct exponents of the materials, ascending.
    pub fn exponents(&self) -> Vec<u32> {
        let mut ns: Vec<u32> = self.materials.iter().map(|m| m.n).collect();
        ns.sort_unstable();
        ns.dedup();
        ns
    }

    fn validate(&self) -> Result<(), Error> {
        let bad = |key: String, problem: String| Err(Error::Config { key, problem });
        let img = &self.image;
        for (key, v) in [("image.width", img.width), ("image.height", img.height)] {
            if !(1..=8192).contains(&v) {
                return bad(key.into(), format!("expected 1..=8192 pixels, got {v}"));
            }
        }
        if img.bits != 8 && img.bits != 10 {
            return bad(
                "image.bits".into(),
                format!("expected 8 or 10, got {}", img.bits),
            );
        }
        let cam = &self.camera;
        vector("camera.position", cam.position, false)?;
        vector("camera.look_at", cam.look_at, false)?;
        vector("camera.up", cam.up, true)?;
        let view = sub(cam.look_at, cam.position);
        if norm(view) == 0.0 {
            return bad(
                "camera.look_at".into(),
                "expected a point other than camera.position".into(),
            );
        }
        if norm(cross(view, cam.up)) <= 1e-9 * norm(view) * norm(cam.up) {
            return bad(
                "camera.up".into(),
                "expected a direction not parallel to the view direction".into(),
            );
        }
        if !(cam.fov_deg.is_finite() && (1.0..=170.0).contains(&cam.fov_deg)) {
            return bad(
                "camera.fov_deg".into(),
                format!("expected 1..=170 degrees, got {}", cam.fov_deg),
            );
        }
        let amb = self.shading.ambient;
        if !(amb.is_finite() && (0.0..=1.0).contains(&amb)) {
            return bad(
                "shading.ambient".into(),
                format!("expected 0..=1, got {amb}"),
            );
        }
        if self.lights.is_empty() || self.lights.len() > MAX_LIGHTS {
            return bad(
                "light".into(),
                format!(
                    "expected 1 to {MAX_LIGHTS} [[light]] tables, got {}",
                    self.lights.len()
                ),
            );
        }
        let work = u64::from(img.width) * u64::from(img.height) * self.lights.len() as u64;
        if work > MAX_PIXEL_LIGHTS {
            return bad(
                "light".into(),
                format!(
                    "{} x {} pixels x {} lights is {work}, above the limit of {MAX_PIXEL_LIGHTS} \
                     (each lit pixel keeps a term per light); use fewer lights or a smaller image",
                    img.width,
                    img.height,
                    self.lights.len()
                ),
            );
        }
        for (i, l) in self.lights.iter().enumerate() {
            let key = |k: &str| format!("light[{i}].{k}");
            match l.kind {
                LightKind::Directional => match l.direction {
                    Some(d) => vector(&key("direction"), d, true)?,
                    None => return bad(key("direction"), "a directional light needs one".into()),
                },
                LightKind::Point => match l.position {
                    Some(p) => vector(&key("position"), p, false)?,
                    None => return bad(key("position"), "a point light needs one".into()),
                },
            }
            colour(&key("colour"), l.colour)?;
            non_negative(&key("intensity"), l.intensity)?;
        }
        if self.materials.is_empty() || self.materials.len() > 4096 {
            return bad(
                "material".into(),
                format!(
                    "expected 1 to 4096 [[material]] tables, got {}",
                    self.materials.len()
                ),
            );
        }
        for (i, m) in self.materials.iter().enumerate() {
            let key = |k: &str| format!("material[{i}].{k}");
            // Names end up in budget expressions, tables, CSV and file headers: the rule of
            // configuration names.
            if let Err(problem) = crate::pipeline::config::check_name(&m.name) {
                return bad(key("name"), problem);
            }
            if self.material_index(&m.name) != Some(i) {
                return bad(
                    key("name"),
                    format!("expected a unique name, got '{}' again", m.name),
                );
            }
            if !(1..=65535).contains(&m.n) {
                return bad(
                    key("n"),
                    format!("expected an exponent in 1..=65535, got {}", m.n),
                );
            }
            non_negative(&key("k_s"), m.k_s)?;
            non_negative(&key("k_d"), m.k_d)?;
            colour(&key("colour"), m.colour)?;
        }
        if self.objects.is_empty() {
            return bad("object".into(), "expected at least one [[object]]".into());
        }
        for (i, o) in self.objects.iter().enumerate() {
            let key = |k: &str| format!("object[{i}].{k}");
            if self.material_index(&o.material).is_none() {
                return bad(
                    key("material"),
                    format!("no [[material]] is named '{}'", o.material.escape_debug()),
                );
            }
            match o.shape {
                Shape::Sphere { center, radius } => {
                    vector(&key("center"), center, false)?;
                    positive(&key("radius"), radius)?;
                }
                Shape::Capsule { a, b, radius } => {
                    vector(&key("a"), a, false)?;
                    vector(&key("b"), b, false)?;
                    positive(&key("radius"), radius)?;
                }
                Shape::Mesh { .. } => {}
                Shape::Torus {
                    center,
                    axis,
                    major,
                    minor,
                } => {
                    vector(&key("center"), center, false)?;
                    vector(&key("axis"), axis, true)?;
                    positive(&key("minor"), minor)?;
                    if !(major.is_finite() && major > minor) {
                        return bad(
                            key("major"),
                            format!("expected a finite radius above minor ({minor}), got {major}"),
                        );
                    }
                }
            }
        }
        Ok(())
    }
}

/// A finite vector (and, for a direction, not zero).
fn vector(key: &str, v: [f64; 3], direction: bool) -> Result<(), Error> {
    if v.iter().any(|x| !x.is_finite()) || (direction && norm(v) == 0.0) {
        return Err(Error::Config {
            key: key.into(),
            problem: format!(
                "expected {} of three finite numbers, got {v:?}",
                if direction {
                    "a non-zero direction"
                } else {
                    "a point"
                }
            ),
        });
    }
    Ok(())
}

fn colour(key: &str, c: [f64; 3]) -> Result<(), Error> {
    if c.iter()
        .any(|x| !(x.is_finite() && (0.0..=1.0).contains(x)))
    {
        return Err(Error::Config {
            key: key.into(),
            problem: format!("expected three numbers in 0..=1, got {c:?}"),
        });
    }
    Ok(())
}

fn non_negative(key: &str, x: f64) -> Result<(), Error> {
    if !(x.is_finite() && x >= 0.0) {
        return Err(Error::Config {
            key: key.into(),
            problem: format!("expected a finite number >= 0, got {x}"),
        });
    }
    Ok(())
}

fn positive(key: &str, x: f64) -> Result<(), Error> {
    if !(x.is_finite() && x > 0.0) {
        return Err(Error::Config {
            key: key.into(),
            problem: format!("expected a finite number > 0, got {x}"),
        });
    }
    Ok(())
}

/// `a - b`.
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a + s b`.
pub fn add_scaled(a: [f64; 3], s: f64, b: [f64; 3]) -> [f64; 3] {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}

/// The dot product.
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The cross product.
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The Euclidean length.
pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// `a / |a|` (`a` non-zero).
pub fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = norm(a);
    [a[0] / l, a[1] / l, a[2] / l]
}
