//! The triviality test for a secondary ray and the surface it leaves (after LG90 §6,
//! "improved treatment of secondary rays"): a cell of the surface of origin around the
//! hit that the ray provably does not cross at or after `tmin`, so the search drops it
//! instead of descending to the end game around the ray's origin.
//!
//! Why: a secondary ray starts a few ulps off its surface (Dammertz §2.4), so every
//! sub-patch around its origin has a box that holds the origin, down to boxes of the end
//! game's size. Before this test, searches of the surface of origin that found nothing were
//! 35 % of the teapot's splits. LG90's tests need Toth's interval bounds on `t`; here the
//! bound comes from the mean value theorem on the patch, as follows.
//!
//! Frame. `e1`, `e2` are built from the `f32` direction `d` so that `e1 · d = e2 · d = 0`
//! holds exactly (`e1 = d_k x_i - d_i x_k`, `e2 = d_k x_j - d_j x_k` for the largest
//! component `k`); a point `p` has coordinates `x = e1 · (p - o)`, `y = e2 · (p - o)`,
//! `z = d · (p - o)`. A point of the line `o + t d` has `x = y = 0` and `z = t |d|²`.
//!
//! Bound. Let `c` be the hit's `(u, v)` and `Q` a cell of width `h` holding it. Over `Q`
//! the Jacobian `J` of `(x, y, z)` with respect to `(u, v)` lies within `R h` of `J(c)`,
//! `R` from bounds on the second derivatives over the whole patch (the control points of
//! the second hodographs, by the convex hull property). For a crossing `p*` in `Q` and
//! `Δ = p* - c` the mean value theorem, per coordinate, gives `-(x_c, y_c) = A Δ` and
//! `z* - z_c = a Δ` with `A` within `R h` of `J_xy(c)` and `a` of `J_z(c)` (`Q` is convex,
//! so the segment from `c` to `p*` stays in it). With `C` the inverse of `J_xy(c)`,
//! `β ≥ ‖I − C A‖∞ < 1` gives `‖Δ‖∞ ≤ ‖C (x_c, y_c)‖∞ / (1 − β)`; with `M = J_z(c) C`,
//! `z* = z_c − M (x_c, y_c) + (a − M A) Δ ≤ z_c − M (x_c, y_c) + W ‖Δ‖∞`, `W` the sum over
//! both columns of the largest magnitude in `a − M A`. When that bound is below
//! `tmin |d|²`, no crossing in `Q` lies on the ray: `Q` is trivial. The first term is the
//! origin's height above the tangent plane at the hit (negative by the ulps the origin
//! was pushed out by, in the direction the ray leaves); `β` and `W` grow linearly with
//! `h`, so the test holds on large cells of flat or gently curved surfaces and fails,
//! leaving the search as it was, where the ray grazes the surface or the patch folds.
//!
//! Cost. The point and both tangents at `c` from the Bernstein weights, the second
//! differences of the net in world coordinates (bounded in the frame coordinate-wise,
//! `|e · w| ≤ |e| · max |w|`), then a few operations per cell size. (Bounding `J` over each
//! cell by its own hodographs instead, on the `f64` net halved towards `c`, gave cells
//! about one level larger, but the halvings took a third of the teapot's render.)
//!
//! Exactness. The test is about the exact surface of the `f32` control net the kernel
//! searches (read into `f64` without rounding), and every `f64` rounding of the test is
//! covered by [`ROUNDING`] of the scale `max(|o|, |net|) |d|`, thousands of times the
//! rounding and far below the ulps of `f32` that separate the origin from the surface.
//! A dropped cell holds no crossing of the exact surface; what the kernel would have found
//! there is a box around the ray's own origin. The tests below check every dropped cell
//! against the `f64` reference on curved patches that rays leaving them cross again.
//!
//! Where it runs: on the SSE/AVX2 paths (CPUs without AVX-512, `PATCHTRACE_NO_AVX512`),
//! whose world-space search of the origin's surface is long, and for patches the AVX-512
//! path does not take. On the AVX-512 path the ray-space search with jumps descends to the
//! origin in about the time the test takes, so it is not asked there.

use glam::DVec3;

use super::bicubic::Net;
use super::bilinear::BilinearNet;
use super::float::GRay;
use super::param::ParamCell;
use super::prepared::Prepared;

/// Deepest cell level (in u and in v) tried around the hit: below 2^-12 of the patch the
/// descent the test saves is a few splits.
const TRIVIAL_LEVELS: u8 = 12;

