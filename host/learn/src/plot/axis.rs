//! The axes: our own mapping and tick marks, computed in bounded loops rather than by
//! `plotters`, whose float tick search can loop forever on degenerate ranges.

use std::ops::Range;

use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter};

/// A 1-D axis with our own mapping and tick marks (see the module docs for why).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Axis {
    pub(super) lo: f64,
    pub(super) hi: f64,
    pub(super) log: bool,
}

impl Axis {
    /// Fits the axis to the values (already `usable`) with a 5 % margin.
    pub(super) fn fit(values: impl Iterator<Item = f64>, log: bool) -> Axis {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if lo > hi {
            return if log {
                Axis {
                    lo: 1.0,
                    hi: 10.0,
                    log,
                }
            } else {
                Axis {
                    lo: 0.0,
                    hi: 1.0,
                    log,
                }
            };
        }
        if log {
            // Fit in decades; a flat curve gets a one-decade window.
            let (mut l, mut h) = (lo.log10(), hi.log10());
            if h - l < 1e-6 {
                l -= 0.5;
                h += 0.5;
            } else {
                let pad = 0.05 * (h - l);
                l -= pad;
                h += pad;
            }
            let (l, h) = (l.max(-300.0), h.min(300.0));
            return Axis {
                lo: 10f64.powf(l),
                hi: 10f64.powf(h),
                log,
            };
        }
        let scale = lo.abs().max(hi.abs());
        // Spans too small for f64 to tick (relative or absolute) count as flat.
        if hi - lo <= 1e-10 * scale || hi - lo < 1e-250 {
            let c = 0.5 * (lo + hi);
            let half = if c.abs() < 1e-200 { 1.0 } else { 0.1 * c.abs() };
            return Axis {
                lo: c - half,
                hi: c + half,
                log,
            };
        }
        let pad = 0.05 * (hi - lo);
        Axis {
            lo: lo - pad,
            hi: hi + pad,
            log,
        }
    }

    pub(super) fn lin(&self, v: f64) -> f64 {
        if self.log { v.log10() } else { v }
    }

    /// Bold ticks (`light == false`) or the finer grid, at most `max_n` of them.
    pub(super) fn ticks(&self, max_n: usize, light: bool) -> Vec<f64> {
        let max_n = max_n.clamp(1, 200);
        if !self.log {
            return nice_ticks(self.lo, self.hi, max_n);
        }
        let (l, h) = (self.lo.log10(), self.hi.log10());
        if !(l.is_finite() && h.is_finite() && l < h) {
            return Vec::new();
        }
        // Bounded: the axis lies within 10^±300.
        let (k0, k1) = (l.floor() as i32, h.ceil() as i32);
        let decades = usize::try_from(k1 - k0).unwrap_or(0).max(1);
        let within = |v: &f64| *v >= self.lo * (1.0 - 1e-9) && *v <= self.hi * (1.0 + 1e-9);
        let with_mantissas = |ms: &[f64]| -> Vec<f64> {
            (k0..=k1)
                .flat_map(|k| ms.iter().map(move |m| m * 10f64.powi(k)))
                .filter(within)
                .collect()
        };
        let step = decades.div_ceil(max_n).max(1);
        let powers: Vec<f64> = (k0..=k1)
            .filter(|k| ((k - k0) as usize).is_multiple_of(step))
            .map(|k| 10f64.powi(k))
            .filter(within)
            .collect();
        let ticks = if light {
            if decades <= 30 {
                with_mantissas(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
            } else {
                (k0..=k1).map(|k| 10f64.powi(k)).filter(within).collect()
            }
        } else if powers.len() >= 3 {
            powers
        } else {
            let ticks = with_mantissas(&[1.0, 2.0, 5.0]);
            // Less than a decade or so: 1-2-5 ticks are too sparse, use linear ones.
            if ticks.len() >= 3 {
                ticks
            } else {
                nice_ticks(self.lo, self.hi, max_n)
            }
        };
        if ticks.len() > max_n {
            let every = ticks.len().div_ceil(max_n);
            ticks.into_iter().step_by(every).collect()
        } else {
            ticks
        }
    }
}

/// Round ticks (1, 2 or 5 × 10^k apart) in `[lo, hi]`, at most about `max_n`.
fn nice_ticks(lo: f64, hi: f64, max_n: usize) -> Vec<f64> {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) {
        return Vec::new();
    }
    let n = max_n as f64;
    let mag = 10f64.powf((span / n).log10().floor());
    let steps = [1.0, 2.0, 5.0, 10.0].map(|m| m * mag);
    let k = steps.iter().position(|s| span / s <= n).unwrap_or(3);
    let ticks = |step: f64| -> Vec<f64> {
        if !(step.is_finite() && step > 0.0) {
            return Vec::new();
        }
        let first = (lo / step).ceil();
        let mut out = Vec::new();
        // Multiplying (rather than accumulating) keeps ticks exact-ish; the bound keeps the
        // loop finite whatever rounding does.
        for i in 0..=2 * max_n + 2 {
            let v = (first + i as f64) * step;
            if v > hi + 1e-9 * step {
                break;
            }
            out.push(if v.abs() < 1e-9 * step { 0.0 } else { v });
        }
        out
    };
    let out = ticks(steps[k]);
    match k.checked_sub(1) {
        // Fewer than two ticks inside (1 to 9 in steps of 5): the next finer step.
        Some(finer) if out.len() < 2 => ticks(steps[finer]),
        _ => out,
    }
}

