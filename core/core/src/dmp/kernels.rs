//! Where a DMP's kernels lie on the phase and which of them are within
//! reach of a phase: shared by the forcing term of an execution and the
//! fit's basis, so both sum the same window.

use super::options::KERNEL_CUTOFF;

/// Kernel spacings between the movement's ends: `K − 1 − 2m`.
pub(super) fn span(kernels: usize, margin: f32) -> f32 {
    kernels.saturating_sub(1) as f32 - 2.0 * margin
}

/// Where the kernels are: `c_k = (k − margin)·spacing` for `k` in
/// `0..=last`.
pub(super) struct Layout {
    /// Kernel spacings between the movement's ends, `1/spacing`.
    span: f32,
    margin: f32,
    last: f32,
}

impl Layout {
    pub(super) fn new(kernels: usize, margin: f32) -> Self {
        Layout {
            span: span(kernels, margin),
            margin,
            last: kernels.saturating_sub(1).max(1) as f32,
        }
    }

    /// The distance between neighbouring kernels, in phase.
    pub(super) fn spacing(&self) -> f32 {
        1.0 / self.span
    }

    /// Kernel spacings between the movement's ends.
    pub(super) fn span(&self) -> f32 {
        self.span
    }

    /// Kernel spacings beyond each end.
    pub(super) fn margin(&self) -> f32 {
        self.margin
    }

    /// The kernel index range `[lo, hi]` within reach of phase `s`, and
    /// the nearest kernel, which it always contains.
    pub(super) fn window(&self, s: f32, width: f32) -> (usize, usize, usize) {
        let last = self.last;
        let reach = libm::sqrtf(KERNEL_CUTOFF / width) * self.span;
        let centre = s * self.span + self.margin;
        // `as usize` saturates, and the clamp keeps both ends inside [0, last].
        let lo = libm::ceilf(centre - reach).clamp(0.0, last) as usize;
        let hi = libm::floorf(centre + reach).clamp(0.0, last) as usize;
        let nearest = libm::roundf(centre).clamp(0.0, last) as usize;
        (lo.min(nearest), hi.max(nearest), nearest)
    }
}

/// Activations of the kernels within reach of phase `s`, relative to the
/// nearest kernel (which gets exactly 1, so the sum is ≥ 1 however narrow the
/// kernels): written to `psi[lo..=hi]`, returned with `lo`, `hi` and the sum.
pub(super) fn activations<const K: usize>(
    s: f32,
    width: f32,
    layout: &Layout,
    psi: &mut [f32; K],
) -> (usize, usize, f32) {
    let spacing = layout.spacing();
    let (lo, hi, nearest) = layout.window(s, width);
    // The phase from kernel 0's centre (s itself without a margin, so
    // those DMPs move bit for bit as before margins existed).
    let from_first = s + layout.margin * spacing;
    let d0 = from_first - nearest as f32 * spacing;
    let base = d0 * d0;
    let mut sum = 0.0;
    for (k, p) in (lo..=hi).zip(psi.iter_mut().skip(lo)) {
        let ds = from_first - k as f32 * spacing;
        *p = libm::expf(-width * (ds * ds - base));
        sum += *p;
    }
    (lo, hi, sum)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dmp::options::{AUTO_MARGIN, DEFAULT_OVERLAP, LEARNING_OVERLAP};

    #[test]
    fn window_is_small_and_covers_nearest() {
        // Within reach: |s − c| ≤ √(cutoff/overlap) spacings either side.
        for (overlap, margin, most) in [
            (DEFAULT_OVERLAP, 0.0, 13),
            (DEFAULT_OVERLAP, AUTO_MARGIN, 13),
            (LEARNING_OVERLAP, 0.0, 8),
        ] {
            let layout = Layout::new(30, margin);
            let width = overlap * layout.span() * layout.span();
            for i in 0..=1000 {
                let s = i as f32 / 1000.0;
                let (lo, hi, nearest) = layout.window(s, width);
                assert!(lo <= nearest && nearest <= hi);
                assert!(lo <= hi && hi < 30);
                assert!(hi - lo < most, "window {lo}..={hi} at overlap {overlap}");
            }
        }
    }
}
