//! The simulated pouring cell: a KUKA LWR4 arm holding a bottle over a glass
//! on a precision scale (DESIGN.md §3). Each physical piece has unit tests.
//!
//! - [`arm`]: LWR4 forward and inverse kinematics from the DH table, joint
//!   position and velocity limits.
//! - [`bottle`]: the liquid's free surface in a tilted bottle and the
//!   outflow over its mouth.
//! - [`stream`]: the stream's flight to the glass, captured and spilled.
//! - [`scale`]: the precision scale under the glass.
//! - [`cell`]: all of it together, one control step at a time.
//! - [`expert`]: a scripted expert who pours the demonstrations.

pub mod arm;
pub mod bottle;
pub mod cell;
pub mod expert;
pub mod scale;
pub mod stream;
