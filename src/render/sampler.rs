//! Where in a pixel the camera rays go: a stratified, deterministic sequence per pixel, and
//! the reconstruction filter that shapes it.
//!
//! The sequence is the first two dimensions of Sobol's (0,2)-sequence (Sobol 1967), Owen
//! scrambled and shuffled by hashing (Burley, *Practical Hash-based Owen Scrambling*, JCGT
//! 9(4), 2020, §§3–5) with a seed made from the pixel's coordinates in the whole image.
//! Every prefix of 2^k samples is then a (0,k,2)-net: one sample in each of the 2^k
//! elementary intervals of every shape (for 16 samples: each cell of the 4×4, 2×8, 8×2,
//! 1×16 and 16×1 grids). Because the sequence is progressive, adaptive sampling adds samples
//! to those already taken, and because it depends only on the pixel, the image is the same
//! for any thread count, tile split, crop or sampling order.
//!
//! Filters are applied by importance sampling (pbrt-v4 §8.8, "filter importance
//! sampling"): each uniform sample is warped by the filter's inverse distribution, so all
//! samples weigh the same and a pixel is the plain mean of its own rays, even for a filter
//! wider than the pixel. That keeps pixels independent of each other, which tiles need.

/// Reconstruction filter of `render --filter`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Filter {
    /// The pixel's own square, uniformly (the box filter, width 1).
    #[default]
    Box,
    /// The tent (triangle) filter of radius 1 pixel: width 2, weight falling linearly from
    /// the pixel centre.
    Tent,
    /// A Gaussian of standard deviation 0.5 pixel (pbrt-v4's default sigma), untruncated;
    /// 99% of its weight lies within 1.5 pixels of the centre.
    Gaussian,
}

/// Samples per pixel, as `render --spp` and the scene's `samples` give them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleCount {
    /// `N`: the first N samples of every pixel's sequence (1: the pixel centre, as in the
    /// DESIGN.md camera contract).
    Fixed(u32),
    /// `adaptive[:MAX]`: [`ADAPTIVE_FIRST`] samples everywhere, then up to `max` in pixels
    /// whose first samples disagree.
    Adaptive { max: u32 },
}

impl Default for SampleCount {
    fn default() -> Self {
        SampleCount::Fixed(1)
    }
}

/// Samples every pixel gets before adaptive sampling judges it: the smallest stratified
/// net (2×2) that sees an edge crossing the pixel in either direction.
pub const ADAPTIVE_FIRST: u32 = 4;
/// `--spp adaptive` without `:MAX` refines up to this many samples, the reference count
/// of the antialiasing table in BENCHMARKS.md.
pub const ADAPTIVE_DEFAULT_MAX: u32 = 64;
/// The most samples per pixel `--spp` accepts ([`crate::scene::MAX_SAMPLES`]).
pub const MAX_SPP: u32 = crate::scene::MAX_SAMPLES;

impl std::str::FromStr for SampleCount {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let count = |t: &str| match t.parse::<u32>() {
            Ok(n) if (1..=MAX_SPP).contains(&n) => Ok(n),
            _ => Err(format!(
                "expected a sample count from 1 to {MAX_SPP}, or adaptive[:MAX], found `{t}`"
            )),
        };
        match s.strip_prefix("adaptive") {
            Some("") => Ok(SampleCount::Adaptive {
                max: ADAPTIVE_DEFAULT_MAX,
            }),
            Some(rest) => match rest.strip_prefix(':') {
                Some(max) => Ok(SampleCount::Adaptive { max: count(max)? }),
                None => Err(format!("expected adaptive or adaptive:MAX, found `{s}`")),
            },
            None => Ok(SampleCount::Fixed(count(s)?)),
        }
    }
}

impl std::fmt::Display for SampleCount {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            SampleCount::Fixed(n) => write!(f, "{n}"),
            SampleCount::Adaptive { max } => write!(f, "adaptive:{max}"),
        }
    }
}

/// Standard deviation of [`Filter::Gaussian`] in pixels (pbrt-v4 `GaussianFilter` default).
pub const GAUSSIAN_SIGMA: f64 = 0.5;

impl Filter {
    /// The sample offset inside pixel coordinates (0.5, 0.5 is the centre) for a uniform
    /// point `(u, v)` in [0, 1)².
    pub fn offset(self, (u, v): (f64, f64)) -> (f64, f64) {
        match self {
            Filter::Box => (u, v),
            Filter::Tent => (0.5 + tent(u), 0.5 + tent(v)),
            Filter::Gaussian => {
                // Box–Muller: the radius from one coordinate, the angle from the other, so
                // the 2D strata map to rings and sectors of the Gaussian. 1 - u lies in
                // (0, 1], so the logarithm is finite.
                let r = GAUSSIAN_SIGMA * (-2.0 * (1.0 - u).ln()).sqrt();
                let (s, c) = (std::f64::consts::TAU * v).sin_cos();
                (0.5 + r * c, 0.5 + r * s)
            }
        }
    }
}

/// The inverse distribution of the tent of radius 1 on [-1, 1].
fn tent(u: f64) -> f64 {
    if u < 0.5 {
        (2.0 * u).sqrt() - 1.0
    } else {
        1.0 - (2.0 - 2.0 * u).sqrt()
    }
}

