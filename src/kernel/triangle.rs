//! Watertight ray–triangle intersection (Woop, Benthin, Wald, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1), 2013), in `f32`.
//!
//! The ray is sheared once ([`RayShear`]) so that it runs along +z from the origin; the
//! triangle's vertices are transformed the same way and the 2D edge functions decide the
//! hit. Because every edge function of a shared edge is computed from the same two
//! transformed vertices in the same arithmetic, a ray through an edge or vertex hits at
//! least one of the triangles sharing it (§3 of the paper). Edge functions that round to
//! exactly 0 are recomputed in `f64`, where the products are exact (§4, "fallback to
//! double precision").
//!
//! [`intersect_pack`] runs the same test on four triangles at once ([`TrianglePack`], one
//! SSE lane each, as in Embree's `QuadMv`/`TriangleMv` leaves that Woop et al. §5 measure):
//! every lane does exactly the scalar operations in the same order, without fused
//! multiply–adds, so its decisions and values are bit for bit those of
//! [`intersect_triangle`] and the watertightness argument carries over.
//!
//! The hit box for secondary rays is the barycentric point rounded outward by the error
//! bound of computing it in `f32` (pbrt-v3 §3.9.5, "Bounding intersection point error",
//! triangles: γ₇ (|b0 p0| + |b1 p1| + |b2 p2|)), so the renderer's ulp-robust offset from
//! a corner of the hit box (Dammertz §2.4) applies to triangles as it does to patches.

use glam::{BVec4A, Vec3, Vec4};

use crate::geom::{Aabb, Ray};

/// The per-ray precomputation of Woop et al. §3: the axis `kz` along which the direction
/// is largest, the other two axes (swapped when `dir[kz] < 0` to keep the winding), and the
/// shear constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayShear {
    pub origin: Vec3,
    pub kx: usize,
    pub ky: usize,
    pub kz: usize,
    pub sx: f32,
    pub sy: f32,
    pub sz: f32,
}

impl RayShear {
    pub fn new(ray: &Ray) -> RayShear {
        let d = ray.dir;
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        RayShear {
            origin: ray.origin,
            kx,
            ky,
            kz,
            sx: d[kx] / d[kz],
            sy: d[ky] / d[kz],
            sz: 1.0 / d[kz],
        }
    }
}

/// A triangle hit: the ray parameter and the barycentric weights of p0, p1, p2 (summing
/// to 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub b0: f32,
    pub b1: f32,
    pub b2: f32,
}

/// `p q - r t` with the products exact in `f64` and the difference rounded once, so its sign
/// is right (Woop et al. §4).
fn edge_f64(p: f32, q: f32, r: f32, t: f32) -> f32 {
    ((p as f64) * (q as f64) - (r as f64) * (t as f64)) as f32
}

/// The hit from edge functions `u, v, w`, their sum `det` and the sign-corrected scaled
/// distance `t_scaled / det_abs` that passed the interval test.
fn hit_from(u: f32, v: f32, w: f32, det: f32, t_scaled: f32, det_abs: f32) -> TriangleHit {
    let r = 1.0 / det;
    TriangleHit {
        t: t_scaled / det_abs,
        b0: u * r,
        b1: v * r,
        b2: w * r,
    }
}

/// The hit of the sheared ray with triangle (p0, p1, p2) for `t` in `[tmin, tmax]`, either
/// side facing (no culling).
pub fn intersect_triangle(
    s: &RayShear,
    p0: Vec3,
    p1: Vec3,
    p2: Vec3,
    tmin: f32,
    tmax: f32,
) -> Option<TriangleHit> {
    let (a, b, c) = (p0 - s.origin, p1 - s.origin, p2 - s.origin);
    let shear = |p: Vec3| (p[s.kx] - s.sx * p[s.kz], p[s.ky] - s.sy * p[s.kz]);
    let ((ax, ay), (bx, by), (cx, cy)) = (shear(a), shear(b), shear(c));
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    if u == 0.0 || v == 0.0 || w == 0.0 {
        u = edge_f64(cx, by, cy, bx);
        v = edge_f64(ax, cy, ay, cx);
        w = edge_f64(bx, ay, by, ax);
    }
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    let (az, bz, cz) = (s.sz * a[s.kz], s.sz * b[s.kz], s.sz * c[s.kz]);
    let t_scaled = u * az + v * bz + w * cz;
    // Compare t = T / det with the interval without dividing: flip signs so det > 0.
    let (t_scaled, det_abs) = if det < 0.0 {
        (-t_scaled, -det)
    } else {
        (t_scaled, det)
    };
    if t_scaled < tmin * det_abs || t_scaled > tmax * det_abs {
        return None;
    }
    Some(hit_from(u, v, w, det, t_scaled, det_abs))
}

