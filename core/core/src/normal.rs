//! A seedable standard-normal sampler on any [`rand_core::Rng`].
//!
//! Box–Muller with `libm`, so a given generator state yields the same bits on
//! every target. The second value of each pair is kept for the next call.
//!
//! ```
//! use primo_core::normal::StandardNormal;
//! use rand_core::SeedableRng;
//! let mut rng = primo_core::rng::Xoshiro128PlusPlus::seed_from_u64(7);
//! let mut normal = StandardNormal::new();
//! let z = normal.sample(&mut rng);
//! assert!(z.is_finite());
//! ```

use rand_core::Rng;

/// Standard-normal sampler; holds the spare value of the last Box–Muller pair.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct StandardNormal {
    spare: Option<f32>,
}

impl StandardNormal {
    /// A sampler with no spare value.
    pub const fn new() -> Self {
        Self { spare: None }
    }

    /// Draws one value from N(0, 1). Always finite: |z| < 5.8.
    pub fn sample<R: Rng + ?Sized>(&mut self, rng: &mut R) -> f32 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        // u1 in (0, 1] so that ln(u1) is finite; u2 in [0, 1).
        let u1 = ((rng.next_u32() >> 8) + 1) as f32 * (1.0 / 16_777_216.0);
        let u2 = (rng.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0);
        let r = libm::sqrtf(-2.0 * libm::logf(u1));
        let (s, c) = libm::sincosf(core::f32::consts::TAU * u2);
        self.spare = Some(r * s);
        r * c
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_core::SeedableRng;

    #[test]
    fn mean_and_variance_match_standard_normal() {
        let mut rng = crate::rng::Xoshiro128PlusPlus::seed_from_u64(1);
        let mut n = StandardNormal::new();
        let count = 200_000;
        let (mut s1, mut s2, mut s4) = (0.0f64, 0.0f64, 0.0f64);
        for _ in 0..count {
            let z = n.sample(&mut rng) as f64;
            s1 += z;
            s2 += z * z;
            s4 += z * z * z * z;
        }
        let c = count as f64;
        let mean = s1 / c;
        let var = s2 / c - mean * mean;
        // Standard errors: mean 1/sqrt(n) = 0.0022, variance sqrt(2/n) = 0.0032.
        assert!(mean.abs() < 5.0 * 0.0023, "mean {mean}");
        assert!((var - 1.0).abs() < 5.0 * 0.0032, "variance {var}");
        // Kurtosis 3 distinguishes a normal from e.g. a uniform of equal variance.
        assert!((s4 / c - 3.0).abs() < 0.1, "fourth moment {}", s4 / c);
    }

    #[test]
    fn same_seed_same_bits() {
        let draw = |seed| {
            let mut rng = crate::rng::Xoshiro128PlusPlus::seed_from_u64(seed);
            let mut n = StandardNormal::new();
            [n.sample(&mut rng), n.sample(&mut rng), n.sample(&mut rng)].map(f32::to_bits)
        };
        assert_eq!(draw(3), draw(3));
        assert_ne!(draw(3), draw(4));
    }
}
