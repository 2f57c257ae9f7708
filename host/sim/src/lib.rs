//! The simulated pouring cell and its simulated devices: a KUKA LWR4 arm
//! (its model from `primo-robot`) holding a bottle over a glass on a
//! precision scale. Each physical piece has unit tests.
//!
//! - [`bottle`]: the liquid's free surface in a tilted bottle and the
//!   outflow over its mouth.
//! - [`stream`]: the stream's flight to the glass, captured and spilled.
//! - [`scale`]: the precision scale under the glass.
//! - [`cell`]: all of it together, one control step at a time.
//! - [`expert`]: a scripted expert who pours the demonstrations.
//! - [`krc`]: a simulated KRC, the robot side of FRI, driving the cell,
//!   with fault injection for the tests: a state machine sans I/O, and on
//!   UDP.
//! - [`fci`]: a simulated Franka controller, the robot side of the FCI
//!   (TCP command channel and 1 kHz UDP state stream), with fault
//!   injection for the tests.
//! - [`scale_device`]: the cell's scale speaking MT-SICS, sans I/O, and
//!   served on a pseudo-terminal.
//! - [`load_cell`]: the cell's scale as a bare load cell: raw ADC counts
//!   for the scale firmware, sent on a pseudo-terminal.
#![deny(missing_docs)]

pub mod bottle;
pub mod cell;
mod error;
pub mod expert;
pub mod fci;
pub mod krc;
pub mod load_cell;
pub mod scale;
pub mod scale_device;
pub mod stream;

pub use error::Error;