/// The `f64` rounding allowance, relative to `max(|o|, |net|) |d|` (both in the max
/// norm): the test's arithmetic is a few dozen `f64` operations on values of that scale,
/// each rounding by 2^-53 of it, and the margin it must detect (the origin's offset) is
/// a few `f32` ulps, 2^-23 of it or more.
const ROUNDING: f64 = 1.0 / (1u64 << 40) as f64;

/// A control net of degree at most 3 × 3 in `f64`, one array per coordinate, point
/// `(i, j)` at `i + 4 j` (zero beyond the degree).
struct SmallNet {
    xyz: [[f64; 16]; 3],
    nu: usize,
    nv: usize,
}

/// The Bernstein weights of degree `n - 1` at `s` and their derivatives (zero from `n`).
fn bernstein(n: usize, s: f64) -> ([f64; 4], [f64; 4]) {
    let r = 1.0 - s;
    match n {
        2 => ([r, s, 0.0, 0.0], [-1.0, 1.0, 0.0, 0.0]),
        3 => (
            [r * r, 2.0 * r * s, s * s, 0.0],
            [-2.0 * r, 2.0 * (r - s), 2.0 * s, 0.0],
        ),
        4 => (
            [r * r * r, 3.0 * r * r * s, 3.0 * r * s * s, s * s * s],
            [
                -3.0 * r * r,
                3.0 * r * (r - 2.0 * s),
                3.0 * s * (2.0 * r - s),
                3.0 * s * s,
            ],
        ),
        _ => ([1.0, 0.0, 0.0, 0.0], [0.0; 4]),
    }
}

impl SmallNet {
    /// The net the kernel searches for `data`, if the test supports it (integral, degree
    /// at most 3 in each direction).
    fn of(data: &Prepared) -> Option<SmallNet> {
        Some(match data {
            // A ray leaving a plane never meets it again: the closed form drops the whole
            // patch before this test.
            Prepared::Affine(_) => return None,
            Prepared::Bicubic(n) => SmallNet::fill(4, 4, |i, j| Net::point(n, i, j)),
            Prepared::Bilinear(BilinearNet { xyz }) => {
                SmallNet::fill(2, 2, |i, j| xyz.map(|c| c[i + 2 * j]))
            }
            Prepared::General { net: h, shape } => {
                if shape.rational || shape.nu > 4 || shape.nv > 4 {
                    return None;
                }
                SmallNet::fill(shape.nu, shape.nv, |i, j| {
                    let p = h[i + shape.nu * j];
                    [p[0], p[1], p[2]]
                })
            }
        })
    }

    #[inline(always)]
    fn fill(nu: usize, nv: usize, point: impl Fn(usize, usize) -> [f32; 3]) -> SmallNet {
        let mut xyz = [[0.0; 16]; 3];
        for j in 0..nv {
            for i in 0..nu {
                for (c, x) in point(i, j).into_iter().enumerate() {
                    xyz[c][i + 4 * j] = f64::from(x);
                }
            }
        }
        SmallNet { xyz, nu, nv }
    }

    /// The largest coordinate magnitude.
    fn scale(&self) -> f64 {
        self.xyz.iter().flatten().fold(0.0, |s, x| s.max(x.abs()))
    }

    /// The point and its derivatives in u and v at `(u, v)`, from the Bernstein weights.
    fn eval(&self, u: f64, v: f64) -> [DVec3; 3] {
        let ((bu, du), (bv, dv)) = (bernstein(self.nu, u), bernstein(self.nv, v));
        let mut out = [DVec3::ZERO; 3];
        for (c, coords) in self.xyz.iter().enumerate() {
            let (mut p, mut pu, mut pv) = (0.0, 0.0, 0.0);
            for j in 0..4 {
                let row = &coords[4 * j..4 * j + 4];
                let (mut r, mut t) = (0.0, 0.0);
                for i in 0..4 {
                    r += bu[i] * row[i];
                    t += du[i] * row[i];
                }
                p += bv[j] * r;
                pu += bv[j] * t;
                pv += dv[j] * r;
            }
            out[0][c] = p;
            out[1][c] = pu;
            out[2][c] = pv;
        }
        out
    }

