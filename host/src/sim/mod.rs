//! The simulated pouring cell: a KUKA LWR4 arm holding a bottle over a glass
//! on a precision scale (DESIGN.md §3). Built up piece by piece, each with
//! unit tests of its physics.
//!
//! - [`arm`]: LWR4 forward kinematics from the DH table, the tool transform,
//!   joint position and velocity limits.
//! - [`bottle`]: the liquid's free surface in a tilted bottle and the
//!   outflow over its mouth.

pub mod arm;
pub mod bottle;
