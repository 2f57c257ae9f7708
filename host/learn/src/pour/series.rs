//! A roll-out's time series: the coordinates commanded and what the cell
//! measured at every recorded control step, and its CSV form.
//!
//! ```
//! use primo_learn::pour::rig::{Simulated, roll_out};
//! use primo_learn::pour::skill::built_in_skill;
//! use primo_sim::cell::{CellConfig, GlassKind};
//! use primo_learn::pour::skill::Space;
//!
//! let cell = CellConfig::standard(GlassKind::Normal);
//! let skill = built_in_skill(&cell, Space::Cartesian, 10)?;
//! // Only a recording cell pays for the series.
//! let mut rig = Simulated::new(cell, 0.5, 1)?.recording(1);
//! let trial = roll_out(&mut rig, &skill, 0.2, 1, &[0.5], &[])?;
//! let series = trial.series.expect("the cell recorded");
//! let csv = String::from_utf8(series.to_csv()).unwrap();
//! assert!(csv.starts_with("t,x,y,z,qw,qx,qy,qz,tilt_rad,"));
//! assert_eq!(csv.lines().count(), series.samples.len() + 1);
//! # Ok::<(), primo_learn::Error>(())
//! ```

use std::path::Path;

use primo_sim::cell::Sample;
use primo_skill::csv::Csv;

use crate::Error;
use crate::output::write_file;

use super::skill::Space;

/// The columns after the commanded coordinates.
pub const MEASURED: &str = "tilt_rad,mouth_x_m,mouth_y_m,mouth_z_m,flow_l_per_s,bottle_l,in_flight_l,glass_l,spilled_l,scale_g,stable";

/// The values of [`MEASURED`] in a sample, `stable` as 1 or 0.
pub fn measured(s: &Sample) -> [f64; 11] {
    let v = &s.totals;
    [
        s.tilt,
        s.mouth[0],
        s.mouth[1],
        s.mouth[2],
        s.flow,
        v.bottle,
        v.in_flight,
        v.glass,
        v.spilled,
        s.scale,
        f64::from(u8::from(s.stable)),
    ]
}

/// A roll-out's time series.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// The space of the commanded coordinates (their names are its names).
    pub space: Space,
    /// Per sample, the coordinates commanded in the control step that
    /// ended at the sample's time (while the scale settles: the movement's
    /// last), row-major.
    pub commands: Vec<f64>,
    /// What the cell recorded.
    pub samples: Vec<Sample>,
}

impl Series {
    /// Joins the cell's `samples`, recorded every `every` control steps,
    /// with the plan that drove it: `rows` of `dof` coordinates, one per
    /// step.
    pub fn new(space: Space, rows: &[f64], dof: usize, every: usize, samples: Vec<Sample>) -> Self {
        let steps = rows.len() / dof.max(1);
        let mut commands = Vec::with_capacity(samples.len() * dof);
        for k in 1..=samples.len() {
            // Sample k was taken after step k·every; the step's row is one
            // less, and the last row holds while the scale settles.
            let row = (k * every).min(steps).saturating_sub(1);
            match rows.get(row * dof..(row + 1) * dof) {
                Some(values) => commands.extend_from_slice(values),
                None => commands.extend(std::iter::repeat_n(f64::NAN, dof)),
            }
        }
        Series {
            space,
            commands,
            samples,
        }
    }

    /// The CSV text: the header, then one row per sample. Time in seconds
    /// to the microsecond, the commanded coordinates as the f32 the DMP
    /// computed, the measurements as exactly as `f64` prints (flow in l/s,
    /// volumes in l), the scale's display in g as its digits; `stable` is
    /// 1 or 0.
    pub fn to_csv(&self) -> Vec<u8> {
        let dof = self.space.names().len();
        let mut csv = Csv::new();
        csv.text("t");
        for name in self
            .space
            .names()
            .iter()
            .copied()
            .chain(MEASURED.split(','))
        {
            csv.text(name);
        }
        csv.end_row();
        for (s, command) in self.samples.iter().zip(self.commands.chunks_exact(dof)) {
            csv.seconds(s.t);
            // The plan is f32 (the DMP's): printed as f32, no false digits.
            for v in command {
                csv.display(*v as f32);
            }
            let m = measured(s);
            for v in &m[..9] {
                // + 0.0 turns an empty sum's -0 into 0.
                csv.display(v + 0.0);
            }
            // The display's digits (198.98, not 198.98000000000002).
            csv.display(m[9] as f32 + 0.0).display(u8::from(s.stable));
            csv.end_row();
        }
        csv.into_bytes()
    }
}

/// Writes `series` as CSV to `path`, atomically; without a series (the
/// roll-out was rejected and never ran) the file holds only the header.
pub fn write_csv(path: &Path, space: Space, series: Option<&Series>) -> Result<(), Error> {
    let csv = match series {
        Some(s) => s.to_csv(),
        None => Series::new(space, &[], 0, 1, Vec::new()).to_csv(),
    };
    write_file(path, &csv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pour::rig::{Simulated, roll_out};
    use crate::pour::skill::built_in_skill;
    use primo_sim::cell::{CellConfig, GlassKind};

    #[test]
    fn commands_line_up_with_the_samples() {
        let cell = CellConfig::standard(GlassKind::Small);
        let skill = built_in_skill(&cell, Space::Joint, 10).unwrap();
        let rig = Simulated::new(cell, 0.5, 1).unwrap();
        let trial = roll_out(&mut rig.recording(3), &skill, 0.2, 1, &[0.5], &[]).unwrap();
        let series = trial.series.unwrap();
        assert_eq!(series.commands.len(), 7 * series.samples.len());
        let arm = cell.arm();
        // The mouth the cell recorded is where the commanded joints put it.
        for (s, q) in series.samples.iter().zip(series.commands.chunks_exact(7)) {
            let pose = arm.forward(&std::array::from_fn(|j| q[j]));
            let (mouth, _) = cell.mouth_and_orientation(&pose);
            assert_eq!(mouth, s.mouth, "t {}", s.t);
        }
        let dt = series.samples[1].t - series.samples[0].t;
        assert!((dt - 3.0 * cell.dt).abs() < 1e-12);
        // Not recording: no series.
        let trial = roll_out(&mut rig.recording(0), &skill, 0.2, 1, &[0.5], &[]).unwrap();
        assert!(trial.series.is_none());
    }

    #[test]
    fn settling_holds_the_last_command() {
        let sample = Sample {
            t: 0.0,
            tilt: 0.0,
            mouth: [0.0; 3],
            flow: 0.0,
            totals: Default::default(),
            scale: 0.0,
            stable: false,
        };
        let rows = [1.0, 10.0, 2.0, 20.0, 3.0, 30.0];
        let s = Series::new(Space::Joint, &rows, 2, 2, vec![sample; 4]);
        assert_eq!(s.commands, [2.0, 20.0, 3.0, 30.0, 3.0, 30.0, 3.0, 30.0]);
        let none = Series::new(Space::Joint, &[], 2, 1, vec![sample]);
        assert!(none.commands.iter().all(|v| v.is_nan()) && none.commands.len() == 2);
    }
}
