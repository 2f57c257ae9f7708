//! `--model`, `--base`, `--tip`: the robot a trajectory is for, any serial
//! arm from its URDF or the built-in KUKA LWR 4.

use std::path::PathBuf;

use primo_robot::chain::Chain;
use primo_robot::urdf::Urdf;
use primo_robot::{Robot, Tip};

use crate::error::CliError;
use crate::output::read;

/// The robot's model.
#[derive(Debug, clap::Args)]
pub struct ModelArgs {
    /// The robot's URDF (default: the built-in KUKA LWR 4, joints
    /// `a1..a7`, also `A1..A7`, `j1..j7`, `joint_1..joint_7`).
    #[arg(long, value_name = "ROBOT.urdf")]
    model: Option<PathBuf>,
    /// The chain's base link (default: the URDF's root link).
    #[arg(long, value_name = "LINK", requires = "model")]
    base: Option<String>,
    /// The chain's tip link (default: the one leaf below the base).
    #[arg(long, value_name = "LINK", requires = "model")]
    tip: Option<String>,
}

impl ModelArgs {
    /// The chain: the URDF's from its base to its tip, read and checked,
    /// or the LWR 4's.
    pub fn chain(&self) -> Result<Chain, CliError> {
        self.chain_or(|| Robot::lwr4().chain())
    }

    /// The chain: the URDF's, or `builtin`'s without `--model`.
    pub fn chain_or(&self, builtin: impl FnOnce() -> Chain) -> Result<Chain, CliError> {
        let Some(path) = &self.model else {
            return Ok(builtin());
        };
        let file = path.display().to_string();
        let urdf = Urdf::parse(&file, &read(Some("--model"), path)?)
            .map_err(|e| CliError::input(e.to_string()))?;
        let tip = Tip {
            base: self.base.clone(),
            tip: self.tip.clone(),
            ..Tip::default()
        };
        Chain::from_urdf(&urdf, &tip).map_err(|e| CliError::input(e.to_string()))
    }
}

/// `NAME (J joints, BASE to TIP)`.
pub fn describe(chain: &Chain) -> String {
    format!(
        "{} ({} joints, {} to {})",
        chain.robot,
        chain.dof(),
        chain.base,
        chain.tip
    )
}
