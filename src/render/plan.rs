//! The effect plan: which ray types a scene needs, derived before rendering so that no
//! shadow ray is traced without a light, no reflection ray without a reflective (or
//! refractive, for Fresnel) material, and no refraction ray without a transmissive one.

use std::fmt;

use serde::Serialize;

use crate::scene::Scene;

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EffectPlan {
    /// Shadow rays towards each light.
    pub shadows: bool,
    /// Mirror reflection rays (materials with `reflect > 0`, and the Fresnel reflection of
    /// transmissive materials).
    pub reflection: bool,
    /// Refraction rays (materials with `transmit > 0`).
    pub refraction: bool,
    /// Longest ray path; 1 (primary rays only) when neither reflection nor refraction.
    pub max_depth: u32,
    pub lights: usize,
    /// Trim loops applied (Dammertz §2.6), or ignored with `--ignore-trims`.
    pub trims: TrimEffect,
    /// Adaptive depth control: a secondary ray whose weight (the product of the
    /// reflection and transmission coefficients on its path, largest channel) is below
    /// this cannot change an 8-bit pixel and is not traced ([`MIN_RAY_WEIGHT`]).
    pub min_weight: f32,
}

/// Whether hits are tested against trim loops.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct TrimEffect {
    /// Trim loops of the scene's surfaces.
    pub loops: usize,
    /// `--ignore-trims`: the loops were read and dropped.
    pub ignored: bool,
}

impl TrimEffect {
    /// The trims of `scene`, as `--ignore-trims` (`ignored`) leaves them.
    pub fn of(scene: &Scene, ignored: bool) -> TrimEffect {
        TrimEffect {
            loops: scene.trim_loop_count(),
            ignored,
        }
    }
}

/// POV-Ray's `adc_bailout` default, 1/255: one step of an 8-bit pixel. Without it a
/// material that both reflects and transmits doubles the ray tree at every bounce (issue
/// 21: `reflect: 0.5, transmit: 0.5` never finished a 16×16 teapot).
pub const MIN_RAY_WEIGHT: f32 = 1.0 / 255.0;

/// Most rays (of every kind) one primary ray's tree may trace. Weights of energy-conserving
/// materials (reflect + transmit ≤ 1) sum to at most 1 per level, so at most 255 rays per
/// level pass [`MIN_RAY_WEIGHT`] and 255 × 64 levels bound the tree; materials that add
/// energy (reflect 1, transmit 1) would not be bounded by weight alone, so this caps
/// them too. Cut rays are counted in `--stats`.
pub const MAX_TREE_RAYS: u32 = 255 * 64;

impl EffectPlan {
    /// Derives the plan from the materials objects actually use and the lights present.
    pub fn for_scene(scene: &Scene) -> EffectPlan {
        let used = || {
            scene
                .objects
                .iter()
                .filter_map(|o| scene.materials.get(o.material))
        };
        let refraction = used().any(|m| m.transmit > 0.0);
        let reflection = used().any(|m| m.reflect > 0.0) || refraction;
        let bounces = reflection || refraction;
        EffectPlan {
            shadows: !scene.lights.is_empty(),
            reflection,
            refraction,
            max_depth: if bounces { scene.max_depth.max(1) } else { 1 },
            lights: scene.lights.len(),
            trims: TrimEffect::of(scene, false),
            min_weight: MIN_RAY_WEIGHT,
        }
    }
}

impl fmt::Display for EffectPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let on = |b: bool, what: &str| {
            if b {
                what.to_string()
            } else {
                format!("no {what}")
            }
        };
        write!(
            f,
            "effects: primary rays, {} ({} light{}), {}, {}, max depth {}",
            on(self.shadows, "shadows"),
            self.lights,
            if self.lights == 1 { "" } else { "s" },
            on(self.reflection, "reflection"),
            on(self.refraction, "refraction"),
            self.max_depth
        )?;
        if self.max_depth > 1 {
            write!(
                f,
                ", rays below weight 1/{:.0} not traced",
                1.0 / self.min_weight
            )?;
        }
        match self.trims {
            TrimEffect { ignored: true, .. } => write!(f, ", trims ignored"),
            TrimEffect { loops: 0, .. } => Ok(()),
            TrimEffect { loops, .. } => write!(
                f,
                ", trims: {loops} loop{}",
                if loops == 1 { "" } else { "s" }
            ),
        }
    }
}
