//! Golden-section search for the minimum of a function of one variable on an interval
//! (Kiefer, "Sequential minimax search for a maximum", Proc. AMS 4, 1953): each step keeps
//! 0.618 of the bracket, so `steps` steps narrow it to 0.618^steps of its width.

/// The middle of the bracket left after `steps` golden-section steps on `[a, b]` towards a
/// minimum of `f` (the minimum, when `f` has one minimum there).
pub fn minimize(f: impl Fn(f64) -> f64, a: f64, b: f64, steps: usize) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (a, b);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..steps {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    #[test]
    fn finds_the_vertex_of_a_parabola() {
        let t = super::minimize(|t| (t - 0.3).powi(2), -1.0, 2.0, 80);
        assert!((t - 0.3).abs() < 1e-8, "{t}");
    }
}
