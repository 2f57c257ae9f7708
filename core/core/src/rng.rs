//! xoshiro128++ (Blackman & Vigna), the seedable generator of the learners.
//!
//! Kept here rather than taken from `rand_xoshiro` because the learners'
//! state must serialize without `std` (its `serde` feature enables serde's
//! `std`), and 32-bit output suits the Cortex-M4F.
//!
//! ```
//! use primo_core::rng::Xoshiro128PlusPlus;
//! use rand_core::{Rng, SeedableRng};
//! let mut a = Xoshiro128PlusPlus::seed_from_u64(1);
//! let mut b = Xoshiro128PlusPlus::seed_from_u64(1);
//! assert_eq!(a.next_u32(), b.next_u32());
//! ```

use core::convert::Infallible;

use rand_core::{SeedableRng, TryRng};
use serde::Serialize;

/// The generator's 128-bit state.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Xoshiro128PlusPlus {
    s: [u32; 4],
}

impl Xoshiro128PlusPlus {
    /// The all-zero state, which only ever yields 0: a placeholder to be
    /// replaced by a seeded generator before use.
    pub(crate) const fn unseeded() -> Self {
        Self { s: [0; 4] }
    }

    fn next(&mut self) -> u32 {
        let [s0, s1, s2, s3] = self.s;
        let result = s0.wrapping_add(s3).rotate_left(7).wrapping_add(s0);
        let t = s1 << 9;
        let (mut n0, mut n1, mut n2, mut n3) = (s0, s1, s2 ^ s0, s3 ^ s1);
        n1 ^= n2;
        n0 ^= n3;
        n2 ^= t;
        n3 = n3.rotate_left(11);
        self.s = [n0, n1, n2, n3];
        result
    }
}

impl SeedableRng for Xoshiro128PlusPlus {
    type Seed = [u8; 16];

    fn from_seed(seed: [u8; 16]) -> Self {
        let mut s = [0u32; 4];
        for (w, b) in s.iter_mut().zip(seed.chunks_exact(4)) {
            *w = u32::from_le_bytes([
                b.first().copied().unwrap_or(0),
                b.get(1).copied().unwrap_or(0),
                b.get(2).copied().unwrap_or(0),
                b.get(3).copied().unwrap_or(0),
            ]);
        }
        // The all-zero state is a fixed point; replace it as the authors advise.
        if s == [0; 4] {
            return Self::seed_from_u64(0);
        }
        Self { s }
    }
}

impl TryRng for Xoshiro128PlusPlus {
    type Error = Infallible;

    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        Ok(self.next())
    }

    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        let lo = u64::from(self.next());
        Ok(lo | (u64::from(self.next()) << 32))
    }

    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        for chunk in dst.chunks_mut(4) {
            let bytes = self.next().to_le_bytes();
            for (d, b) in chunk.iter_mut().zip(bytes) {
                *d = b;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_core::Rng;

    #[test]
    fn matches_the_reference_sequence() {
        // Reference: the authors' xoshiro128plusplus.c from state {1, 2, 3, 4}.
        let mut r = Xoshiro128PlusPlus { s: [1, 2, 3, 4] };
        let got: [u32; 4] = core::array::from_fn(|_| r.next_u32());
        assert_eq!(got, [641, 1_573_767, 3_222_811_527, 3_517_856_514]);
    }
}
