//! Triangle meshes for scenes: OBJ (tobj) and STL (stl_io, binary or ASCII) read from bytes
//! the caller supplies, checked (finite vertices, indices in range, at least one triangle),
//! and a bounding-volume hierarchy for ray casting.
//!
//! **Invariant:** no I/O: the command reads the files and hands their bytes over.

use crate::error::Error;
use crate::scene::{cross, dot, sub};

/// A triangle mesh with its bounding-volume hierarchy.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// The triangles, reordered so that every BVH leaf is a contiguous run.
    pub triangles: Vec<[[f64; 3]; 3]>,
    nodes: Vec<Node>,
}

/// A BVH node: a box, and either two children or a run of triangles.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Node {
    lo: [f64; 3],
    hi: [f64; 3],
    /// For a leaf, the first triangle; for an inner node, the right child (the left is next).
    index: u32,
    /// Triangles in a leaf (0 for an inner node).
    count: u32,
}

/// Triangles per leaf at most.
const LEAF: usize = 4;

/// How a mesh file is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ (polygons are triangulated).
    Obj,
    /// STL, binary or ASCII.
    Stl,
}

impl MeshFormat {
    /// The format of a file name's extension (`.obj`, `.stl`, any case).
    pub fn of(name: &str) -> Option<MeshFormat> {
        let lower = name.to_ascii_lowercase();
        if lower.ends_with(".obj") {
            Some(MeshFormat::Obj)
        } else if lower.ends_with(".stl") {
            Some(MeshFormat::Stl)
        } else {
            None
        }
    }
}

impl Mesh {
    /// Reads a mesh from a file's bytes, scaled by `scale` and moved by `translate`; `what`
    /// names it in errors.
    ///
    /// # Examples
    /// ```
    /// use specfx::scene::mesh::{Mesh, MeshFormat};
    /// let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n";
    /// let m = Mesh::parse(obj, MeshFormat::Obj, 1.0, [0.0; 3], "t.obj").unwrap();
    /// assert_eq!(m.triangles.len(), 2);
    /// let bad = b"v 0 0 0\nv 1 0 0\nf 1 2 3\n";
    /// assert!(Mesh::parse(bad, MeshFormat::Obj, 1.0, [0.0; 3], "t.obj").is_err());
    /// ```
    pub fn parse(
        bytes: &[u8],
        format: MeshFormat,
        scale: f64,
        translate: [f64; 3],
        what: &str,
    ) -> Result<Mesh, Error> {
        let fail = |problem: String| Error::Config {
            key: what.to_string(),
            problem,
        };
        let (vertices, faces) = match format {
            MeshFormat::Obj => read_obj(bytes, fail)?,
            MeshFormat::Stl => read_stl(bytes, fail)?,
        };
        if let Some((i, v)) = vertices
            .iter()
            .enumerate()
            .find(|(_, v)| v.iter().any(|x| !x.is_finite()))
        {
            return Err(fail(format!("vertex {} is not finite: {v:?}", i + 1)));
        }
        if let Some((i, f)) = faces
            .iter()
            .enumerate()
            .find(|(_, f)| f.iter().any(|&k| k >= vertices.len()))
        {
            return Err(fail(format!(
                "triangle {} refers to a vertex past the {} there are: {f:?} (0-based)",
                i + 1,
                vertices.len()
            )));
        }
        if faces.is_empty() {
            return Err(fail("the mesh has no triangles".into()));
        }
        let place = |v: [f64; 3]| [0, 1, 2].map(|k| v[k] * scale + translate[k]);
        // Placed, a vertex or the mesh's extent may leave f64's range (scale 1e300).
        if let Some((i, v)) = vertices
            .iter()
            .map(|&v| place(v))
            .enumerate()
            .find(|(_, v)| v.iter().any(|x| !x.is_finite()))
        {
            return Err(fail(format!(
                "vertex {} scaled by {scale:?} and moved by {translate:?} is not finite: {v:?}",
                i + 1
            )));
        }
        let triangles = faces
            .iter()
            .map(|f| f.map(|k| place(vertices[k])))
            .collect();
        let mesh = Mesh::new(triangles);
        let (centre, radius) = mesh.bound();
        if !(radius.is_finite() && centre.iter().all(|x| x.is_finite())) {
            return Err(fail(format!(
                "scaled by {scale:?} and moved by {translate:?}, the mesh spans more than f64 holds"
            )));
        }
        Ok(mesh)
    }