/// Sample `index` of pixel `(x, y)`: a point of [0, 1)².
pub fn pixel_sample(x: u32, y: u32, index: u32) -> (f64, f64) {
    let seed = hash(x.wrapping_mul(0x9E37_79B9) ^ hash(y ^ 0x5bd1_e995));
    // Shuffling the index by a nested uniform scramble keeps every aligned block of 2^k
    // indices together (Burley §5), so each prefix of 2^k samples stays a (0,k,2)-net.
    let i = nested_uniform_scramble(index, seed);
    let a = nested_uniform_scramble(i.reverse_bits(), hash(seed ^ 0xa511_e9b3));
    let b = nested_uniform_scramble(sobol_second(i), hash(seed ^ 0x63d8_3595));
    (unit(a), unit(b))
}

/// A 32-bit fraction as a float in [0, 1): the top 24 bits, so the result is exact in `f32`
/// as well and never rounds up to 1.
fn unit(bits: u32) -> f64 {
    (bits >> 8) as f64 / (1u32 << 24) as f64
}

/// The second dimension of Sobol's sequence: the generator matrix is Pascal's triangle mod
/// 2, whose columns are produced by `v ^= v >> 1` (Burley, listing 1; Sobol 1967).
fn sobol_second(mut index: u32) -> u32 {
    let (mut out, mut v) = (0u32, 1u32 << 31);
    while index != 0 {
        if index & 1 != 0 {
            out ^= v;
        }
        index >>= 1;
        v ^= v >> 1;
    }
    out
}

/// Owen scrambling of a 32-bit fraction, most significant bit first (Burley, listing 2:
/// the Laine–Karras permutation on the reversed bits, with his improved constants).
fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    let mut x = x.reverse_bits();
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x.reverse_bits()
}

/// A 32-bit integer hash with good avalanche (Wellons' `lowbias32`, as in Burley §4).
fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether the points have exactly one in each cell of every `2^a × 2^(k-a)` grid.
    fn is_net(points: &[(f64, f64)], k: u32) -> bool {
        (0..=k).all(|a| {
            let (nx, ny) = (1usize << a, 1usize << (k - a));
            let mut seen = vec![false; nx * ny];
            points.iter().all(|&(u, v)| {
                let c = (v * ny as f64) as usize * nx + (u * nx as f64) as usize;
                !std::mem::replace(&mut seen[c], true)
            })
        })
    }

    #[test]
    fn every_power_of_two_prefix_is_stratified_in_every_shape() {
        for (x, y) in [(0, 0), (17, 3), (511, 511), (4000, 12)] {
            let s: Vec<_> = (0..64).map(|i| pixel_sample(x, y, i)).collect();
            for k in 0..=6 {
                assert!(is_net(&s[..1 << k], k), "pixel ({x}, {y}), prefix 2^{k}");
            }
            // The block after the first 16 is a net as well: adaptive sampling extends
            // a pixel with samples that fill the strata in turn.
            assert!(is_net(&s[16..32], 4));
        }
    }

    #[test]
    fn sample_counts_parse_and_bad_ones_are_refused() {
        let parse = |s: &str| s.parse::<SampleCount>();
        assert_eq!(parse("16"), Ok(SampleCount::Fixed(16)));
        assert_eq!(parse("adaptive"), Ok(SampleCount::Adaptive { max: 64 }));
        assert_eq!(
            parse("adaptive:256"),
            Ok(SampleCount::Adaptive { max: 256 })
        );
        for bad in [
            "0",
            "-1",
            "adaptive:",
            "adaptive:0",
            "adaptivex",
            "70000",
            "x",
        ] {
            assert!(parse(bad).is_err(), "{bad} accepted");
        }
    }

    #[test]
    fn neighbouring_pixels_get_different_sequences() {
        let a = pixel_sample(10, 10, 0);
        assert_ne!(a, pixel_sample(11, 10, 0));
        assert_ne!(a, pixel_sample(10, 11, 0));
        assert_eq!(a, pixel_sample(10, 10, 0));
    }

    /// Mean and variance of one offset coordinate over 4096 stratified samples.
    fn moments(filter: Filter) -> [(f64, f64); 2] {
        let s: Vec<_> = (0..4096)
            .map(|i| filter.offset(pixel_sample(3, 5, i)))
            .collect();
        let n = s.len() as f64;
        [|p: &(f64, f64)| p.0, |p: &(f64, f64)| p.1].map(|c| {
            let mean = s.iter().map(c).sum::<f64>() / n;
            let var = s.iter().map(|p| (c(p) - mean).powi(2)).sum::<f64>() / n;
            (mean, var)
        })
    }

    #[test]
    fn filters_have_the_centre_and_spread_of_their_closed_forms() {
        // Variances: uniform on [0, 1) is 1/12; the tent of radius r is r²/6; the
        // Gaussian's is sigma².
        for (filter, var) in [
            (Filter::Box, 1.0 / 12.0),
            (Filter::Tent, 1.0 / 6.0),
            (Filter::Gaussian, GAUSSIAN_SIGMA * GAUSSIAN_SIGMA),
        ] {
            for (mean, v) in moments(filter) {
                assert!((mean - 0.5).abs() < 2e-3, "{filter:?} mean {mean}");
                assert!(
                    (v - var).abs() < 0.01 * var,
                    "{filter:?} variance {v} vs {var}"
                );
            }
        }
        // The tent stays within one pixel of the centre.
        assert!(
            (0..1024)
                .map(|i| Filter::Tent.offset(pixel_sample(1, 2, i)))
                .all(|(a, b)| (-0.5..=1.5).contains(&a) && (-0.5..=1.5).contains(&b))
        );
    }
}
