//! Discrete, multi-DoF Dynamic Movement Primitives of fixed capacity.
//!
//! # Formulation
//!
//! Per degree of freedom, with `τ` the execution time in seconds (the
//! movement runs from `t = 0` to `t = τ`; there is no separate "execution
//! time" knob):
//!
//! ```text
//! τ ż = α (β (g − y) − z) + a · f(s),   τ ẏ = z,   β = α / 4
//! s   = min(t / τ, 1)                              (phase)
//! f(s) = Σ ψ_k(s) w_k / Σ ψ_k(s) for s < 1, 0 for s ≥ 1
//! ψ_k(s) = exp(−h (s − c_k)²),  c_k = (k − m) / (K − 1 − 2m)
//! a   = g − y0  (amplitude-scaled DoF)  or  1  (loop-like DoF)
//! ```
//!
//! or, scaling globally ([`Scaling::Global`], Koutras & Doulgeri 2020, their
//! eq. 11), the forcing terms of a group of DoFs (the positions) as one
//! vector, fitted as demonstrated and executed as `k·R·f(s)`: `k = ‖g −
//! y0‖/‖g_d − y0_d‖` and `R` the smallest rotation taking the demonstrated
//! `g_d − y0_d` ([`Dmp::reference`]) onto `g − y0`. With the spring linear
//! the run is the demonstrated one turned and stretched about the start.
//! [`Scaling::Never`] leaves every forcing term as demonstrated.
//!
//! Why this form, against the anchors' known failures:
//! - The forcing term is scaled by the new amplitude `g − y0`, so a goal moved
//!   close to the start shrinks the whole shape instead of overshooting
//!   (movement_primitives issue 70).
//! - A DoF whose demonstration starts and ends (almost) at the same place
//!   cannot be amplitude-scaled; it keeps an unscaled forcing term, so loops
//!   and shakes are reproduced (pydmps issue 5). [`Scaling::Auto`] decides per
//!   DoF; [`Scaling::Mask`] overrides.
//! - The phase reaches 1 exactly at `t = τ` and the forcing term is exactly zero
//!   afterwards: no Pastor-style `x(T) ≠ 0` residue pulling away from the goal.
//! - The kernels are uniform in `s`, so only the few within reach of the
//!   current phase are evaluated (see [`Dmp::forcing`]).
//! - The outer kernels may lie `m` spacings beyond the movement's ends
//!   ([`Margin`]). With `m = 0` the first and last kernels sit on the ends,
//!   where the normalized kernels can hardly bend: once a movement is
//!   resolved (enough kernels) that is where most of a fit's error is, and
//!   one spacing beyond each end reproduces it up to 30× better. With few
//!   kernels the interior's resolution counts more, so a fit tries both
//!   and keeps the better ([`Margin::Auto`]).
//! - The spring-damper is critically damped and linear, so a step with the
//!   forcing held at its mid-step value is integrated exactly (matrix
//!   exponential), not by Euler: any `dt` is stable and the error is
//!   second order in `dt` only through the forcing term.
//!
//! # Bounds, and reaching the goal
//!
//! A DMP takes values only in documented ranges, and within them every
//! sample it integrates is finite (the `dmp` fuzz target checks this on
//! arbitrary demonstrations, gains, goals and steps): weights within
//! ±[`MAX_ABS_WEIGHT`], starts and goals within ±[`MAX_ABS_POSITION`], `α`
//! in [[`MIN_ALPHA`], [`MAX_ALPHA`]], `τ ≥` [`MIN_TAU`], any `dt > 0`.
//!
//! It reaches its goal whatever the weights within those bounds: once the
//! phase is 1 (the first step past `τ`) the forcing term is exactly zero
//! and each step is the exact solution of the critically damped spring, so
//! `s·τ` seconds later
//!
//! ```text
//! |y − g| ≤ (1 + αs/2)·e^(−αs/2) · (|y − g| + 2τ|ẏ|/α at phase 1)
//! ```
//!
//! up to `f32` rounding: below 4e−10 of that deviation by `s = 50/α` (2τ
//! at the default `α` = 25). Property-tested in `core/tests/properties.rs`.
//!
//! # Parameter vector
//!
//! [`Dmp::params`] / [`Dmp::set_params`] expose `θ` for generalization and
//! learning, laid out as `[w_{0,0..K}, w_{1,0..K}, …, w_{D−1,0..K}, g_0, …,
//! g_{D−1}, τ]`: `D·K + D + 1` values (7 joints × 30 kernels → 218).
//!
//! ```
//! use primo_core::dmp::{Dmp, FitOptions};
//! let t: Vec<f32> = (0..=200).map(|i| i as f32 / 200.0).collect();
//! // Two DoF, row-major samples.
//! let y: Vec<f32> = t.iter().flat_map(|&t| [t, 1.0 - t * t]).collect();
//! let dmp = Dmp::<2, 15>::fit(&t, &y, 2, 15, &FitOptions::default())?;
//! let mut exec = dmp.execution();
//! exec.goal[0] = 2.0; // new goal for DoF 0
//! exec.tau = 2.0; // twice as slow
//! let last = dmp.trajectory(&exec, 0.01)?.last().unwrap();
//! assert_eq!(last.time, 2.0);
//! assert!((last.position[0] - 2.0).abs() < 1e-2);
//! # Ok::<(), primo_core::Error>(())
//! ```

mod fit;
mod integrator;
mod kernels;
mod model;
mod options;
#[cfg(feature = "global-scaling")]
mod turn;
mod via;

pub use integrator::{Run, Sample, Trajectory};
pub use model::{Dmp, Execution, Shape};
pub(crate) use options::check_alpha;
pub use options::{
    AUTO_MARGIN, AUTO_SAMPLES_PER_SPACING, AUTO_SCALING_MIN_FRACTION, DEFAULT_ALPHA,
    DEFAULT_OVERLAP, FINAL_VELOCITY_WINDOW, FinalVelocity, FitOptions, KERNEL_CUTOFF,
    LEARNING_OVERLAP, MAX_ABS_POSITION, MAX_ABS_WEIGHT, MAX_ALPHA, MIN_ALPHA, MIN_TAU, Margin,
    Scaling, max_margin,
};
pub use via::{MAX_VIA_POINTS, ViaPoint};
