//! Arbitrary output variables: per-pixel layers beside the colour, written as channels of
//! one EXR under the names compositors look for (OpenEXR's `Z` for depth, `P.X`/`P.Y`/`P.Z`
//! for position and `N.X`/… for the normal, as Nuke and Blender name their layers).
//!
//! The geometric layers come from the pixel's centre ray (offset 0.5, 0.5 of the DESIGN.md
//! camera), the same ray `trace` is given for the pixel, whatever `--spp` is: depth and
//! ids are not quantities one averages over a pixel. A miss is marked by `Z` = +∞ and
//! ids of `u32::MAX` ([`MISS_ID`]); position, normal and uv are 0 there.

use exr::prelude::{AnyChannel, FlatSamples};

use super::renderer::{CentreHit, Rendered};

/// One output variable of `render --aov`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, clap::ValueEnum)]
pub enum Aov {
    /// `Z`: distance from the eye along the centre ray (the ray's `t`, its direction being
    /// unit length), f32.
    Depth,
    /// `P.X`, `P.Y`, `P.Z`: the hit point in world space, f32.
    Position,
    /// `N.X`, `N.Y`, `N.Z`: the unit geometric normal, f32.
    Normal,
    /// `UV.U`, `UV.V`: the hit's parameters in its patch's own [0, 1]² domain, f32.
    Uv,
    /// `id.object`: the object's number in the scene, u32.
    Object,
    /// `id.patch`: the patch's number within its object (DESIGN.md patch order), u32.
    Patch,
    /// `effort`: de Casteljau splits of all rays the pixel started (Dammertz Fig. 2.9),
    /// f32; also drawn, colour-mapped, as <name>-effort.png.
    Effort,
    /// Every layer above.
    All,
}

/// The id of a pixel whose centre ray hit nothing.
pub const MISS_ID: u32 = u32::MAX;

/// The layers asked for, `all` expanded, each once, in declaration order.
pub fn expand(list: &[Aov]) -> Vec<Aov> {
    let mut out: Vec<Aov> = if list.contains(&Aov::All) {
        vec![
            Aov::Depth,
            Aov::Position,
            Aov::Normal,
            Aov::Uv,
            Aov::Object,
            Aov::Patch,
            Aov::Effort,
        ]
    } else {
        list.to_vec()
    };
    out.sort();
    out.dedup();
    out
}

/// Whether any of `aovs` needs the centre ray's hit.
pub fn needs_hits(aovs: &[Aov]) -> bool {
    aovs.iter().any(|&a| a != Aov::Effort)
}

/// The channels of `aovs` (expanded) over the rendered window of a scene rendered moved
/// by minus `origin` (its floating origin, [`crate::scene::origin`]): positions are
/// reported in world space, `origin` added back in `f64`.
pub fn channels(
    aovs: &[Aov],
    rendered: &Rendered,
    origin: glam::DVec3,
) -> Vec<AnyChannel<FlatSamples>> {
    let hits = &rendered.hits;
    let f32s = |name: &str, f: &dyn Fn(&CentreHit) -> f64, miss: f32| {
        let v = hits
            .iter()
            .map(|h| h.as_ref().map_or(miss, |h| f(h) as f32))
            .collect();
        AnyChannel::new(name, FlatSamples::F32(v))
    };
    let ids = |name: &str, f: &dyn Fn(&CentreHit) -> u32| {
        let v = hits.iter().map(|h| h.as_ref().map_or(MISS_ID, f)).collect();
        AnyChannel::new(name, FlatSamples::U32(v))
    };
    let mut out = Vec::new();
    for aov in aovs {
        match aov {
            Aov::Depth => out.push(f32s("Z", &|h| h.hit.t, f32::INFINITY)),
            Aov::Position => out.extend([
                f32s("P.X", &|h| h.point.x + origin.x, 0.0),
                f32s("P.Y", &|h| h.point.y + origin.y, 0.0),
                f32s("P.Z", &|h| h.point.z + origin.z, 0.0),
            ]),
            Aov::Normal => out.extend([
                f32s("N.X", &|h| h.hit.normal.x, 0.0),
                f32s("N.Y", &|h| h.hit.normal.y, 0.0),
                f32s("N.Z", &|h| h.hit.normal.z, 0.0),
            ]),
            Aov::Uv => out.extend([
                f32s("UV.U", &|h| h.hit.u, 0.0),
                f32s("UV.V", &|h| h.hit.v, 0.0),
            ]),
            Aov::Object => out.push(ids("id.object", &|h| h.hit.object)),
            Aov::Patch => out.push(ids("id.patch", &|h| h.hit.patch)),
            Aov::Effort => out.push(AnyChannel::new(
                "effort",
                FlatSamples::F32(rendered.effort.iter().map(|&e| e as f32).collect()),
            )),
            Aov::All => {}
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_expands_to_every_layer_once() {
        let all = expand(&[Aov::Effort, Aov::All, Aov::Depth]);
        assert_eq!(all.len(), 7);
        assert!(!all.contains(&Aov::All));
        assert_eq!(
            expand(&[Aov::Uv, Aov::Depth, Aov::Uv]),
            [Aov::Depth, Aov::Uv]
        );
        assert!(!needs_hits(&[Aov::Effort]) && needs_hits(&[Aov::Patch]));
    }
}