    /// Per world coordinate, the largest magnitudes of the second derivatives `(∂uu, ∂uv,
    /// ∂vv)` over the whole patch: the largest of the second hodographs' control points.
    fn second_derivative_bounds(&self) -> [DVec3; 3] {
        let (nu, nv) = (self.nu, self.nv);
        let (du, dv) = ((nu - 1) as f64, (nv - 1) as f64);
        // A NaN coordinate is skipped here, but it makes the point at the hit NaN too (every
        // Bernstein weight multiplies it), and no NaN bound passes the test.
        let larger = |m: f64, x: f64| if x.abs() > m { x.abs() } else { m };
        let mut k = [DVec3::ZERO; 3];
        for (c, b) in self.xyz.iter().enumerate() {
            let (mut uu, mut uv, mut vv) = (0f64, 0f64, 0f64);
            for j in 0..nv {
                let row = &b[4 * j..4 * j + 4];
                for i in 0..nu.saturating_sub(2) {
                    uu = larger(uu, row[i + 2] - 2.0 * row[i + 1] + row[i]);
                }
            }
            for j in 0..nv - 1 {
                let (row, next) = (&b[4 * j..4 * j + 4], &b[4 * j + 4..4 * j + 8]);
                for i in 0..nu - 1 {
                    uv = larger(uv, next[i + 1] - row[i + 1] - next[i] + row[i]);
                }
            }
            for j in 0..nv.saturating_sub(2) {
                for i in 0..nu {
                    vv = larger(vv, b[i + 4 * j + 8] - 2.0 * b[i + 4 * j + 4] + b[i + 4 * j]);
                }
            }
            k[0][c] = uu * du * (du - 1.0);
            k[1][c] = uv * du * dv;
            k[2][c] = vv * dv * (dv - 1.0);
        }
        k
    }
}

/// The largest cell around `(u, v)` (levels 0 to [`TRIVIAL_LEVELS`] in both directions)
/// in which the patch `data` provably has no crossing with `ray` at or after `ray.tmin`
/// (see the module documentation), or `None`.
pub(crate) fn trivial_cell(
    data: &Prepared,
    ray: &GRay<f32>,
    (u, v): (f64, f64),
) -> Option<ParamCell> {
    if !(0.0..=1.0).contains(&u) || !(0.0..=1.0).contains(&v) {
        return None;
    }
    let net = SmallNet::of(data)?;
    let o = DVec3::from_array(ray.origin.map(f64::from));
    let d = DVec3::from_array(ray.dir.map(f64::from));
    let k = d.abs().max_position();
    let across = |m: usize| {
        let mut e = DVec3::ZERO;
        e[m] = d[k];
        e[k] = -d[m];
        e
    };
    let axes = [across((k + 1) % 3), across((k + 2) % 3), d];
    let eps = ROUNDING * net.scale().max(o.abs().max_element()) * d.abs().max_element();
    if !eps.is_finite() || eps == 0.0 {
        return None;
    }
    let [p, pu, pv] = net.eval(u, v);
    let in_frame = |w: DVec3| DVec3::new(axes[0].dot(w), axes[1].dot(w), axes[2].dot(w));
    // |e · w| ≤ |e| · max |w| coordinate-wise: the second derivatives' bounds in the frame.
    let bound_in_frame = |w: DVec3| {
        DVec3::new(
            axes[0].abs().dot(w),
            axes[1].abs().dot(w),
            axes[2].abs().dot(w),
        )
    };
    let [kuu, kuv, kvv] = net.second_derivative_bounds().map(bound_in_frame);
    let bound = Bound::new(
        in_frame(p - o),
        [in_frame(pu), in_frame(pv)],
        [kuu + kuv, kuv + kvv],
        eps,
    )?;
    let limit = f64::from(ray.tmin) * d.length_squared();
    let limit = limit - limit.abs() * ROUNDING;
    // The bound grows with the cell: bisect for the coarsest level that passes.
    let passes = |level: u8| bound.z_max(super::param::dyadic_width(level)) < limit;
    if !passes(TRIVIAL_LEVELS) {
        return None;
    }
    // Levels below `coarsest` fail, `level` passes.
    let (mut coarsest, mut level) = (0, TRIVIAL_LEVELS);
    while coarsest < level {
        let mid = (coarsest + level) / 2;
        if passes(mid) {
            level = mid;
        } else {
            coarsest = mid + 1;
        }
    }
    let cells = (1u64 << level) as f64;
    let index = |s: f64| ((s * cells) as u64).min((1u64 << level) - 1);
    Some(ParamCell::ROOT.sub_cell([level; 2], [index(u), index(v)]))
}

/// The bound of the module documentation as a function of the cell width `h`: what does
/// not depend on `h` computed once.
struct Bound {
    /// `z_c − M (x_c, y_c)` plus its rounding allowance.
    plane: f64,
    /// `‖C (x_c, y_c)‖∞` with the allowance for the rounding of `(x_c, y_c)`.
    step: f64,
    /// `‖I − C J_xy(c)‖∞`, the rounding of the inverse, plus the allowance for `J`'s.
    beta0: f64,
    /// Per unit of `h`: the growth of `β`.
    beta1: f64,
    /// `W` at `h = 0` (the rounding of `M` and the allowance for `J`) and per unit of `h`.
    w0: f64,
    w1: f64,
}

