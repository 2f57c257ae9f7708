//! `primo demo`: demonstrations synthesized on the simulated cell.

use std::path::PathBuf;

use primo_mtsics::Fixed;
use primo_sim::cell::{CellConfig, GlassKind};
use primo_sim::expert::{Style, synthesize};
use primo_skill::csv::write_rows;

use crate::args::Space;
use crate::error::CliError;
use crate::output::{check_out_file, emit};

/// `primo demo …`.
#[derive(Debug, clap::Subcommand)]
pub enum DemoCommand {
    /// A scripted, slightly imperfect expert pours on the simulated cell;
    /// the movement is written as CSV (`t,x,y,z,qw,qx,qy,qz`: the mouth and
    /// the bottle's orientation, a sign-continuous unit quaternion; or
    /// `t,a1..a7`).
    Synth {
        /// Record the bottle pose or the joint angles.
        #[arg(long, value_enum, default_value_t = Space::Cartesian)]
        space: Space,
        /// Liquid in the bottle, l.
        #[arg(long, default_value_t = 0.5)]
        bottle: f64,
        /// Volume to pour, l.
        #[arg(long, default_value_t = 0.2)]
        pour: f64,
        /// Angle at which the demonstrator holds joint 3, rad.
        #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
        elbow: f64,
        /// Seed of the expert's imperfections.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output CSV file (stdout when absent).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// Runs a `primo demo` command.
pub fn run(command: DemoCommand) -> Result<(), CliError> {
    let DemoCommand::Synth {
        space,
        bottle,
        pour,
        elbow,
        seed,
        out,
    } = command;
    if let Some(out) = &out {
        check_out_file("--out", out, &[])?;
    }
    let cell = CellConfig::standard(GlassKind::Normal);
    let demo = synthesize(&cell, bottle, pour, &Style { elbow, seed })?;
    eprintln!(
        "primo: the expert poured {} ml (spilled {} ml) from {bottle} l in {:.2} s",
        Fixed(demo.poured * 1e3, 1),
        Fixed(demo.spilled * 1e3, 1),
        demo.t.last().copied().unwrap_or(0.0)
    );
    let csv = primo_learn::pour::skill::to_csv_demo(&demo, space.into());
    let mut buf = Vec::new();
    let dof = csv.names.len();
    write_rows(
        &mut buf,
        &csv.names,
        csv.times
            .iter()
            .zip(csv.positions.chunks_exact(dof))
            .map(|(t, row)| (*t, row.iter().copied())),
    )
    .map_err(|e| CliError::other(format!("writing the demonstration: {e}")))?;
    emit(out.as_deref(), &buf)
}
