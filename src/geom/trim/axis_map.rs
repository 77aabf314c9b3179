//! The map from a NURBS parameter to the parameter trims are written in.

/// How one parameter of a surface's NURBS form maps to the parameter its trim loops are
/// written in. CAD formats give trims of analytic surfaces (IGES 120, 190–198; STEP
/// cylinders, cones, spheres, tori, revolutions) in the analytic parameter, an angle, while
/// the exact NURBS form runs through rational quadratic arcs whose parameter is not
/// proportional to the angle. Rather than approximate the loops, the trim test maps the
/// hit's NURBS parameter to the angle exactly (up to `f64` rounding).
#[derive(Clone, Debug, Default, PartialEq)]
pub enum AxisMap {
    /// The trim parameter is the NURBS parameter.
    #[default]
    Identity,
    /// The NURBS parameter on `[breaks[i], breaks[i+1]]` runs through one rational quadratic
    /// circular arc with symmetric weights (end weights 1, middle weight cos(Δ/2)) from angle
    /// `angles[i]` to `angles[i+1]` (radians): `breaks.len() == angles.len() >= 2`.
    Arcs { breaks: Vec<f64>, angles: Vec<f64> },
}

impl AxisMap {
    /// The trim parameter at NURBS parameter `t`. For an arc of angle Δ with local
    /// parameter s ∈ [0, 1], the rational quadratic form has tan(α/2) = tan(Δ/4)(2s − 1),
    /// α measured from the arc's middle (Piegl & Tiller §7.3: the symmetric weights make
    /// it a stereographic parameterisation).
    pub fn apply(&self, t: f64) -> f64 {
        match self {
            AxisMap::Identity => t,
            AxisMap::Arcs { breaks, angles } => {
                let n = breaks.len() - 1;
                let i = breaks[1..n].partition_point(|&b| b <= t);
                let (b0, b1) = (breaks[i], breaks[i + 1]);
                let (a0, a1) = (angles[i], angles[i + 1]);
                let s = (t - b0) / (b1 - b0);
                let delta = a1 - a0;
                0.5 * (a0 + a1) + 2.0 * ((0.25 * delta).tan() * (2.0 * s - 1.0)).atan()
            }
        }
    }

    /// The NURBS parameter at trim parameter `a`, the inverse of [`Self::apply`]: on the
    /// arc whose angles bracket `a` (the nearest end arc outside them),
    /// s = (tan(α/2) / tan(Δ/4) + 1) / 2. The tessellator needs it to place the samples of
    /// a trim loop on the surface.
    pub fn invert(&self, a: f64) -> f64 {
        match self {
            AxisMap::Identity => a,
            AxisMap::Arcs { breaks, angles } => {
                let n = angles.len() - 1;
                // Angles run one way along the breaks; count the inner ones a has passed.
                let rising = angles[n] >= angles[0];
                let i = angles[1..n]
                    .iter()
                    .take_while(|&&x| if rising { x <= a } else { x >= a })
                    .count();
                let (b0, b1) = (breaks[i], breaks[i + 1]);
                let (a0, a1) = (angles[i], angles[i + 1]);
                let quarter = (0.25 * (a1 - a0)).tan();
                let s = if quarter == 0.0 {
                    0.5
                } else {
                    0.5 * ((0.5 * (a - 0.5 * (a0 + a1))).tan() / quarter + 1.0)
                };
                b0 + (b1 - b0) * s
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn arc_map_inverts_the_rational_quadratic_arc() {
        // A 120° arc from 10° as the rational quadratic of Piegl & Tiller §7.3; its point
        // at s must lie at the angle the map returns.
        let (a0, a1) = (10f64.to_radians(), 130f64.to_radians());
        let half = 0.5 * (a1 - a0);
        let mid = 0.5 * (a0 + a1);
        let p0 = DVec3::new(a0.cos(), a0.sin(), 1.0);
        let p2 = DVec3::new(a1.cos(), a1.sin(), 1.0);
        let w = half.cos();
        let p1 = DVec3::new(mid.cos() / w, mid.sin() / w, 1.0) * w;
        let map = AxisMap::Arcs {
            breaks: vec![2.0, 3.0],
            angles: vec![a0, a1],
        };
        for k in 0..=16 {
            let s = k as f64 / 16.0;
            let h = p0 * (1.0 - s) * (1.0 - s) + p1 * 2.0 * s * (1.0 - s) + p2 * s * s;
            let angle = (h.y / h.z).atan2(h.x / h.z);
            assert!((map.apply(2.0 + s) - angle).abs() < 1e-14, "s = {s}");
            assert!((map.invert(angle) - (2.0 + s)).abs() < 1e-14, "s = {s}");
        }
    }
}
