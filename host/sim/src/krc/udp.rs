//! The simulated KRC on a UDP socket: [`SimKrc`] drives a [`Krc`] with
//! the wall clock, sends its measurements to the remote and hands it what
//! arrives; and it serves the cell's scale to other processes.

use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use primo_fri::udp::transient;

use super::config::{CellHandle, KrcConfig};
use super::machine::Krc;
use super::report::KrcReport;
use crate::Error;
use crate::load_cell::{LoadCellModel, LoadCellServer};
use crate::scale_device::{Device, DeviceConfig, PtyServer};

/// How often the KRC looks for the answer within a cycle.
const POLL: Duration = Duration::from_micros(100);

/// The simulated KRC, bound and ready to run.
#[derive(Debug)]
pub struct SimKrc {
    socket: UdpSocket,
    krc: Krc,
}

impl SimKrc {
    /// Checks `cfg`, fills the cell's bottle and binds an ephemeral UDP
    /// port (the KRC's own address; the remote answers to it).
    pub fn new(cfg: KrcConfig) -> Result<SimKrc, Error> {
        let krc = Krc::new(cfg)?;
        let any: SocketAddr = if cfg.remote.is_ipv4() {
            ([0, 0, 0, 0], 0).into()
        } else {
            ([0u16; 8], 0).into()
        };
        let socket =
            UdpSocket::bind(any).map_err(|e| Error::Io(format!("cannot bind UDP {any}: {e}")))?;
        Ok(SimKrc { socket, krc })
    }

    /// The shared cell.
    pub fn cell(&self) -> CellHandle {
        self.krc.cell()
    }

    /// Serves the cell's scale as an MT-SICS device on a new
    /// pseudo-terminal ([`PtyServer`], not thread-safe to start): the
    /// cell's scale model with the noise from the KRC's seed, weighing the
    /// cell's pan in wall-clock time.
    pub fn serve_scale(&self) -> Result<PtyServer, Error> {
        let cfg = self.krc.config();
        let model = cfg.cell_config().scale;
        let device = Device::new(
            model,
            cfg.seed,
            self.cell(),
            DeviceConfig::for_model(&model),
        )?;
        PtyServer::start(device)
            .map_err(|e| Error::Io(format!("cannot serve the scale on a pseudo-terminal: {e}")))
    }

    /// Serves the cell's scale as a bare load cell ([`LoadCellServer`],
    /// not thread-safe to start): raw counts of the pan's load on a new
    /// pseudo-terminal, the noise from the KRC's seed.
    pub fn serve_load_cell(&self) -> Result<LoadCellServer, Error> {
        let cfg = self.krc.config();
        let model = LoadCellModel {
            scale: cfg.cell_config().scale,
            ..LoadCellModel::default()
        };
        LoadCellServer::start(model, cfg.seed, self.cell()).map_err(|e| {
            Error::Io(format!(
                "cannot serve the load cell on a pseudo-terminal: {e}"
            ))
        })
    }

    /// The KRC's own UDP address.
    pub fn local_addr(&self) -> Result<SocketAddr, Error> {
        self.socket.local_addr().map_err(socket_error)
    }

    /// Runs until `stop` is set, `stop_after` passes, or (with `once`) a
    /// command session ends. Errors are socket failures.
    pub fn run(self, stop: &AtomicBool) -> Result<KrcReport, Error> {
        let SimKrc { socket, mut krc } = self;
        let remote = krc.config().remote;
        socket.set_nonblocking(true).map_err(socket_error)?;
        let mut buf = [0u8; 2048];
        loop {
            // A cycle opens when it is due: its measurement goes out now.
            if stop.load(Ordering::Relaxed) {
                break;
            }
            if let Some(measurement) = krc.poll_transmit(Instant::now()) {
                socket.send_to(&measurement, remote).map_err(socket_error)?;
            }
            let Some(deadline) = krc.poll_timeout() else {
                break;
            };
            // Until the cycle's end, what arrives. Poll rather than block
            // with a timeout: socket timeouts round up to the kernel's
            // tick (4 ms at 250 Hz), sleeps do not.
            loop {
                match socket.recv_from(&mut buf) {
                    Ok((n, _)) => {
                        if let Some(datagram) = buf.get(..n) {
                            krc.handle_datagram(Instant::now(), datagram);
                        }
                        continue;
                    }
                    Err(e) if transient(&e) => {}
                    Err(e) => return Err(socket_error(e)),
                }
                let now = Instant::now();
                if now >= deadline {
                    break;
                }
                let left = deadline - now;
                std::thread::sleep(if krc.awaiting_answer() {
                    left.min(POLL)
                } else {
                    left
                });
            }
            krc.handle_timeout(Instant::now());
        }
        Ok(krc.into_report())
    }
}

fn socket_error(e: std::io::Error) -> Error {
    Error::Io(format!("KRC socket: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_settings_are_refused() {
        let remote = SocketAddr::from(([127, 0, 0, 1], 49938));
        let mut cfg = KrcConfig::new(remote);
        cfg.cycle = Duration::from_millis(20);
        assert_eq!(
            SimKrc::new(cfg).unwrap_err().to_string(),
            "FRI cycle 20 ms: must be 1 to 10 ms"
        );
        let mut cfg = KrcConfig::new(remote);
        cfg.drop = 1.0;
        assert!(
            SimKrc::new(cfg)
                .unwrap_err()
                .to_string()
                .starts_with("packet loss 1")
        );
        let mut cfg = KrcConfig::new(remote);
        cfg.start[1] = 2.2;
        assert!(
            SimKrc::new(cfg)
                .unwrap_err()
                .to_string()
                .starts_with("start position: joint a2 at sample 0")
        );
        let mut cfg = KrcConfig::new(remote);
        cfg.thresholds = [0.9, 0.8, 0.98];
        assert!(SimKrc::new(cfg).is_err());
    }
}
