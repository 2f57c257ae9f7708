//! Mettler Toledo MT-SICS precision scales (DESIGN.md §4): the protocol,
//! a client for a scale on a serial port, and the simulated scale served
//! as an MT-SICS device on a pseudo-terminal.
//!
//! - [`parse_response`] turns any line into a typed [`Response`] or an
//!   error quoting it; [`Response`]'s `Display` writes the line back.
//! - [`Scale`]: the client (`@`, `S`, `SI`, `Z`, `T`, `TAC`) with
//!   timeouts, retries, and skipping of power-on lines.
//! - [`Device`]: the simulated scale speaking MT-SICS without I/O;
//!   [`PtyServer`] serves it on a new pseudo-terminal, its load coming
//!   from any [`LoadSource`] (a [`LoadHandle`] for a shared value).
//! - [`commands`]: `primo scale serve` and `primo scale read`.
//!
//! A round trip over a real pseudo-terminal:
//!
//! ```
//! use primo_host::mtsics::{ClientConfig, Device, DeviceConfig, LoadHandle, PtyServer, Scale};
//! use primo_host::sim::scale::ScaleModel;
//! let model = ScaleModel::default();
//! let load = LoadHandle::new(250.0);
//! let mut device = Device::new(model, 1, load.clone(), DeviceConfig::for_model(&model)).unwrap();
//! device.advance(30.0); // the load has settled
//! let server = PtyServer::start(device).unwrap();
//! let mut scale = Scale::open(server.path(), ClientConfig::default()).unwrap();
//! let grams = scale.stable().unwrap().grams();
//! assert!((grams - 250.0).abs() <= 0.02, "{grams}");
//! drop(scale);
//! server.stop().unwrap();
//! ```

mod client;
pub mod commands;
mod protocol;
mod server;

pub use client::{ClientConfig, ErrorKind, Scale, ScaleError};
pub use protocol::{
    Density, MAX_LINE, Reply, Response, ResponseError, Stability, Unit, Weight, parse_response,
    quote,
};
pub use server::{Control, Device, DeviceConfig, LoadHandle, LoadSource, PtyServer};
