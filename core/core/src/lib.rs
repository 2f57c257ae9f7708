//! # primo-core
//!
//! The learning core of primo: everything the paper's method computes, with no
//! I/O, no clock and no allocator, so the same code runs on the host and on a
//! Cortex-M4F coprocessor and gives the same bits on both.
//!
//! - [`dmp`]: discrete Dynamic Movement Primitives of fixed capacity, fitted to
//!   demonstrations and integrated step by step.
//! - [`generalize`]: statistical generalization `θ = G(q)` from example
//!   movements `(q_i, θ_i)` (locally weighted regression or Gaussian process
//!   regression).
//! - [`golden`]: the paper's error learning with golden-section search on the
//!   query, as an ask/tell state machine; [`illinois`]: a bracketed method
//!   that also uses the error's magnitude; [`secant`]: the paper's eq. 10,
//!   `q ← q + K ε`, for a query of any dimension, with the gain `K` learned
//!   by secant (Broyden) updates.
//! - [`power`]: PoWER over the extended parameter set `[q̂, Δθ]` with
//!   per-block exploration and an importance sampler.
//! - [`promp`]: probabilistic movement primitives from several
//!   demonstrations: mean and variance, conditioning, blending.
//! - [`quaternion`] and [`orientation`]: unit quaternions, orientation DMPs
//!   and Cartesian DMPs (position and orientation on one phase);
//!   [`tangent`]: orientations as rotation vectors at a reference, the way
//!   [`generalize::orientation`] combines them over a query.
//! - [`coupling`]: obstacles, joint limits and phase stopping, as terms a
//!   running DMP takes each step.
//! - [`rhythmic`]: periodic DMPs, frequency and amplitude changed online.
//! - [`normal`]: a seedable standard-normal sampler on any [`rand_core::Rng`].
//! - [`linalg`]: Cholesky factorization and solves of symmetric
//!   positive-definite systems in `f32` or `f64`, on fixed-size buffers.
//!
//! The core is math and learners only: the wire protocol of primo's
//! devices is the crate `primo-protocol`, the learner behind it
//! `primo-learner`, the scale `primo-device`.
//!
//! All arithmetic is `f32` with [`libm`] functions only, and every public
//! function returns an [`Error`] on bad input instead of panicking.
//!
//! ```
//! use primo_core::dmp::{Dmp, FitOptions};
//! // A 1-DoF demonstration: 0 → 1 over one second, sampled at 101 points.
//! let t: Vec<f32> = (0..101).map(|i| i as f32 / 100.0).collect();
//! let y: Vec<f32> = t.iter().map(|&t| t * t * (3.0 - 2.0 * t)).collect();
//! let dmp = Dmp::<1, 20>::fit(&t, &y, 1, 20, &FitOptions::default())?;
//! let mut run = dmp.start(&dmp.execution())?;
//! while run.time() < 1.0 {
//!     run.step(&dmp, 0.001)?;
//! }
//! assert!((run.position()[0] - 1.0).abs() < 1e-2);
//! # Ok::<(), primo_core::Error>(())
//! ```
#![no_std]
#![deny(missing_docs)]
// `!(x > 0.0)` is the idiom that also rejects NaN; keep it.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing,
        clippy::unreachable,
        clippy::todo,
        clippy::unimplemented
    )
)]

#[cfg(test)]
extern crate std;

pub mod coupling;
pub mod dmp;
mod error;
pub mod generalize;
pub mod golden;
pub mod illinois;
pub mod linalg;
pub mod normal;
pub mod orientation;
pub mod power;
pub mod promp;
pub mod quaternion;
pub mod rhythmic;
pub mod rng;
pub mod secant;
mod spring;
pub mod tangent;
mod vec3;

pub use error::{Error, check_capacity, check_len};