    /// A mesh of the given triangles, with its hierarchy built.
    pub fn new(mut triangles: Vec<[[f64; 3]; 3]>) -> Mesh {
        let mut nodes = Vec::with_capacity(2 * triangles.len() / LEAF + 1);
        let n = triangles.len();
        build(&mut triangles, 0, n, &mut nodes);
        Mesh { triangles, nodes }
    }

    /// A sphere enclosing the mesh: the centre and half-diagonal of its bounding box.
    pub fn bound(&self) -> ([f64; 3], f64) {
        let root = self.nodes[0];
        let c = [0, 1, 2].map(|k| 0.5 * (root.lo[k] + root.hi[k]));
        let r = 0.5 * crate::scene::norm(sub(root.hi, root.lo));
        (c, r)
    }

    /// The nearest hit of a ray (origin `o`, unit direction `d`) beyond a small epsilon: the
    /// distance and the unit face normal.
    pub fn hit(&self, o: [f64; 3], d: [f64; 3]) -> Option<(f64, [f64; 3])> {
        let inv = d.map(|x| 1.0 / x);
        let mut best: Option<(f64, usize)> = None;
        let mut stack = vec![0u32];
        while let Some(i) = stack.pop() {
            let node = self.nodes[i as usize];
            let limit = best.map_or(f64::INFINITY, |b| b.0);
            if !slab(node.lo, node.hi, o, inv, limit) {
                continue;
            }
            if node.count > 0 {
                let start = node.index as usize;
                for t in start..start + node.count as usize {
                    if let Some(dist) = triangle_hit(&self.triangles[t], o, d) {
                        if best.is_none_or(|b| dist < b.0) {
                            best = Some((dist, t));
                        }
                    }
                }
            } else {
                stack.push(node.index);
                stack.push(i + 1);
            }
        }
        best.map(|(t, i)| {
            let [a, b, c] = self.triangles[i];
            (t, crate::scene::normalize(cross(sub(b, a), sub(c, a))))
        })
    }
}

/// A mesh as a file holds it: vertices and triangles of vertex indices (0-based).
type Indexed = (Vec<[f64; 3]>, Vec<[usize; 3]>);

fn read_obj(bytes: &[u8], fail: impl Fn(String) -> Error) -> Result<Indexed, Error> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    };
    // Only positions and faces are used: texture coordinates and normals (`vt`, `vn` lines,
    // first words as tobj splits them) are dropped before tobj reads the file, because tobj
    // 4.0.5 computes their relative indices unchecked (`f 1/-3` overflows: a panic where
    // overflow checks are on, a wrong element where they are off).
    let text = std::str::from_utf8(bytes).map_err(|e| {
        fail(format!(
            "not a readable OBJ file: not UTF-8 text (an invalid byte at offset {})",
            e.valid_up_to()
        ))
    })?;
    // A byte-order mark is not part of the first line.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    check_obj(text).map_err(&fail)?;
    let positions_and_faces: String = text
        .split_inclusive('\n')
        .filter(|line| !matches!(line.split_whitespace().next(), Some("vt" | "vn")))
        .collect();
    let mut reader = std::io::BufReader::new(positions_and_faces.as_bytes());
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| fail(format!("not a readable OBJ file: {e}")))?;
    let mut vertices = Vec::new();
    let mut faces = Vec::new();
    for m in &models {
        let base = vertices.len();
        vertices.extend(
            m.mesh
                .positions
                .chunks(3)
                .map(|p| [f64::from(p[0]), f64::from(p[1]), f64::from(p[2])]),
        );
        faces.extend(
            m.mesh
                .indices
                .chunks(3)
                .map(|f| [0, 1, 2].map(|k| base + f[k] as usize)),
        );
    }
    Ok((vertices, faces))
}

