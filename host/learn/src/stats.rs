//! Statistics over seeded runs: medians, means, and percentile bootstrap
//! confidence intervals, reproducible (the resampling is seeded).

use primo_core::rng::Xoshiro128PlusPlus;
use rand_core::{Rng, SeedableRng};
use serde::Serialize;

/// Resamples per interval.
pub const RESAMPLES: usize = 2000;
/// The intervals' coverage.
pub const LEVEL: f64 = 0.90;

/// A statistic and its bootstrap interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Estimate {
    /// The statistic on the runs.
    pub value: f64,
    /// Lower end of the [`LEVEL`] percentile bootstrap interval.
    pub low: f64,
    /// Upper end.
    pub high: f64,
}

/// The median (`NaN` for no values).
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    0.5 * (v[(n - 1) / 2] + v[n / 2])
}

/// The `q` quantile (0 to 1) of the finite values, interpolated linearly between the
/// sorted values (`NaN` for none).
pub fn quantile(values: &[f64], q: f64) -> f64 {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    let Some(last) = v.len().checked_sub(1) else {
        return f64::NAN;
    };
    let at = q.clamp(0.0, 1.0) * last as f64;
    let (i, t) = (at.floor() as usize, at.fract());
    let next = v[(i + 1).min(last)];
    v[i] + t * (next - v[i])
}

/// The mean (`NaN` for no values).
pub fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len() as f64
}

/// `statistic` of the runs with its percentile bootstrap interval: the
/// runs are resampled with replacement [`RESAMPLES`] times (indices, so
/// paired values stay paired).
pub fn bootstrap(n: usize, statistic: impl Fn(&[usize]) -> f64, seed: u64) -> Estimate {
    let all: Vec<usize> = (0..n).collect();
    let value = statistic(&all);
    if n == 0 {
        return Estimate {
            value,
            low: f64::NAN,
            high: f64::NAN,
        };
    }
    let mut rng = Xoshiro128PlusPlus::seed_from_u64(seed);
    let mut stats: Vec<f64> = (0..RESAMPLES)
        .map(|_| {
            let pick: Vec<usize> = (0..n).map(|_| rng.next_u32() as usize % n).collect();
            statistic(&pick)
        })
        .collect();
    stats.sort_by(f64::total_cmp);
    let at = |q: f64| stats[((q * (RESAMPLES - 1) as f64).round() as usize).min(RESAMPLES - 1)];
    Estimate {
        value,
        low: at(0.5 * (1.0 - LEVEL)),
        high: at(0.5 * (1.0 + LEVEL)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_interval_holds_the_value_and_narrows_with_more_runs() {
        let values: Vec<f64> = (0..40).map(|i| ((i * 37) % 11) as f64).collect();
        let of = |n: usize| {
            let v = &values[..n];
            bootstrap(
                n,
                |pick| mean(&pick.iter().map(|i| v[*i]).collect::<Vec<_>>()),
                7,
            )
        };
        let (few, many) = (of(10), of(40));
        for e in [few, many] {
            assert!(e.low <= e.value && e.value <= e.high, "{e:?}");
        }
        assert!(many.high - many.low < few.high - few.low);
        assert_eq!(of(10), of(10), "seeded");
        assert_eq!(median(&[3.0, 1.0, 2.0, 10.0]), 2.5);
    }

    #[test]
    fn quantiles_interpolate_and_stay_within_the_values() {
        let v = [4.0, 0.0, 2.0, f64::NAN, 1.0];
        assert_eq!(quantile(&v, 0.0), 0.0);
        assert_eq!(quantile(&v, 1.0), 4.0);
        assert_eq!(quantile(&v, 0.5), 1.5);
        assert_eq!(quantile(&v, 0.25), 0.75);
        assert_eq!(quantile(&v, 7.0), 4.0);
        assert_eq!(quantile(&[3.0], 0.05), 3.0);
        assert!(quantile(&[], 0.5).is_nan());
        assert!(quantile(&[f64::NAN], 0.5).is_nan());
    }
}