/// Triangles per [`TrianglePack`]: the `f32` lanes of one SSE register.
pub const PACK_WIDTH: usize = 4;

/// Up to [`PACK_WIDTH`] triangles in structure-of-arrays form: `p[vertex][axis]` holds that
/// coordinate of every lane's vertex, so that the shear picks whole registers by axis.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct TrianglePack {
    p: [[Vec4; 3]; 3],
    /// Lanes that hold a triangle.
    used: BVec4A,
}

impl TrianglePack {
    /// The pack of `triangles` (at most [`PACK_WIDTH`]; more is a caller bug), in lane order.
    pub fn new(triangles: &[[Vec3; 3]]) -> TrianglePack {
        assert!(
            triangles.len() <= PACK_WIDTH,
            "too many triangles for a pack"
        );
        let mut p = [[Vec4::ZERO; 3]; 3];
        for (lane, t) in triangles.iter().enumerate() {
            for (vertex, corner) in t.iter().enumerate() {
                for axis in 0..3 {
                    p[vertex][axis][lane] = corner[axis];
                }
            }
        }
        let n = triangles.len();
        TrianglePack {
            p,
            used: BVec4A::new(n > 0, n > 1, n > 2, n > 3),
        }
    }
}

/// [`RayShear`] with its constants splat across lanes, the origin in shear axis order.
#[derive(Clone, Copy, Debug)]
pub struct PackShear {
    axes: [usize; 3],
    origin: [Vec4; 3],
    sx: Vec4,
    sy: Vec4,
    sz: Vec4,
}

impl PackShear {
    pub fn new(s: &RayShear) -> PackShear {
        let axes = [s.kx, s.ky, s.kz];
        PackShear {
            axes,
            origin: axes.map(|k| Vec4::splat(s.origin[k])),
            sx: Vec4::splat(s.sx),
            sy: Vec4::splat(s.sy),
            sz: Vec4::splat(s.sz),
        }
    }
}

/// What [`intersect_pack`] found: the lanes that hit within the interval and, per lane, the
/// quantities [`intersect_triangle`] derives its hit from.
#[derive(Clone, Copy, Debug)]
pub struct PackHits {
    /// Bit `i` set when lane `i` hits.
    pub mask: u32,
    u: Vec4,
    v: Vec4,
    w: Vec4,
    det: Vec4,
    t_scaled: Vec4,
    det_abs: Vec4,
}

impl PackHits {
    /// The hit of lane `lane` (a lane in `mask`), equal to [`intersect_triangle`]'s.
    pub fn hit(&self, lane: usize) -> TriangleHit {
        hit_from(
            self.u[lane],
            self.v[lane],
            self.w[lane],
            self.det[lane],
            self.t_scaled[lane],
            self.det_abs[lane],
        )
    }

    /// The lane and hit that testing the lanes one after another with [`intersect_triangle`]
    /// would end with, each test's `tmax` shortened to the hits before it (`tmax` is the one
    /// the pack was tested with, or shorter): the same choice among equal distances as a
    /// scalar loop over the triangles in lane order. Updates `tmax`.
    pub fn nearest(&self, tmax: &mut f32) -> Option<(usize, TriangleHit)> {
        let mut best = None;
        let mut mask = self.mask;
        while mask != 0 {
            let lane = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            // The pack passed this lane against a `tmax` no shorter; the tmin test is unchanged.
            if self.t_scaled[lane] > *tmax * self.det_abs[lane] {
                continue;
            }
            let h = self.hit(lane);
            *tmax = tmax.min(h.t);
            best = Some((lane, h));
        }
        best
    }
}

