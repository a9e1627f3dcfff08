//! Triangle meshes before they become `ShapeGeometry`: OBJ loading, the built-in rectangle and
//! cube, and the per-shape edits (to_world, face_normals, flip_normals).

use glam::{Mat3, Mat4, Vec3};
use std::io::BufReader;
use std::path::Path;

/// A triangle mesh as read from a file or built by a shape element.
#[derive(Clone, Debug, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// One per vertex when present.
    pub normals: Option<Vec<Vec3>>,
    /// Triangles as three vertex indices.
    pub indices: Vec<[u32; 3]>,
}

impl TriMesh {
    /// Points by `m`, normals by its inverse transpose (renormalised) so they stay
    /// perpendicular under non-uniform scale. `m` must be invertible (checked by the caller).
    pub fn transform(&mut self, m: &Mat4) {
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        if let Some(normals) = &mut self.normals {
            let n_mat = Mat3::from_mat4(*m).inverse().transpose();
            for n in normals {
                *n = (n_mat * *n).normalize_or_zero();
            }
        }
    }

    /// Reverses the winding and the normals, so both notions of "front" flip together.
    pub fn flip(&mut self) {
        for t in &mut self.indices {
            t.swap(1, 2);
        }
        if let Some(normals) = &mut self.normals {
            for n in normals {
                *n = -*n;
            }
        }
    }

    /// Surface area.
    pub fn area(&self) -> f32 {
        self.indices
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i as usize]);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }
}

/// Mitsuba's `rectangle`: [-1,1]^2 in the z=0 plane, facing +z (counter-clockwise seen from +z).
pub fn rectangle() -> TriMesh {
    TriMesh {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        normals: Some(vec![Vec3::Z; 4]),
        indices: vec![[0, 1, 2], [2, 3, 0]],
    }
}

/// Mitsuba's `cube`: [-1,1]^3 with flat faces (4 own vertices per face, so vertex normals are
/// the face normals) and outward winding.
pub fn cube() -> TriMesh {
    let mut mesh = TriMesh {
        positions: Vec::with_capacity(24),
        normals: Some(Vec::with_capacity(24)),
        indices: Vec::with_capacity(12),
    };
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut n = Vec3::ZERO;
            n[axis] = sign;
            // u, v span the face so that u x v = n (counter-clockwise seen from outside).
            let mut u = Vec3::ZERO;
            u[(axis + 1) % 3] = 1.0;
            let v = n.cross(u);
            let base = mesh.positions.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                mesh.positions.push(n + a * u + b * v);
                mesh.normals.as_mut().unwrap().push(n);
            }
            mesh.indices.push([base, base + 1, base + 2]);
            mesh.indices.push([base + 2, base + 3, base]);
        }
    }
    mesh
}

/// The first malformed line of an OBJ file, and why. Checks the statements directlab reads
/// (v, vn, vt, f): numbers where numbers belong, and face indices (1-based, or negative
/// relative ones) into the vertices, texture coordinates and normals defined above them.
pub fn find_obj_error(path: &Path) -> Option<(usize, String)> {
    use std::io::BufRead;
    let file = std::fs::File::open(path).ok()?;
    let (mut nv, mut nt, mut nn) = (0i64, 0i64, 0i64);
    for (i, line) in BufReader::new(file).lines().enumerate() {
        let lineno = i + 1;
        let Ok(line) = line else {
            return Some((lineno, "expected UTF-8 text".into()));
        };
        let mut words = line.split_whitespace();
        let Some(head) = words.next() else {
            continue;
        };
        let args: Vec<&str> = words.collect();
        let shown = super::xml::clip(line.trim());
        let numbers = |min: usize, count: &mut i64| -> Option<String> {
            let ok = args.len() >= min && args.iter().all(|a| a.parse::<f32>().is_ok());
            *count += 1;
            (!ok)
                .then(|| format!("expected '{head}' and at least {min} numbers, found \"{shown}\""))
        };
        let err = match head {
            "v" => numbers(3, &mut nv),
            "vt" => numbers(1, &mut nt),
            "vn" => numbers(3, &mut nn),
            "f" if args.len() < 3 => Some(format!(
                "a face needs at least 3 vertices, found \"{shown}\""
            )),
            "f" => args.iter().find_map(|v| {
                let parts: Vec<&str> = v.split('/').collect();
                let ok = parts.len() <= 3
                    && parts
                        .iter()
                        .zip([nv, nt, nn])
                        .enumerate()
                        .all(|(k, (p, n))| {
                            if p.is_empty() {
                                return k > 0; // v//vn: the texture index may be left out
                            }
                            p.parse::<i64>().is_ok_and(|i| i != 0 && i <= n && -i <= n)
                        });
                (!ok).then(|| {
                    format!(
                        "face vertex '{}' is not an index into the {nv} vertices (or {nt} \
                         texture coordinates, {nn} normals) defined above it",
                        super::xml::clip(v)
                    )
                })
            }),
            _ => None,
        };
        if let Some(e) = err {
            return Some((lineno, e));
        }
    }
    None
}