impl Bound {
    /// From the hit point `c` and the Jacobian `j = [∂u, ∂v]` at it (each column's
    /// coordinates x, y, z in the frame), the per-column growth `r` of the Jacobian's
    /// coordinates per unit of cell width, and the rounding allowance `eps` of every
    /// computed coordinate. `None` where the tangents seen along the ray are degenerate.
    fn new(c: DVec3, j: [DVec3; 2], r: [DVec3; 2], eps: f64) -> Option<Bound> {
        let det = j[0].x * j[1].y - j[1].x * j[0].y;
        if !det.is_normal() {
            return None;
        }
        // C = J_xy(c)^-1, rows r: C[r] · (x, y).
        let inv = [[j[1].y / det, -j[1].x / det], [-j[0].y / det, j[0].x / det]];
        let (mut beta0, mut beta1) = (0f64, 0f64);
        for (row, ci) in inv.iter().enumerate() {
            let (mut b0, mut b1) = (0.0, 0.0);
            for (col, jc) in j.iter().enumerate() {
                let identity = if row == col { 1.0 } else { 0.0 };
                let (ca, cb) = (ci[0].abs(), ci[1].abs());
                b0 += (identity - (ci[0] * jc.x + ci[1] * jc.y)).abs() + (ca + cb) * eps;
                b1 += ca * r[col].x + cb * r[col].y;
            }
            beta0 = beta0.max(b0);
            beta1 = beta1.max(b1);
        }
        let step = inv
            .iter()
            .map(|ci| (ci[0] * c.x + ci[1] * c.y).abs() + (ci[0].abs() + ci[1].abs()) * eps)
            .fold(0.0, f64::max);
        let m = [
            j[0].z * inv[0][0] + j[1].z * inv[1][0],
            j[0].z * inv[0][1] + j[1].z * inv[1][1],
        ];
        let (ma, mb) = (m[0].abs(), m[1].abs());
        let (mut w0, mut w1) = (0.0, 0.0);
        for (jc, rc) in j.iter().zip(&r) {
            w0 += (jc.z - (m[0] * jc.x + m[1] * jc.y)).abs() + (1.0 + ma + mb) * eps;
            w1 += rc.z + ma * rc.x + mb * rc.y;
        }
        let plane = c.z - (m[0] * c.x + m[1] * c.y);
        let allowance = ROUNDING * (c.z.abs() + (m[0] * c.x).abs() + (m[1] * c.y).abs())
            + (1.0 + ma + mb) * eps;
        Some(Bound {
            plane: plane + allowance,
            step,
            beta0,
            beta1,
            w0,
            w1,
        })
    }

    /// An upper bound on `z` of every crossing of the line with a cell of width `h`
    /// around the hit, infinite where the bound does not apply (`β ≥ 1`).
    fn z_max(&self, h: f64) -> f64 {
        let beta = (self.beta0 + self.beta1 * h) * (1.0 + ROUNDING);
        // Also refuses a NaN β.
        if beta.partial_cmp(&1.0) != Some(std::cmp::Ordering::Less) {
            return f64::INFINITY;
        }
        let delta = self.step / (1.0 - beta);
        let spread = (self.w0 + self.w1 * h) * delta;
        self.plane + spread * (1.0 + ROUNDING)
    }
}

#[cfg(test)]
mod tests {
    use glam::{DVec3, Vec3};

    use super::*;
    use crate::geom::{Aabb, BezierPatch};
    use crate::kernel::secondary::secondary_origin;
    use crate::kernel::subdivision::{PreparedPatch, SubdivisionConfig, intersect_f64};

    /// A bicubic patch over [0,1]² with heights `h(x, y)` at its control points, each
    /// coordinate rounded to `f32` so that the `f64` reference searches the kernel's net.
    fn height_patch(h: impl Fn(f64, f64) -> f64) -> BezierPatch {
        let pts: Vec<DVec3> = (0..16)
            .map(|k| {
                let (x, y) = ((k % 4) as f64 / 3.0, (k / 4) as f64 / 3.0);
                DVec3::new(x, y, h(x, y)).as_vec3().as_dvec3()
            })
            .collect();
        BezierPatch::from_points(3, 3, &pts).unwrap()
    }

