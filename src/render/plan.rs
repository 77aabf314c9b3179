//! The effect plan: which ray types a scene needs, derived before rendering so that no
//! shadow ray is traced without a light, no reflection ray without a reflective (or
//! refractive, for Fresnel) material, and no refraction ray without a transmissive one.

use std::fmt;

use serde::Serialize;

use crate::scene::Scene;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
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
