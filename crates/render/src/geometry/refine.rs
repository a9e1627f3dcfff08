//! The watertight triangle test's distance, redone in f64 when its f32 error bound cannot
//! decide. pbrt-v4's bound on t grows with the vertices' distance from the ray origin, so in
//! f32 a hit 1e-6 of the scene away cannot be told from the ray's own surface (and was
//! dropped), nor a shadow ray's end 1e-7 short of a light from the light (which then blocked
//! itself); the same formulas in f64 (f32 inputs, so every product is exact) bound the error
//! ~5e8 times tighter. Only the distance is redone: the inside/outside decision stays the
//! f32 one, which neighbouring triangles share.

use glam::{DVec3, Vec3A};

#[inline]
fn gamma(n: f64) -> f64 {
    n * f64::EPSILON * 0.5 / (1.0 - n * f64::EPSILON * 0.5)
}

/// The hit distance along the ray (o, d) to the triangle's plane, if it is larger than its own
/// f64 rounding bound (pbrt-v4's derivation with f64 gammas); None if it may be a self-hit.
#[cold]
pub(super) fn distance_f64(o: Vec3A, d: Vec3A, kz: u8, v: [Vec3A; 3]) -> Option<f64> {
    let f64v = |x: Vec3A| DVec3::new(x.x as f64, x.y as f64, x.z as f64);
    let dp = permute_d(f64v(d), kz);
    let (sx, sy, sz) = (-dp.x / dp.z, -dp.y / dp.z, 1.0 / dp.z);
    let o = f64v(o);
    let [a, b, c] = v.map(|x| permute_d(f64v(x) - o, kz));
    let (ax, ay) = (a.x + sx * a.z, a.y + sy * a.z);
    let (bx, by) = (b.x + sx * b.z, b.y + sy * b.z);
    let (cx, cy) = (c.x + sx * c.z, c.y + sy * c.z);
    let u = cx * by - cy * bx;
    let vv = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    let det = u + vv + w;
    if det == 0.0 {
        return None;
    }
    let (az, bz, cz) = (sz * a.z, sz * b.z, sz * c.z);
    let inv = 1.0 / det;
    let t = (u * az + vv * bz + w * cz) * inv;
    let max_z = az.abs().max(bz.abs()).max(cz.abs());
    let max_x = ax.abs().max(bx.abs()).max(cx.abs());
    let max_y = ay.abs().max(by.abs()).max(cy.abs());
    let delta_z = gamma(3.0) * max_z;
    let delta_x = gamma(5.0) * (max_x + max_z);
    let delta_y = gamma(5.0) * (max_y + max_z);
    let delta_e = 2.0 * (gamma(2.0) * max_x * max_y + delta_y * max_x + delta_x * max_y);
    let max_e = u.abs().max(vv.abs()).max(w.abs());
    let delta_t =
        3.0 * (gamma(3.0) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inv.abs();
    (t > delta_t).then_some(t)
}

/// `permute` for f64 vectors.
#[inline]
fn permute_d(v: DVec3, kz: u8) -> DVec3 {
    match kz {
        0 => DVec3::new(v.y, v.z, v.x),
        1 => DVec3::new(v.z, v.x, v.y),
        _ => v,
    }
}

#[cfg(test)]
mod tests {
    use crate::geometry::shape::Mesh;
    use crate::geometry::watertight::intersect_triangle;
    use crate::rng::Rng;
    use crate::sampling::warps::square_to_uniform_sphere;
    use glam::Vec3;

    /// A unit square light 1e-6 above the floor point (0, 0, 0), seen along directions whose
    /// f32 bound on t (~2.6e-6) exceeds the true distance (~1.5e-6).
    #[test]
    fn hits_closer_than_the_f32_bound_are_found() {
        let z = 1e-6;
        let tris = [
            [
                Vec3::new(-0.5, -0.5, z),
                Vec3::new(-0.5, 0.5, z),
                Vec3::new(0.5, 0.5, z),
            ],
            [
                Vec3::new(-0.5, -0.5, z),
                Vec3::new(0.5, 0.5, z),
                Vec3::new(0.5, -0.5, z),
            ],
        ];
        let o = Vec3::new(0.0, 0.0, f32::MIN_POSITIVE);
        let mut rng = Rng::new(5, 5);
        for _ in 0..10_000 {
            let mut d = square_to_uniform_sphere(rng.next_2d());
            d.z = d.z.abs().max(1e-3);
            let d = d.normalize();
            let t = tris
                .iter()
                .find_map(|v| intersect_triangle(o, d, 0.0, f32::INFINITY, *v))
                .map(|h| h.0);
            let expected = (z - o.z) / d.z;
            let t = t.unwrap_or_else(|| panic!("direction {d} missed the light"));
            // t is as accurate as the f32 path that found it (the hit point is recomputed
            // from barycentrics); what matters is that the light is found.
            assert!((t / expected - 1.0).abs() < 0.05, "t {t} vs {expected}");
        }
    }

    /// A shadow ray ending 1.9e-7 short of a light whose vertices are 5e4 away (the contact
    /// case at scale 1e5): f32 put the light's plane at t = 0.988 < tmax, so the light blocked
    /// its own sample (8 % of them).
    #[test]
    fn shadow_rays_do_not_end_on_their_light() {
        let (h, z) = (5e4f32, 0.1f32);
        let tri = [
            Vec3::new(-h, -h, z),
            Vec3::new(h, h, z),
            Vec3::new(h, -h, z),
        ];
        let o = Vec3::new(0.0, 0.0, f32::MIN_POSITIVE);
        let target = Vec3::new(0.158_309_37, -0.584_090_6, 0.099_999_815);
        assert!(intersect_triangle(o, target - o, 0.0, 1.0 - 1e-4, tri).is_none());
        // The same ray continued past the light does hit it (f32 places the hit only to
        // within its bound; the renderer recomputes the point from barycentrics).
        assert!(intersect_triangle(o, target - o, 0.0, 2.0, tri).is_some());
    }

    /// The f64 re-evaluation accepts hits the f32 bound refused, so it must still refuse the
    /// ray's own surface: from points on tilted triangles at several scales, spawned with the
    /// renderer's offset towards either side, no ray hits its own triangle or the coplanar
    /// neighbour sharing its edge.
    #[test]
    fn spawned_rays_never_hit_their_own_surface() {
        let mut rng = Rng::new(8, 1);
        for scale in [1e-4f32, 1.0, 1e5] {
            let c = Vec3::new(0.3, -0.2, 0.7) * scale;
            let (u, v) = (
                Vec3::new(1.0, 0.2, 0.4) * scale,
                Vec3::new(-0.3, 1.0, 0.1) * scale,
            );
            let p = vec![c - u - v, c + u - v, c + u + v, c - u + v];
            let m = Mesh::new(p.clone(), None, vec![[0, 1, 2], [0, 2, 3]]);
            for _ in 0..20_000 {
                let tri = (rng.next_f32() * 2.0) as usize;
                let b = crate::sampling::warps::square_to_uniform_triangle(rng.next_2d());
                let sp = m.surface_point(tri, b, 0);
                let d = square_to_uniform_sphere(rng.next_2d());
                let o = sp.spawn_origin(d);
                for t in 0..2 {
                    let hit = intersect_triangle(o, d, 0.0, f32::INFINITY, m.vertices(t));
                    assert!(
                        hit.is_none(),
                        "scale {scale}: self-hit {hit:?} from {o} along {d}"
                    );
                }
            }
        }
    }
}
