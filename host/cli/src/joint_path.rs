//! A joint trajectory file, read and passed through a robot's limit checks
//! before any driver may send it.

use std::path::Path;

use primo_robot::JointPath;
use primo_robot::chain::Chain;
use primo_robot::columns::Columns;
use primo_robot::safety::check_path;
use primo_skill::csv::parse_demo;

use crate::error::CliError;
use crate::output::read;

/// Reads a joint trajectory of `chain` and passes it through its limit
/// checks; `driver` streams joint angles.
pub fn load(path: &Path, chain: &Chain, driver: &str) -> Result<JointPath, CliError> {
    let file = path.display().to_string();
    let demo = parse_demo(&file, &read(None, path)?)?;
    let rejected = |why: String| {
        CliError::input(format!(
            "{file}: trajectory rejected, nothing sent to the robot: {why}"
        ))
    };
    let columns = match Columns::of(chain, &demo.names) {
        Ok(c @ Columns::Joints(_)) => c,
        Ok(Columns::Pose(_)) => {
            return Err(CliError::input(format!(
                "{file}: a tool trajectory: {driver} streams joint angles; solve it with `primo robot \
                 check` first or give the joints ({})",
                chain.names().join(",")
            )));
        }
        Err(e) => return Err(CliError::input(format!("{file}: {e}"))),
    };
    let rows: Vec<f64> = demo.positions.iter().map(|v| f64::from(*v)).collect();
    let times = demo.times.iter().map(|t| f64::from(*t)).collect();
    check_path(chain, times, columns.reorder(&rows), None).map_err(|why| rejected(why.to_string()))
}