    /// The patch restricted to `cell` by halving in `f64` (exact here: the halvings of
    /// `f32` coordinates a few levels deep need few bits).
    fn restricted(patch: &BezierPatch, cell: ParamCell) -> BezierPatch {
        let (u0, v0, wu, wv) = cell.bounds();
        let (lu, lv) = cell.levels();
        let mut p = patch.clone();
        for k in 0..lu {
            let (lo, hi) = p.split_u();
            let bit = (u0 / wu) as u64 >> (lu - 1 - k) & 1;
            p = if bit == 1 { hi } else { lo };
        }
        for k in 0..lv {
            let (lo, hi) = p.split_v();
            let bit = (v0 / wv) as u64 >> (lv - 1 - k) & 1;
            p = if bit == 1 { hi } else { lo };
        }
        p
    }

    /// Secondary rays leaving `patch` from a grid of hits as the renderer makes them (a
    /// box of a few ulps around the surface point, the origin at its corner by the normal's
    /// octant, 7 ulps out), in many directions of the hemisphere they leave into, down to
    /// 1° from grazing. Every cell the test drops is searched by the `f64` reference for a
    /// crossing at `t ≥ 0`: there must be none. Returns (rays, rays with a dropped cell,
    /// rays whose origin is the whole patch, rays that re-hit the patch).
    fn check(patch: &BezierPatch) -> (usize, usize, usize, usize) {
        let prepared = PreparedPatch::new(patch);
        let cfg = SubdivisionConfig::default();
        let (mut rays, mut dropped, mut whole, mut rehit) = (0, 0, 0, 0);
        for a in 0..9 {
            for b in 0..9 {
                let (u, v) = ((a as f64 + 0.5) / 9.0, (b as f64 + 0.5) / 9.0);
                let p = patch.eval(u, v);
                let n = patch.normal(u, v);
                let grow = |x: f64, up: bool| {
                    let x = x as f32;
                    (0..3).fold(x, |y, _| if up { y.next_up() } else { y.next_down() })
                };
                let hit_box = Aabb::new(
                    Vec3::new(grow(p.x, false), grow(p.y, false), grow(p.z, false)),
                    Vec3::new(grow(p.x, true), grow(p.y, true), grow(p.z, true)),
                );
                let t1 = n.any_orthonormal_vector();
                let t2 = n.cross(t1);
                for outside in [true, false] {
                    let side = if outside { n } else { -n };
                    let o = secondary_origin(&hit_box, n.as_vec3(), outside, 7);
                    for elevation in [1.0f64, 5.0, 20.0, 45.0, 89.0] {
                        for azimuth in 0..8 {
                            let (e, z) = (elevation.to_radians(), azimuth as f64 * 0.785);
                            let d = side * e.sin() + (t1 * z.cos() + t2 * z.sin()) * e.cos();
                            let ray =
                                GRay::new(o.to_array(), d.as_vec3().to_array(), 0.0, f32::INFINITY);
                            let (o64, d64) = (o.as_dvec3(), d.as_vec3().as_dvec3());
                            rays += 1;
                            let inf = f64::INFINITY;
                            rehit += intersect_f64(patch, o64, d64, 0.0, inf, &cfg, None).is_some()
                                as usize;
                            let Some(cell) = trivial_cell(&prepared.data, &ray, (u, v)) else {
                                continue;
                            };
                            dropped += 1;
                            whole += (cell == ParamCell::ROOT) as usize;
                            let sub = restricted(patch, cell);
                            let h = intersect_f64(&sub, o64, d64, 0.0, inf, &cfg, None);
                            assert!(h.is_none(), "({u}, {v}) {d:?} {cell:?}: {h:?}");
                        }
                    }
                }
            }
        }
        (rays, dropped, whole, rehit)
    }

    #[test]
    fn a_plane_is_trivial_as_a_whole() {
        let (rays, dropped, whole, rehit) = check(&height_patch(|x, y| 0.3 * x - 0.2 * y + 1.0));
        assert_eq!((dropped, whole, rehit), (rays, rays, 0));
    }

    /// A bowl and a saddle: rays leaving the bowl's slopes towards its middle cross it
    /// again, and the test must leave those crossings to the search.
    #[test]
    fn dropped_cells_hold_no_crossing_on_curved_patches() {
        let bowl = height_patch(|x, y| 3.0 * ((x - 0.5).powi(2) + (y - 0.5).powi(2)));
        let (rays, dropped, _, rehit) = check(&bowl);
        assert!(
            rehit > rays / 20,
            "{rehit} of {rays} rays cross the bowl again"
        );
        assert!(dropped > rays / 2, "{dropped} of {rays}");
        let saddle = height_patch(|x, y| 2.0 * (x - 0.5) * (y - 0.5) + 5.0);
        let (rays, dropped, _, _) = check(&saddle);
        assert!(dropped > rays / 2, "{dropped} of {rays}");
    }
}
