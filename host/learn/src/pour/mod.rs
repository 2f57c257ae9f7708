//! The built-in pouring task: a bottle poured into a glass on a scale,
//! on the simulated cell or a real one (a KUKA LWR 4 over FRI and a scale:
//! MT-SICS, or primo's own), learning the bottle's volume `q̂` (and with
//! PoWER the movement) to pour a target volume.
//!
//! - [`run`]: the pour as a kind of run; [`settings`]: what it learns and
//!   how; [`skill`]: its demonstrations and the cell's gate.
//! - [`rig`]: where its roll-outs happen; [`weigh`]: the scales a real
//!   cell weighs with; [`trial`]: what a roll-out measured, scored.
//! - [`report`], [`series`]: what it writes.
//! - [`simulate`]: learning on the simulated cell without a log;
//!   [`objective`]: the simulated cell as an objective for any optimizer.

pub mod objective;
pub mod report;
pub mod rig;
pub mod run;
pub mod series;
pub mod settings;
pub mod simulate;
pub mod skill;
pub mod trial;
pub mod weigh;

/// The simulated cell and its devices report in the library's terms: a
/// refused setting or movement is bad input, a failed device a failure
/// while running.
impl From<primo_sim::Error> for crate::Error {
    fn from(e: primo_sim::Error) -> Self {
        match e {
            primo_sim::Error::Invalid(why) => crate::Error::Invalid(why),
            primo_sim::Error::Io(why) => crate::Error::Instrument(why),
        }
    }
}
