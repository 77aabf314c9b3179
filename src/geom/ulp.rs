//! Unit-in-the-last-place helpers. Dammertz 2005, §2.4.2: secondary rays are offset by a
//! fixed number of ulps of the hit coordinates, never by a scene-dependent epsilon.

/// End-game threshold: a box whose L1 diameter is below this many ulps of the root box's
/// largest coordinate magnitude is final, besides Dammertz's "stops shrinking" (§2.3.3),
/// which alone spends the last splits on rounding noise. Measured with
/// `cargo bench --bench kernel -- size=256 end=K` (teapot primary rays; splits per test,
/// mean / 99th-percentile hit-point distance to the `f64` reference in those ulps):
/// K = 0: 78.2, 4.3 / 33; 4: 72.4, 4.5 / 35; 8: 68.2, 4.9 / 37; 16: 64.3, 6.0 / 44.
/// 8 saves an eighth of the splits for an error still well inside the de Casteljau
/// rounding bound the tests allow (tests/lib/kernel_newton.rs).
pub const DEFAULT_END_ULPS: u32 = 8;

/// Moves `x` by `n` representable `f32` values towards `+inf` (n > 0) or `-inf` (n < 0).
pub fn step_ulps(mut x: f32, n: i32) -> f32 {
    if n >= 0 {
        for _ in 0..n {
            x = x.next_up();
        }
    } else {
        for _ in 0..(-n) {
            x = x.next_down();
        }
    }
    x
}

/// Number of representable `f32` values strictly between `a` and `b`, plus one: the
/// "mantissa distance" of Dammertz §2.7.2 (0 when equal). Works across the sign change.
pub fn ulp_distance(a: f32, b: f32) -> u32 {
    fn ordered(x: f32) -> i64 {
        let bits = x.to_bits() as i32;
        let v = if bits < 0 {
            i32::MIN.wrapping_sub(bits)
        } else {
            bits
        };
        v as i64
    }
    (ordered(a) - ordered(b))
        .unsigned_abs()
        .min(u32::MAX as u64) as u32
}

/// One ulp of `x` as an `f64` (the gap to the next representable `f32` away from zero).
pub fn ulp_of(x: f32) -> f64 {
    let a = x.abs();
    (a.next_up() as f64) - (a as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_counts_representable_steps() {
        assert_eq!(ulp_distance(1.0, 1.0), 0);
        assert_eq!(ulp_distance(1.0, 1.0f32.next_up()), 1);
        assert_eq!(ulp_distance(step_ulps(2.5, 7), 2.5), 7);
        assert_eq!(ulp_distance(-0.0, 0.0), 0);
        assert_eq!(ulp_distance(f32::from_bits(1), -f32::from_bits(1)), 2);
    }

    #[test]
    fn stepping_is_monotone_and_reversible() {
        for &x in &[0.0f32, 1e-30, -3.5, 1e30] {
            let y = step_ulps(x, 5);
            assert!(y > x);
            assert_eq!(step_ulps(y, -5), x);
        }
    }

    #[test]
    fn ulp_of_one_is_machine_epsilon() {
        assert_eq!(ulp_of(1.0), f32::EPSILON as f64);
    }
}
