//! The communication statistics over the last [`STAT_WINDOW`] cycles, and
//! the quality they give.

use std::collections::VecDeque;

use primo_fri::packet::Quality;

/// Cycles the communication statistics and the quality are computed over.
pub const STAT_WINDOW: usize = 100;
/// On-time answers needed for OK; twice as many for PERFECT.
pub const RAMP: u64 = 10;

/// The communication statistics over the last [`STAT_WINDOW`] cycles.
#[derive(Debug, Default)]
pub(super) struct Window {
    /// Answer latency of each cycle, `None` if missed.
    cycles: VecDeque<Option<f64>>,
    /// On-time answers since power-on.
    answered: u64,
}

impl Window {
    pub(super) fn push(&mut self, latency: Option<f64>) {
        if self.cycles.len() == STAT_WINDOW {
            self.cycles.pop_front();
        }
        self.cycles.push_back(latency);
        self.answered += u64::from(latency.is_some());
    }

    pub(super) fn answer_rate(&self) -> f64 {
        let n = self.cycles.len();
        if n == 0 {
            return 0.0;
        }
        self.cycles.iter().filter(|c| c.is_some()).count() as f64 / n as f64
    }

    /// Mean and spread (max − min) of the latencies.
    pub(super) fn latency(&self) -> (f64, f64) {
        let l: Vec<f64> = self.cycles.iter().flatten().copied().collect();
        if l.is_empty() {
            return (0.0, 0.0);
        }
        let mean = l.iter().sum::<f64>() / l.len() as f64;
        let (lo, hi) = l
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(*x), b.max(*x))
            });
        (mean, hi - lo)
    }

    /// The quality: the answer rate against `[bad, ok, perfect]`, capped
    /// by the ramp after opening.
    pub(super) fn quality(&self, [bad, ok, perfect]: [f64; 3]) -> Quality {
        let rate = self.answer_rate();
        let by_rate = if rate >= perfect {
            Quality::Perfect
        } else if rate >= ok {
            Quality::Ok
        } else if rate >= bad {
            Quality::Bad
        } else {
            Quality::Unacceptable
        };
        let ramp = if self.answered < RAMP {
            Quality::Bad
        } else if self.answered < 2 * RAMP {
            Quality::Ok
        } else {
            Quality::Perfect
        };
        by_rate.min(ramp)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const THRESHOLDS: [f64; 3] = [0.5, 0.8, 0.98];

    #[test]
    fn quality_ramps_up_with_answers_and_falls_with_misses() {
        let mut w = Window::default();
        assert_eq!(w.quality(THRESHOLDS), Quality::Unacceptable);
        let mut seen = Vec::new();
        for _ in 0..2 * RAMP {
            w.push(Some(1e-4));
            seen.push(w.quality(THRESHOLDS));
        }
        seen.dedup();
        assert_eq!(seen, [Quality::Bad, Quality::Ok, Quality::Perfect]);
        // One answer in 20 missing: OK, not PERFECT.
        for i in 0..STAT_WINDOW {
            w.push((i % 20 != 0).then_some(2e-4));
        }
        assert_eq!(w.quality(THRESHOLDS), Quality::Ok);
        assert!((w.answer_rate() - 0.95).abs() < 1e-12);
        let (latency, jitter) = w.latency();
        assert!((latency - 2e-4).abs() < 1e-15 && jitter == 0.0);
        // Silence: down to UNACCEPTABLE.
        for _ in 0..40 {
            w.push(None);
        }
        assert!((w.answer_rate() - 0.57).abs() < 1e-12);
        assert_eq!(w.quality(THRESHOLDS), Quality::Bad);
        for _ in 0..60 {
            w.push(None);
        }
        assert_eq!(w.quality(THRESHOLDS), Quality::Unacceptable);
    }
}
