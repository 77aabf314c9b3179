//! Whitted ray tracing (Whitted 1980): ambient, Lambert and a Phong or Blinn highlight per
//! light with shadow rays, mirror reflection, and refraction by Snell's law with total
//! internal reflection and Schlick's Fresnel approximation. Surfaces are shaded two-sided.
//!
//! Secondary rays start at a corner of the hit box chosen by the normal's octant, moved a
//! fixed number of ulps outward (Dammertz §2.4): there is no scene-dependent epsilon here.

use glam::{Vec3, Vec4};

use super::plan::{EffectPlan, MAX_TREE_RAYS};
use super::stats::{RayKind, RayTally};
use crate::accel::scene::{QueryStats, SceneGeometry, SceneHit};
use crate::geom::Ray;
use crate::kernel::{Kernel, SurfaceOrigin};
use crate::scene::{Light, Scene};

/// Settings that apply to every ray of a render.
#[derive(Clone, Copy, Debug)]
pub struct TraceSettings {
    pub precision: Kernel,
    /// Ulps by which secondary ray origins are pushed off the hit box (Dammertz §2.4.2).
    pub ulps: u32,
    pub plan: EffectPlan,
}

/// Shades rays against a prepared scene.
pub struct Integrator<'a> {
    pub scene: &'a Scene,
    pub geometry: &'a SceneGeometry,
    pub settings: TraceSettings,
}

/// Where a ray sits in its primary ray's tree: path depth (primary = 1) and weight, the
/// largest channel of the product of the coefficients its contribution is scaled by.
#[derive(Clone, Copy, Debug)]
struct Branch {
    depth: u32,
    weight: f32,
}

/// What one primary ray's tree may still spend, and where its statistics go.
struct Work<'t> {
    tally: &'t mut RayTally,
    rays_left: u32,
}