/// Checks the position and face lines of an OBJ file before tobj reads it, so that an error
/// names its line and what was expected (tobj says only "face parse error").
fn check_obj(text: &str) -> Result<(), String> {
    let mut vertices: i64 = 0;
    for (i, line) in text.lines().enumerate() {
        let shown = || line.trim().escape_debug().to_string();
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let numbers: Vec<&str> = words.collect();
                if !(3..=7).contains(&numbers.len())
                    || numbers
                        .iter()
                        .any(|w| !w.parse::<f32>().is_ok_and(f32::is_finite))
                {
                    return Err(format!(
                        "line {}: expected `v x y z` (three numbers within the 32-bit float range, |x| <= 3.4e38, then optionally w or a colour), got '{}'",
                        i + 1,
                        shown()
                    ));
                }
                vertices += 1;
            }
            Some("f") => {
                let corners: Vec<&str> = words.collect();
                if corners.len() < 3 {
                    return Err(format!(
                        "line {}: expected `f` and at least three vertices (i, i/t, i//n or i/t/n), got '{}'",
                        i + 1,
                        shown()
                    ));
                }
                for corner in corners {
                    let index = corner.split('/').next().unwrap_or_default();
                    let Ok(k) = index.parse::<i64>() else {
                        return Err(format!(
                            "line {}: expected a vertex index (an integer; negative counts back), got '{}'",
                            i + 1,
                            corner.escape_debug()
                        ));
                    };
                    if k == 0 || k.unsigned_abs() > vertices.unsigned_abs() {
                        return Err(format!(
                            "line {}: vertex index {k} is out of range: {vertices} vertices come before this line",
                            i + 1
                        ));
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Whether an STL file is binary: it does not start with `solid `, or it does (some exporters
/// write that into a binary header) but its size is exactly a binary file's and it is not a
/// valid ASCII one.
fn stl_is_binary(bytes: &[u8]) -> bool {
    let exact = bytes.get(80..84).is_some_and(|c| {
        84 + 50 * u64::from(u32::from_le_bytes(c.try_into().expect("four bytes")))
            == bytes.len() as u64
    });
    !bytes.starts_with(b"solid ") || (exact && check_ascii_stl(bytes).is_err())
}

/// Checks a binary STL's size against its triangle count.
fn check_binary_stl(bytes: &[u8]) -> Result<(), String> {
    let Some(count) = bytes.get(80..84) else {
        return Err(format!(
            "expected an ASCII STL (starting with `solid `) or a binary one (an 80-byte header and a 4-byte triangle count), got {} bytes",
            bytes.len()
        ));
    };
    let count = u32::from_le_bytes(count.try_into().expect("four bytes"));
    let need = 84 + 50 * u64::from(count);
    if (bytes.len() as u64) < need {
        return Err(format!(
            "binary STL: its header says {count} triangles, which take {need} bytes, but the file has {}",
            bytes.len()
        ));
    }
    Ok(())
}

/// Checks an ASCII STL line by line, so that an error names its line and what was expected.
fn check_ascii_stl(bytes: &[u8]) -> Result<(), String> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        format!(
            "ASCII STL: not UTF-8 text (an invalid byte at offset {})",
            e.valid_up_to()
        )
    })?;
    // What each line must be, in turn: a facet (or the end), its loop, three vertices, the
    // loop's end and the facet's end.
    const STEPS: [&str; 7] = [
        "facet normal x y z",
        "outer loop",
        "vertex x y z",
        "vertex x y z",
        "vertex x y z",
        "endloop",
        "endfacet",
    ];
    let numbers = |w: &[&str]| w.iter().all(|x| x.parse::<f32>().is_ok_and(f32::is_finite));
    let mut step = 0;
    let mut last = 1;
    for (i, line) in text.lines().enumerate().skip(1) {
        let words: Vec<&str> = line.split_whitespace().collect();
        if words.is_empty() {
            continue;
        }
        last = i + 1;
        let ok = match step {
            0 if words[0] == "endsolid" => return Ok(()),
            0 => words.len() == 5 && words[..2] == ["facet", "normal"] && numbers(&words[2..]),
            1 => words == ["outer", "loop"],
            2..=4 => words.len() == 4 && words[0] == "vertex" && numbers(&words[1..]),
            5 => words == ["endloop"],
            _ => words == ["endfacet"],
        };
        if !ok {
            let expected = if step == 0 {
                "`facet normal x y z` or `endsolid`".to_string()
            } else {
                format!("`{}`", STEPS[step])
            };
            return Err(format!(
                "line {}: expected {expected} (x y z numbers within the 32-bit float range, |x| <= 3.4e38), got '{}'",
                i + 1,
                line.trim().escape_debug()
            ));
        }
        step = (step + 1) % STEPS.len();
    }
    Err(format!(
        "line {last}: the ASCII STL ends before `endsolid` (expected {})",
        if step == 0 {
            "a facet or `endsolid`"
        } else {
            STEPS[step]
        }
    ))
}

fn read_stl(bytes: &[u8], fail: impl Fn(String) -> Error) -> Result<Indexed, Error> {
    // A byte-order mark before an ASCII STL's `solid` is not part of it.
    let bytes = match bytes.strip_prefix("\u{feff}".as_bytes()) {
        Some(rest) if rest.starts_with(b"solid ") => rest,
        _ => bytes,
    };
    let binary = stl_is_binary(bytes);
    if binary {
        check_binary_stl(bytes).map_err(&fail)?;
    } else if let Err(ascii) = check_ascii_stl(bytes) {
        // Not text after `solid `: a binary file whose header starts so, of the wrong size.
        let text = std::str::from_utf8(bytes).is_ok_and(|t| !t.contains('\0'));
        return Err(fail(match check_binary_stl(bytes) {
            Err(size) if !text => size,
            _ => ascii,
        }));
    }
    // stl_io takes any file starting with `solid ` for ASCII.
    let mut owned;
    let bytes = if binary && bytes.starts_with(b"solid ") {
        owned = bytes.to_vec();
        owned[..6].fill(0);
        &owned[..]
    } else {
        bytes
    };
    let mut cursor = std::io::Cursor::new(bytes);
    let mesh =
        stl_io::read_stl(&mut cursor).map_err(|e| fail(format!("not a readable STL file: {e}")))?;
    let vertices = mesh
        .vertices
        .iter()
        .map(|v| [f64::from(v[0]), f64::from(v[1]), f64::from(v[2])])
        .collect();
    let faces = mesh.faces.iter().map(|f| f.vertices).collect();
    Ok((vertices, faces))
}

/// Builds the subtree of `tris[start..end]` (reordering them) and returns its node index.
fn build(tris: &mut [[[f64; 3]; 3]], start: usize, end: usize, nodes: &mut Vec<Node>) -> u32 {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for t in &tris[start..end] {
        for v in t {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
    }
    let me = nodes.len() as u32;
    nodes.push(Node {
        lo,
        hi,
        index: start as u32,
        count: (end - start) as u32,
    });
    if end - start <= LEAF {
        return me;
    }
    // Split at the median centroid along the box's longest axis.
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .expect("three axes");
    let centroid = |t: &[[f64; 3]; 3]| t[0][axis] + t[1][axis] + t[2][axis];
    let mid = start + (end - start) / 2;
    tris[start..end]
        .select_nth_unstable_by(mid - start, |a, b| centroid(a).total_cmp(&centroid(b)));
    build(tris, start, mid, nodes);
    let right = build(tris, mid, end, nodes);
    nodes[me as usize].index = right;
    nodes[me as usize].count = 0;
    me
}

/// Whether a ray meets a box before distance `limit`.
fn slab(lo: [f64; 3], hi: [f64; 3], o: [f64; 3], inv: [f64; 3], limit: f64) -> bool {
    let (mut t0, mut t1) = (0.0f64, limit);
    for k in 0..3 {
        let a = (lo[k] - o[k]) * inv[k];
        let b = (hi[k] - o[k]) * inv[k];
        let (near, far) = if a <= b { (a, b) } else { (b, a) };
        // NaN (a ray in the box's plane, 0 * inf) leaves the interval as it is.
        t0 = if near > t0 { near } else { t0 };
        t1 = if far < t1 { far } else { t1 };
        if t0 > t1 {
            return false;
        }
    }
    true
}

/// Möller-Trumbore: the distance along the ray to the triangle, if it is hit ahead.
fn triangle_hit(t: &[[f64; 3]; 3], o: [f64; 3], d: [f64; 3]) -> Option<f64> {
    let e1 = sub(t[1], t[0]);
    let e2 = sub(t[2], t[0]);
    let p = cross(d, e2);
    let det = dot(e1, p);
    if det.abs() < 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let s = sub(o, t[0]);
    let u = dot(s, p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = cross(s, e1);
    let v = dot(d, q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let dist = dot(e2, q) * inv;
    (dist > 1e-9).then_some(dist)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_and_normal_indices_are_ignored() {
        // `3/-3` names the texture coordinate three before the one there is: tobj's unchecked
        // index arithmetic overflowed on it. Only the positions matter here.
        let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvn 0 0 1\nf 3/-3/-7 1/1/1 2//1\n";
        let m = Mesh::parse(obj, MeshFormat::Obj, 1.0, [0.0; 3], "t.obj").unwrap();
        assert_eq!(
            m.triangles,
            vec![[[1.0, 1.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]]
        );
    }

    fn err(bytes: &[u8], format: MeshFormat) -> String {
        Mesh::parse(bytes, format, 1.0, [0.0; 3], "m")
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn obj_errors_name_the_line_and_what_was_expected() {
        let v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        for (tail, expect) in [
            (
                "f 1 2\n",
                "line 4: expected `f` and at least three vertices",
            ),
            (
                "f 1 2 x/1\n",
                "line 4: expected a vertex index (an integer; negative counts back), got 'x/1'",
            ),
            (
                "f 1 2 4\n",
                "line 4: vertex index 4 is out of range: 3 vertices come before this line",
            ),
            ("f 1 2 -4\n", "line 4: vertex index -4 is out of range"),
            ("f 0 1 2\n", "line 4: vertex index 0 is out of range"),
            (
                "v 1 2\n",
                "line 4: expected `v x y z` (three numbers within the 32-bit float range, |x| <= 3.4e38",
            ),
            ("v 1 2 z\n", "line 4: expected `v x y z`"),
            (
                "v 1 2 1e39\n",
                "line 4: expected `v x y z` (three numbers within the 32-bit float range, |x| <= 3.4e38",
            ),
            // Finite, but beyond f32: the message says the real rule.
            (
                "v 1 2 1e300\n",
                "line 4: expected `v x y z` (three numbers within the 32-bit float range, |x| <= 3.4e38",
            ),
        ] {
            let e = err(format!("{v}{tail}").as_bytes(), MeshFormat::Obj);
            assert!(e.starts_with(&format!("m: {expect}")), "{tail}: {e}");
        }
        // A byte-order mark, CRLF line ends and negative indices are fine.
        let bom = format!("\u{feff}{v}f -3 -2 -1\r\n").replace('\n', "\r\n");
        let m = Mesh::parse(bom.as_bytes(), MeshFormat::Obj, 1.0, [0.0; 3], "m").unwrap();
        assert_eq!(
            m.triangles,
            vec![[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]]
        );
    }

    #[test]
    fn stl_errors_name_the_line_or_the_size() {
        let facet = "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
        let good = format!("solid t\n{facet}endsolid t\n");
        let m = Mesh::parse(good.as_bytes(), MeshFormat::Stl, 1.0, [0.0; 3], "m").unwrap();
        assert_eq!(m.triangles.len(), 1);
        let bom = format!("\u{feff}{good}");
        let m = Mesh::parse(bom.as_bytes(), MeshFormat::Stl, 1.0, [0.0; 3], "m").unwrap();
        assert_eq!(m.triangles.len(), 1);
        for (from, to, expect) in [
            (
                "vertex 1 0 0",
                "vertex 1 0",
                "line 5: expected `vertex x y z`",
            ),
            ("endloop", "end loop", "line 7: expected `endloop`"),
            (
                "vertex 1 0 0",
                "vertex 1 nan 0",
                "line 5: expected `vertex x y z` (x y z numbers within the 32-bit float range",
            ),
            (
                "endsolid t\n",
                "",
                "line 8: the ASCII STL ends before `endsolid`",
            ),
            (
                "facet normal",
                "facet",
                "line 2: expected `facet normal x y z` or `endsolid`",
            ),
        ] {
            let e = err(good.replacen(from, to, 1).as_bytes(), MeshFormat::Stl);
            assert!(e.starts_with(&format!("m: {expect}")), "{to}: {e}");
        }
        // Binary: 84 header bytes, then 50 per triangle.
        let mut bin = vec![0u8; 80];
        bin.extend_from_slice(&2u32.to_le_bytes());
        bin.extend_from_slice(&[0u8; 60]);
        let e = err(&bin, MeshFormat::Stl);
        assert_eq!(
            e,
            "m: binary STL: its header says 2 triangles, which take 184 bytes, but the file has 144"
        );
        assert!(err(&bin[..50], MeshFormat::Stl).contains("got 50 bytes"));
        // Its header starting with `solid ` and its size wrong: the size is what is said.
        let mut solid_bin = bin.clone();
        solid_bin[..6].copy_from_slice(b"solid ");
        solid_bin[90] = 0xff;
        let e = err(&solid_bin, MeshFormat::Stl);
        assert!(
            e.starts_with("m: binary STL: its header says 2 triangles"),
            "{e}"
        );
        // A binary header that starts with `solid ` (some exporters write one) is still binary.
        let mut tri = vec![0u8; 12];
        for v in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            tri.extend(v.iter().flat_map(|x| x.to_le_bytes()));
        }
        tri.extend_from_slice(&[0, 0]);
        let mut solid = b"solid exported".to_vec();
        solid.resize(80, b' ');
        solid.extend_from_slice(&1u32.to_le_bytes());
        solid.extend_from_slice(&tri);
        let m = Mesh::parse(&solid, MeshFormat::Stl, 1.0, [0.0; 3], "m").unwrap();
        assert_eq!(
            m.triangles,
            vec![[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]]
        );
    }

    #[test]
    fn placed_vertices_and_extent_stay_finite() {
        let obj = b"v 0 0 0\nv 10 0 0\nv 0 1 0\nf 1 2 3\n";
        let e = Mesh::parse(obj, MeshFormat::Obj, 1e308, [0.0; 3], "t.obj").unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.obj: vertex 2 scaled by 1e308 and moved by [0.0, 0.0, 0.0] is not finite: [inf, 0.0, 0.0]"
        );
        // Every vertex finite (about -1.5e308 and 1.5e308), but not the box's width.
        let wide = b"v -1e38 0 0\nv 1e38 0 0\nv 0 1 0\nf 1 2 3\n";
        let e = Mesh::parse(wide, MeshFormat::Obj, 1.5e270, [0.0; 3], "t.obj")
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("the mesh spans more than f64 holds"), "{e}");
        let m = Mesh::parse(obj, MeshFormat::Obj, 2.0, [1.0, 0.0, 0.0], "t.obj").unwrap();
        assert_eq!(m.bound(), ([11.0, 1.0, 0.0], 0.5 * 404f64.sqrt()));
    }
}