/// Loads a Wavefront OBJ, merging all its objects/groups into one mesh (as Mitsuba and Nori
/// do). Materials are not read. Messages name the OBJ file; the caller adds the XML position.
pub fn load_obj(path: &Path) -> Result<TriMesh, String> {
    let meta = std::fs::metadata(path)
        .map_err(|e| format!("cannot open mesh file '{}': {e}", path.display()))?;
    if !meta.is_file() {
        return Err(format!(
            "cannot read mesh file '{}': expected a regular file",
            path.display()
        ));
    }
    // Checked first: tobj names no line in its errors, and silently accepts face indices past
    // the vertices defined (it read `f 1 2 4` after three vertices as a degenerate triangle).
    if let Some((line, what)) = find_obj_error(path) {
        return Err(format!("{}:{line}: {what}", path.display()));
    }
    let file = std::fs::File::open(path)
        .map_err(|e| format!("cannot open mesh file '{}': {e}", path.display()))?;
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _materials) = tobj::load_obj_buf(&mut BufReader::new(file), &opts, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| format!("cannot read mesh file '{}': {e}", path.display()))?;

    let mut out = TriMesh {
        positions: Vec::new(),
        normals: Some(Vec::new()),
        indices: Vec::new(),
    };
    for model in &models {
        let m = &model.mesh;
        let base = out.positions.len() as u32;
        let nverts = m.positions.len() / 3;
        for (i, p) in m.positions.chunks_exact(3).enumerate() {
            let v = Vec3::from_slice(p);
            if !v.is_finite() {
                return Err(format!(
                    "mesh file '{}': vertex {} of object '{}' is not finite: {v}",
                    path.display(),
                    i + 1,
                    model.name
                ));
            }
            out.positions.push(v);
        }
        // A mesh only keeps normals if every part of it has them.
        if m.normals.len() == m.positions.len() && nverts > 0 {
            if let Some(normals) = &mut out.normals {
                for (i, n) in m.normals.chunks_exact(3).enumerate() {
                    let n = Vec3::from_slice(n);
                    if !n.is_finite() {
                        return Err(format!(
                            "mesh file '{}': normal of vertex {} of object '{}' is not finite: {n}",
                            path.display(),
                            i + 1,
                            model.name
                        ));
                    }
                    normals.push(n);
                }
            }
        } else {
            out.normals = None;
        }
        for t in m.indices.chunks_exact(3) {
            out.indices.push([base + t[0], base + t[1], base + t[2]]);
        }
    }
    if out.indices.is_empty() {
        return Err(format!("mesh file '{}' has no faces", path.display()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn face_normal(m: &TriMesh, t: usize) -> Vec3 {
        let [a, b, c] = m.indices[t].map(|i| m.positions[i as usize]);
        (b - a).cross(c - a).normalize()
    }

    #[test]
    fn rectangle_faces_plus_z_with_area_4() {
        let r = rectangle();
        assert_eq!(r.indices.len(), 2);
        assert!((r.area() - 4.0).abs() < 1e-6);
        for t in 0..2 {
            assert!(face_normal(&r, t).abs_diff_eq(Vec3::Z, 1e-6));
        }
    }

    #[test]
    fn cube_has_outward_flat_faces() {
        let c = cube();
        assert_eq!((c.positions.len(), c.indices.len()), (24, 12));
        assert!((c.area() - 24.0).abs() < 1e-5);
        let normals = c.normals.as_ref().unwrap();
        for t in 0..12 {
            let [a, b, cc] = c.indices[t].map(|i| c.positions[i as usize]);
            let centroid = (a + b + cc) / 3.0;
            let n = face_normal(&c, t);
            assert!(n.dot(centroid) > 0.0, "triangle {t} faces inwards");
            for i in c.indices[t] {
                assert!(normals[i as usize].abs_diff_eq(n, 1e-6));
            }
        }
        for p in &c.positions {
            assert!(p.abs().max_element() == 1.0 && p.abs().min_element() == 1.0);
        }
    }

    #[test]
    fn transform_uses_inverse_transpose_for_normals() {
        // A 45-degree plane x + y = 0 stretched along x: the normal must tilt towards y.
        let mut m = TriMesh {
            positions: vec![Vec3::ZERO],
            normals: Some(vec![Vec3::new(1.0, 1.0, 0.0).normalize()]),
            indices: vec![],
        };
        m.transform(&Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0)));
        let n = m.normals.unwrap()[0];
        assert!(
            n.abs_diff_eq(Vec3::new(1.0, 2.0, 0.0).normalize(), 1e-6),
            "{n}"
        );
    }

    #[test]
    fn flip_reverses_winding_and_normals() {
        let mut r = rectangle();
        r.flip();
        assert!(face_normal(&r, 0).abs_diff_eq(-Vec3::Z, 1e-6));
        assert!(r.normals.unwrap().iter().all(|n| *n == -Vec3::Z));
    }

    #[test]
    fn obj_loading() {
        let dir = std::env::temp_dir().join(format!("directlab-mesh-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let quad = dir.join("quad.obj");
        std::fs::write(
            &quad,
            "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
        )
        .unwrap();
        let m = load_obj(&quad).unwrap();
        assert_eq!(m.indices.len(), 2);
        assert!(m.normals.is_none());
        assert!((m.area() - 1.0).abs() < 1e-6);

        let with_n = dir.join("n.obj");
        std::fs::write(
            &with_n,
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n",
        )
        .unwrap();
        let m = load_obj(&with_n).unwrap();
        assert_eq!(m.normals.unwrap(), vec![Vec3::Z; 3]);

        let nan = dir.join("nan.obj");
        std::fs::write(&nan, "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let e = load_obj(&nan).unwrap_err();
        assert!(e.contains("nan.obj") && e.contains("vertex 2"), "{e}");

        let inf = dir.join("inf.obj");
        std::fs::write(&inf, "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n").unwrap();
        assert!(load_obj(&inf).unwrap_err().contains("not finite"));

        // tobj's own messages name no line: the file and line come from find_obj_error.
        for (text, line, what) in [
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\n# c\nf 1 2 x\n",
                5,
                "face vertex 'x'",
            ),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", 4, "face vertex '4'"),
            (
                "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n",
                2,
                "at least 3 numbers",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
                4,
                "at least 3 vertices",
            ),
        ] {
            let bad = dir.join("bad.obj");
            std::fs::write(&bad, text).unwrap();
            let e = load_obj(&bad).unwrap_err();
            let want = format!("{}:{line}: ", bad.display());
            assert!(e.starts_with(&want) && e.contains(what), "{text:?}: {e}");
        }
        let e = load_obj(Path::new("/dev/zero")).unwrap_err();
        assert!(e.contains("expected a regular file"), "{e}");

        let e = load_obj(&dir.join("absent.obj")).unwrap_err();
        assert!(e.contains("absent.obj"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