impl Integrator<'_> {
    /// Colour and coverage (alpha 1 on geometry, 0 on the background) of a primary ray.
    pub fn primary(&self, ray: &Ray, tally: &mut RayTally) -> Vec4 {
        let precision = self.settings.precision;
        let mut work = Work {
            tally,
            rays_left: MAX_TREE_RAYS,
        };
        let root = Branch {
            depth: 1,
            weight: 1.0,
        };
        let (color, hit) = self.radiance(ray, &precision, RayKind::Primary, root, &mut work);
        color.extend(if hit { 1.0 } else { 0.0 })
    }

    /// Radiance of a secondary ray leaving a surface at `from` whose contribution is scaled
    /// by `coefficient`, or black, counted as cut, when its weight falls below the plan's
    /// [`min_weight`](EffectPlan::min_weight) (adaptive depth control, POV-Ray's
    /// `adc_bailout`) or the tree has spent [`MAX_TREE_RAYS`].
    fn secondary(
        &self,
        ray: &Ray,
        precision: &Kernel,
        kind: RayKind,
        (from, coefficient): (Branch, f32),
        work: &mut Work,
    ) -> Vec3 {
        let branch = Branch {
            depth: from.depth + 1,
            weight: from.weight * coefficient,
        };
        if branch.weight < self.settings.plan.min_weight || work.rays_left == 0 {
            work.tally.cut_ray();
            return Vec3::ZERO;
        }
        self.radiance(ray, precision, kind, branch, work).0
    }

    /// Radiance along `ray`, traced by `precision` (for secondary rays,
    /// [`Kernel::leaving`] the surface they start on), which is of the given kind at
    /// `branch` of its tree, and whether it hit anything.
    fn radiance(
        &self,
        ray: &Ray,
        precision: &Kernel,
        kind: RayKind,
        branch: Branch,
        work: &mut Work,
    ) -> (Vec3, bool) {
        work.rays_left = work.rays_left.saturating_sub(1);
        let tally = &mut *work.tally;
        let mut q = QueryStats::default();
        let hit = self.geometry.intersect(ray, precision, &mut q);
        tally.record(kind, &q);
        let Some(hit) = hit else {
            return (self.scene.background, false);
        };
        let object = &self.scene.objects[hit.object as usize];
        let m = &self.scene.materials[object.material];
        let d = ray.dir.normalize();
        let n_geo = hit.normal.as_vec3();
        // Two-sided: the side the ray came from decides by the geometric normal; shading
        // uses the shading normal turned to that side, secondary rays leave by the
        // geometric one so they really leave the surface.
        let outside = n_geo.dot(d) < 0.0;
        let n_out = if outside { n_geo } else { -n_geo };
        let n_shade = hit.shading_normal.as_vec3();
        let n = if n_shade.dot(n_out) < 0.0 {
            -n_shade
        } else {
            n_shade
        };
        let view = -d;
        let plan = &self.settings.plan;
        let ulps = self.settings.ulps;
        let opaque = 1.0 - m.transmit.min(1.0);
        let leaving = self
            .settings
            .precision
            .leaving(hit.primitive.map(|primitive| SurfaceOrigin {
                primitive,
                u: hit.u,
                v: hit.v,
            }));

        let mut color = self.scene.ambient * m.diffuse * opaque;
        let above = hit.secondary_origin(n_out, true, ulps);
        for light in &self.scene.lights {
            let (to_light, tmax, intensity) = match *light {
                Light::Point {
                    position,
                    intensity,
                } => (position.as_vec3() - above, 1.0, intensity),
                Light::Directional {
                    direction,
                    intensity,
                } => (-direction.as_vec3(), f32::INFINITY, intensity),
            };
            let l = to_light.normalize();
            let n_dot_l = n.dot(l);
            if n_dot_l.is_nan() || n_dot_l <= 0.0 {
                continue; // the light is behind the surface: no shadow ray needed
            }
            if plan.shadows {
                let shadow = Ray {
                    origin: above,
                    dir: to_light,
                    tmin: 0.0,
                    tmax,
                };
                let mut q = QueryStats::default();
                let blocked = self.geometry.occluded(&shadow, &leaving, &mut q);
                work.tally.record(RayKind::Shadow, &q);
                if blocked {
                    continue;
                }
            }
            color += m.diffuse * opaque * n_dot_l * intensity;
            if m.specular > 0.0 {
                let highlight = if m.blinn {
                    n.dot((l + view).normalize())
                } else {
                    reflect(-l, n).dot(view)
                };
                if highlight > 0.0 {
                    color += m.specular * highlight.powf(m.shininess) * intensity;
                }
            }
        }

        if branch.depth < plan.max_depth {
            if m.reflect > 0.0 && plan.reflection {
                let r = Ray::new(above, reflect(d, n));
                let kind = RayKind::Reflection;
                color += m.reflect * self.secondary(&r, &leaving, kind, (branch, m.reflect), work);
            }
            if m.transmit > 0.0 && plan.refraction {
                let through = self.transmitted(
                    d,
                    n,
                    n_out,
                    outside,
                    m.ior,
                    (&hit, &leaving),
                    (branch, m.transmit),
                    work,
                );
                color += m.transmit * through;
            }
        }
        (color, true)
    }

    /// Light through a transmissive surface: refraction weighted by 1 − Fresnel, plus the
    /// Fresnel reflection; all reflection under total internal reflection. `n` is the
    /// shading normal and `n_out` the geometric one, both on the incoming side; the rays
    /// leave `hit` and are traced by `leaving`, from `from`, scaled by `transmit`.
    #[allow(clippy::too_many_arguments)]
    fn transmitted(
        &self,
        d: Vec3,
        n: Vec3,
        n_out: Vec3,
        entering: bool,
        ior: f32,
        (hit, leaving): (&SceneHit, &Kernel),
        (from, transmit): (Branch, f32),
        work: &mut Work,
    ) -> Vec3 {
        let ulps = self.settings.ulps;
        let eta = if entering { 1.0 / ior } else { ior };
        let cos_i = -d.dot(n);
        let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
        let reflected = Ray::new(hit.secondary_origin(n_out, true, ulps), reflect(d, n));
        if k < 0.0 {
            let weight = (from, transmit);
            return self.secondary(&reflected, leaving, RayKind::Reflection, weight, work);
        }
        let t_dir = eta * d + (eta * cos_i - k.sqrt()) * n;
        // Schlick uses the cosine on the optically thinner side.
        let cos = if entering { cos_i } else { k.sqrt() };
        let f = schlick(cos, ior);
        let refracted = Ray::new(hit.secondary_origin(n_out, false, ulps), t_dir);
        let weight = (from, transmit * (1.0 - f));
        let through = self.secondary(&refracted, leaving, RayKind::Refraction, weight, work);
        let weight = (from, transmit * f);
        let mirror = self.secondary(&reflected, leaving, RayKind::Reflection, weight, work);
        (1.0 - f) * through + f * mirror
    }
}

/// Mirror direction of `d` about the plane with normal `n`.
fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - 2.0 * d.dot(n) * n
}

/// Schlick's approximation of the Fresnel reflectance between air and a medium of index
/// `ior`, for the cosine of the angle on the air side.
fn schlick(cos: f32, ior: f32) -> f32 {
    let r0 = ((1.0 - ior) / (1.0 + ior)).powi(2);
    r0 + (1.0 - r0) * (1.0 - cos.clamp(0.0, 1.0)).powi(5)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schlick_matches_fresnel_at_normal_and_grazing_incidence() {
        // At normal incidence the Fresnel equations give ((n-1)/(n+1))^2 exactly.
        assert!((schlick(1.0, 1.5) - 0.04).abs() < 1e-7);
        assert!((schlick(0.0, 1.5) - 1.0).abs() < 1e-7);
    }

    #[test]
    fn reflection_keeps_the_tangential_part_and_flips_the_normal_part() {
        let n = Vec3::Z;
        let d = Vec3::new(0.6, 0.0, -0.8);
        assert_eq!(reflect(d, n), Vec3::new(0.6, 0.0, 0.8));
    }
}