impl Ranged for Axis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let (a, b) = (self.lin(self.lo), self.lin(self.hi));
        let t = (self.lin(*v) - a) / (b - a);
        // Anything far off the axis is pinned just outside it, so the rasteriser never
        // walks millions of off-screen pixels.
        let t = if t.is_nan() { 0.0 } else { t.clamp(-1.0, 2.0) };
        let px = f64::from(limit.0) + t * (f64::from(limit.1) - f64::from(limit.0));
        px.round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        let light = hint.weight().allow_light_points();
        // plotters asks for up to 10 light lines per label, too dense a linear grid.
        let n = if light && !self.log {
            hint.bold_points().saturating_mul(5)
        } else {
            hint.max_num_points()
        };
        self.ticks(n, light)
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

impl ValueFormatter<f64> for Axis {
    fn format(v: &f64) -> String {
        tick_label(*v)
    }
}

/// Short tick label: up to 6 significant digits, scientific for very large or small values.
pub(super) fn tick_label(v: f64) -> String {
    fn trim(s: &str) -> &str {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.')
        } else {
            s
        }
    }
    let a = v.abs();
    if v == 0.0 || !v.is_finite() {
        return if v.is_nan() {
            "NaN".into()
        } else {
            format!("{v}")
        };
    }
    if !(1e-4..1e6).contains(&a) {
        let s = format!("{v:.3e}");
        return match s.split_once('e') {
            Some((m, e)) => format!("{}e{e}", trim(m)),
            None => s,
        };
    }
    let decimals = (5 - a.log10().floor() as i32).clamp(0, 10) as usize;
    trim(&format!("{v:.decimals$}")).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_bounded_and_inside() {
        let axes = [
            Axis::fit([0.0, 1.0].into_iter(), false),
            Axis::fit([-1e300, 1e300].into_iter(), false),
            Axis::fit([1e15, 1e15 + 1e6].into_iter(), false),
            Axis::fit([1e-300, 1e300].into_iter(), true),
            Axis::fit([0.5, 0.6].into_iter(), true),
            Axis::fit([3.0].into_iter(), true),
            Axis::fit([1e-3, 10.0].into_iter(), true),
        ];
        for a in axes {
            assert!(a.lo < a.hi && a.lo.is_finite() && a.hi.is_finite(), "{a:?}");
            for light in [false, true] {
                let t = a.ticks(10, light);
                assert!(t.len() <= 12, "{a:?}: {t:?}");
                assert!(light || t.len() >= 2, "{a:?}: {t:?}");
                for v in t {
                    assert!(v >= a.lo - 1e-9 * a.lo.abs() && v <= a.hi * (1.0 + 1e-9) + 1e-12);
                }
            }
        }
    }

    #[test]
    fn a_narrow_axis_gets_two_ticks_at_least() {
        assert_eq!(nice_ticks(0.6, 9.4, 3), vec![2.0, 4.0, 6.0, 8.0]);
        assert_eq!(nice_ticks(0.0, 10.0, 3), vec![0.0, 5.0, 10.0]);
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(tick_label(0.0), "0");
        assert_eq!(tick_label(1.5), "1.5");
        assert_eq!(tick_label(0.1 + 0.2), "0.3");
        assert_eq!(tick_label(1000.5), "1000.5");
        assert_eq!(tick_label(-250.0), "-250");
        assert_eq!(tick_label(1e-5), "1e-5");
        assert_eq!(tick_label(2.5e7), "2.5e7");
        assert_eq!(tick_label(0.00125), "0.00125");
    }
}