/// [`intersect_triangle`] on the four lanes of `pack` at once, for `t` in `[tmin, tmax]`.
/// Always inlined: its result is a dozen registers that a call would pass through memory.
#[inline(always)]
pub fn intersect_pack(s: &PackShear, pack: &TrianglePack, tmin: f32, tmax: f32) -> PackHits {
    let [kx, ky, kz] = s.axes;
    // The sheared vertex, lane-wise exactly the scalar `shear(p - origin)` and `sz * (p - o).z`.
    let vertex = |p: &[Vec4; 3]| {
        let (x, y, z) = (
            p[kx] - s.origin[0],
            p[ky] - s.origin[1],
            p[kz] - s.origin[2],
        );
        (x - s.sx * z, y - s.sy * z, s.sz * z)
    };
    let (ax, ay, az) = vertex(&pack.p[0]);
    let (bx, by, bz) = vertex(&pack.p[1]);
    let (cx, cy, cz) = vertex(&pack.p[2]);
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    let zero = Vec4::ZERO;
    let mut exact = (u.cmpeq(zero) | v.cmpeq(zero) | w.cmpeq(zero)) & pack.used;
    while exact.any() {
        let lane = exact.bitmask().trailing_zeros() as usize;
        exact.set(lane, false);
        let (ax, ay, bx, by, cx, cy) = (ax[lane], ay[lane], bx[lane], by[lane], cx[lane], cy[lane]);
        u[lane] = edge_f64(cx, by, cy, bx);
        v[lane] = edge_f64(ax, cy, ay, cx);
        w[lane] = edge_f64(bx, ay, by, ax);
    }
    let outside = (u.cmplt(zero) | v.cmplt(zero) | w.cmplt(zero))
        & (u.cmpgt(zero) | v.cmpgt(zero) | w.cmpgt(zero));
    let det = u + v + w;
    let t_scaled = u * az + v * bz + w * cz;
    let negative = det.cmplt(zero);
    let t_scaled = Vec4::select(negative, -t_scaled, t_scaled);
    let det_abs = Vec4::select(negative, -det, det);
    let miss = outside
        | det.cmpeq(zero)
        | t_scaled.cmplt(Vec4::splat(tmin) * det_abs)
        | t_scaled.cmpgt(Vec4::splat(tmax) * det_abs);
    let hit = pack.used & !miss;
    PackHits {
        mask: hit.bitmask(),
        u,
        v,
        w,
        det,
        t_scaled,
        det_abs,
    }
}

/// γₙ = n u / (1 - n u) with u = 2⁻²⁴ the unit round-off of f32 (Higham; pbrt-v3 §3.9.1).
fn gamma(n: u32) -> f32 {
    let u = f32::EPSILON * 0.5;
    (n as f32 * u) / (1.0 - n as f32 * u)
}

/// Floating-point operations behind the bound of the barycentric point, pbrt-v3 §3.9.5:
/// the barycentrics themselves and the weighted sum together are within γ₇.
const HIT_POINT_GAMMA: u32 = 7;

/// The barycentric hit point `b0 p0 + b1 p1 + b2 p2` in `f32`.
pub fn hit_point(hit: &TriangleHit, p0: Vec3, p1: Vec3, p2: Vec3) -> Vec3 {
    hit.b0 * p0 + hit.b1 * p1 + hit.b2 * p2
}

