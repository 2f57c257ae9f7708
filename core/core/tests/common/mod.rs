//! What the DMP test binaries share: recorder timestamps with jitter and
//! the property "a denser recording fits no worse".

/// A reproducible uniform number in [−0.5, 0.5) from `i`.
pub fn hash(i: usize, salt: u64) -> f64 {
    let mut x = (i as u64 ^ salt).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    x ^= x >> 31;
    x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x ^= x >> 29;
    (x >> 40) as f64 / (1u64 << 24) as f64 - 0.5
}

/// `n + 1` timestamps over [0, 1] s, every inner one off by up to
/// ±`jitter` of a sample period (0: even).
pub fn stamps(n: usize, jitter: f64) -> Vec<f32> {
    (0..=n)
        .map(|i| match i {
            0 => 0.0,
            i if i == n => 1.0,
            i => ((i as f64 + 2.0 * jitter * hash(i, 7)) / n as f64) as f32,
        })
        .collect()
}

/// `errors[r]`, the worst error from the `r`-th rate (sparsest first): the
/// sparsest within 1e-5, and no denser one worse beyond f32 rounding.
pub fn assert_no_worse_when_denser(errors: &[f64], what: &str) {
    assert!(errors[0] < 1e-5, "{what}: {errors:?}");
    for e in &errors[1..] {
        assert!(*e <= errors[0] * 1.05 + 1e-7, "{what}: {errors:?}");
    }
}
