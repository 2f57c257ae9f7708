//! The panels every learning chart shares (a quantity over the roll-outs,
//! the reward of every roll-out), and writing a chart as a PNG file.

use std::path::Path;

use crate::Error;
use crate::output::write_file;

use super::{Line, Panel, render_png};

/// Height of a row of panels, px.
const PANEL_HEIGHT: u32 = 350;

/// A linear panel over the roll-outs.
pub fn per_rollout<'a>(title: &'a str, y_label: &'a str, series: &'a [Line<'a>]) -> Panel<'a> {
    Panel {
        title,
        x_label: "roll-out",
        y_label,
        series,
        ..Panel::default()
    }
}

/// The reward of every roll-out from (roll-out, of the mean policy,
/// reward): the mean policy's, and the explorations' around it.
pub fn rewards(rows: impl Iterator<Item = (u32, bool, f64)>) -> [Vec<(f64, f64)>; 2] {
    let mut split = [Vec::new(), Vec::new()];
    for (rollout, mean, reward) in rows {
        split[usize::from(!mean)].push((f64::from(rollout), reward));
    }
    split
}

/// The reward panel's series: the mean policy's line, the explorations'
/// markers.
pub fn reward_lines(split: &[Vec<(f64, f64)>; 2]) -> [Line<'_>; 2] {
    [
        Line::new("mean policy", &split[0]),
        Line {
            scatter: true,
            ..Line::new("exploration", &split[1])
        },
    ]
}

/// Writes a run's `convergence.png` into `dir`: `panels` in rows of
/// 350 px.
pub fn write_convergence(dir: &Path, panels: &[Panel<'_>]) -> Result<(), Error> {
    let rows = super::grid(panels.len()).0 as u32;
    write_png(&dir.join("convergence.png"), panels, PANEL_HEIGHT * rows)
}

/// Renders `panels`, 1000 px wide and `height` high, into the PNG file
/// `path`, atomically.
pub fn write_png(path: &Path, panels: &[Panel<'_>], height: u32) -> Result<(), Error> {
    let bytes = render_png(panels, 1000, height)
        .map_err(|e| Error::Report(format!("{}: {e}", path.display())))?;
    write_file(path, &bytes)
}