/// A box certain to contain the exact point of the triangle at the computed barycentrics:
/// the `f32` barycentric point widened by γ₇ (|b0 p0| + |b1 p1| + |b2 p2|) and rounded
/// outward by one ulp so that the widening itself cannot round inward. As in pbrt-v3
/// §3.9.5 the bound is on the distance to the surface (what the offset of a secondary
/// ray must escape), not on where along the surface the ray crossed it, which is
/// ill-conditioned at grazing angles.
pub fn hit_box(hit: &TriangleHit, p0: Vec3, p1: Vec3, p2: Vec3) -> Aabb {
    let p = hit_point(hit, p0, p1, p2);
    let abs_sum = (hit.b0 * p0).abs() + (hit.b1 * p1).abs() + (hit.b2 * p2).abs();
    let err = gamma(HIT_POINT_GAMMA) * abs_sum;
    Aabb::new((p - err).map(f32::next_down), (p + err).map(f32::next_up))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_a_triangle_with_closed_form_t_and_barycentrics() {
        let (p0, p1, p2) = (
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::new(1.0, 0.0, 2.0),
            Vec3::new(0.0, 1.0, 2.0),
        );
        let ray = Ray::new(Vec3::new(0.25, 0.5, 0.0), Vec3::new(0.0, 0.0, 0.5));
        let h = intersect_triangle(&RayShear::new(&ray), p0, p1, p2, 0.0, f32::INFINITY).unwrap();
        assert_eq!(h.t, 4.0); // z = 2 at t = 2 / 0.5
        assert_eq!((h.b0, h.b1, h.b2), (0.25, 0.25, 0.5));
        assert!(intersect_triangle(&RayShear::new(&ray), p0, p1, p2, 0.0, 3.9).is_none());
        let miss = Ray::new(Vec3::new(0.75, 0.5, 0.0), Vec3::Z);
        assert!(
            intersect_triangle(&RayShear::new(&miss), p0, p1, p2, 0.0, f32::INFINITY).is_none()
        );
    }

    /// A small grid mesh with shared edges and vertices, some corners exactly on the ray
    /// origins' axes so that edge functions round to 0 and take the `f64` path.
    #[test]
    fn pack_equals_scalar_on_edges_vertices_and_random_rays() {
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut rnd = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        // A 3×3 grid of quads (18 triangles) over [0,3]² bent in z, sharing every inner
        // edge and vertex, plus one degenerate (zero area) triangle.
        let z = |i: usize, j: usize| ((i * 7 + j * 3) % 5) as f32 * 0.25;
        let v = |i: usize, j: usize| Vec3::new(i as f32, j as f32, 2.0 + z(i, j));
        let mut tris = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                tris.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
                tris.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
            }
        }
        tris.push([v(0, 0), v(1, 1), v(2, 2)]);
        let mut targets: Vec<Vec3> = tris.iter().flatten().copied().collect();
        for t in &tris {
            for k in 0..3 {
                targets.push(0.5 * (t[k] + t[(k + 1) % 3]));
            }
        }
        for _ in 0..2000 {
            targets.push(Vec3::new(3.4 * rnd() - 0.2, 3.4 * rnd() - 0.2, 2.0 + rnd()));
        }
        let mut checked_hits = 0;
        for (n, &target) in targets.iter().enumerate() {
            // Origins straight above (axis-aligned rays through vertices and edges) and
            // oblique ones, some from below so that the shear swaps axes.
            let origin = match n % 3 {
                0 => Vec3::new(target.x, target.y, 10.0),
                1 => Vec3::new(-1.0 + 5.0 * rnd(), -1.0 + 5.0 * rnd(), 6.0),
                _ => Vec3::new(-1.0 + 5.0 * rnd(), -1.0 + 5.0 * rnd(), -3.0),
            };
            let ray = Ray::new(origin, target - origin);
            let tmax = if n % 5 == 0 {
                0.9 + 0.2 * rnd()
            } else {
                f32::INFINITY
            };
            let scalar_shear = RayShear::new(&ray);
            let shear = PackShear::new(&scalar_shear);
            for chunk in tris.chunks(PACK_WIDTH) {
                let hits = intersect_pack(&shear, &TrianglePack::new(chunk), ray.tmin, tmax);
                // Each lane against the scalar test with the same interval.
                for (lane, [a, b, c]) in chunk.iter().enumerate() {
                    let scalar = intersect_triangle(&scalar_shear, *a, *b, *c, ray.tmin, tmax);
                    let simd = (hits.mask >> lane & 1 == 1).then(|| hits.hit(lane));
                    assert_eq!(simd, scalar, "ray {ray:?}, triangle {:?}", chunk[lane]);
                    checked_hits += usize::from(scalar.is_some());
                }
                assert_eq!(hits.mask >> chunk.len(), 0, "an unused lane hit");
                // The sequential choice: a scalar loop shortening tmax as it goes.
                let mut limit = tmax;
                let mut expected = None;
                for (lane, [a, b, c]) in chunk.iter().enumerate() {
                    if let Some(h) = intersect_triangle(&scalar_shear, *a, *b, *c, ray.tmin, limit)
                    {
                        limit = limit.min(h.t);
                        expected = Some((lane, h));
                    }
                }
                let mut pack_limit = tmax;
                assert_eq!(hits.nearest(&mut pack_limit), expected);
                assert_eq!(pack_limit, limit);
            }
        }
        assert!(checked_hits > 1000, "only {checked_hits} hits compared");
    }

    #[test]
    fn hit_box_contains_the_exact_point() {
        // A skewed triangle far from the origin; the exact hit is computed in f64.
        let (p0, p1, p2) = (
            Vec3::new(1000.1, -3.7, 50.3),
            Vec3::new(1001.9, 2.2, 51.7),
            Vec3::new(999.3, 0.4, 49.1),
        );
        let mut state = 12345u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..2000 {
            let (b1, b2) = (rnd() * 0.5, rnd() * 0.5);
            let target = p0 * (1.0 - b1 - b2) + p1 * b1 + p2 * b2;
            let origin = Vec3::new(990.0, -10.0 + 20.0 * rnd(), 40.0 + 20.0 * rnd());
            let ray = Ray::new(origin, target - origin);
            let Some(h) = intersect_triangle(&RayShear::new(&ray), p0, p1, p2, 0.0, f32::INFINITY)
            else {
                continue;
            };
            // Exact point of the triangle at the computed barycentrics, in f64.
            let b = [h.b0, h.b1, h.b2].map(f64::from);
            let sum = b[0] + b[1] + b[2];
            let exact = (p0.as_dvec3() * b[0] + p1.as_dvec3() * b[1] + p2.as_dvec3() * b[2]) / sum;
            let b = hit_box(&h, p0, p1, p2);
            let inside =
                (0..3).all(|k| (b.min[k] as f64) <= exact[k] && exact[k] <= (b.max[k] as f64));
            assert!(inside, "exact {exact} outside {b:?}");
        }
    }
}
