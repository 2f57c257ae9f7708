//! `primo rollout`: parameter vectors executed on the simulated cell, an
//! objective for any optimizer.

use std::io::{BufRead, Write};
use std::path::PathBuf;

use primo_learn::learning::{QUERY_DECAY, check_target, power_blocks};
use primo_learn::rig::Simulated;
use primo_learn::trial::Trial;
use primo_skill::Skill;

use crate::args::{Glass, Space};
use crate::error::CliError;
use crate::output::{check_out_file, read};
use crate::pour::SkillArgs;

/// `primo rollout` options.
#[derive(Debug, clap::Args)]
pub struct RolloutArgs {
    /// JSON array `[weights (dof×kernels, row by row), goals (dof), τ,
    /// q̂]`: θ is absolute; the movement executed is θ + G(q̂) − G(bottle).
    #[arg(long, conflicts_with_all = ["serve", "print_start"])]
    params: Option<PathBuf>,
    /// Answer JSON-array lines on stdin with one JSON line each.
    #[arg(long, conflicts_with = "print_start")]
    serve: bool,
    /// Print the generalized start vector and PoWER's exploration std.
    #[arg(long)]
    print_start: bool,
    /// With --params: write the roll-out's time series (every 2 ms control
    /// step) to this CSV file.
    #[arg(long, requires = "params", conflicts_with_all = ["serve", "print_start"], value_name = "FILE")]
    series: Option<PathBuf>,
    /// Liquid in the bottle, l.
    #[arg(long, default_value_t = 0.5)]
    bottle: f64,
    /// Volume to pour, l.
    #[arg(long, default_value_t = 0.2, allow_hyphen_values = true)]
    target: f64,
    #[command(flatten)]
    skill: SkillArgs,
    /// Seed of the scale's noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

/// Parses a roll-out vector: a JSON array of `len` finite numbers.
fn parse_params(what: &str, text: &str, len: usize) -> Result<Vec<f32>, String> {
    let values: Vec<f64> = serde_json::from_str(text)
        .map_err(|e| format!("{what}: not a JSON array of numbers: {e}"))?;
    if values.len() != len {
        return Err(format!(
            "{what}: {} values, the layout needs {len} (weights, goals, τ, q̂)",
            values.len()
        ));
    }
    values
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let x = *v as f32;
            if x.is_finite() {
                Ok(x)
            } else {
                Err(format!("{what}: value {} is out of f32 range", i + 1))
            }
        })
        .collect()
}

/// The cell and the skill, for one roll-out after another.
struct Objective {
    space: primo_skill::Space,
    skill: Skill,
    rig: Simulated,
    base: Vec<f32>,
    bottle: f64,
    target: f64,
}

impl Objective {
    /// One roll-out of the vector `x = [θ, q̂]`: Δθ = θ − G(bottle); the
    /// scale's noise from `seed`.
    fn roll_out(&self, x: &[f32], seed: u64) -> Result<(serde_json::Value, Trial), String> {
        let (theta, query) = x.split_at(self.base.len());
        let query = query.first().copied().unwrap_or(self.bottle as f32);
        let delta: Vec<f32> = theta.iter().zip(&self.base).map(|(t, b)| t - b).collect();
        let trial = match self.skill.checked(
            primo_learn::rig::Rig::gate(&self.rig),
            primo_learn::rig::Rig::dt(&self.rig),
            &[query],
            &delta,
        ) {
            Ok((plan, path)) => Trial::scored(
                self.target,
                self.rig
                    .execute_seeded(&plan, &path, seed)
                    .map_err(|e| e.to_string())?,
            ),
            Err(why) => Trial::rejected(self.target, why.to_string()),
        };
        let answer = serde_json::json!({
            "poured": trial.poured,
            "spilled": trial.spilled,
            "error": trial.error,
            "reward": trial.reward,
            "safe": trial.rejected.is_none(),
            "rejected": trial.rejected,
        });
        Ok((answer, trial))
    }
}

/// Runs `primo rollout`.
pub fn run(args: &RolloutArgs) -> Result<(), CliError> {
    check_target(args.bottle, args.target)?;
    if let Some(series) = &args.series {
        check_out_file("--series", series)?;
    }
    let spec = args.skill.spec(Space::Joint, Glass::Normal)?;
    let (cell, skill) = spec.build()?;
    let rig =
        Simulated::new(cell, args.bottle, args.seed)?.recording(usize::from(args.series.is_some()));
    let base = skill.generalize(&[args.bottle as f32])?;
    let len = base.len() + 1;
    let objective = Objective {
        space: spec.space,
        skill,
        rig,
        base,
        bottle: args.bottle,
        target: args.target,
    };
    if args.print_start {
        return print_start(&objective);
    }
    if args.serve {
        return serve(&objective, args.seed, len);
    }
    let path = args
        .params
        .as_deref()
        .ok_or_else(|| CliError::input("give --params FILE, --serve or --print-start"))?;
    let x =
        parse_params(&path.display().to_string(), &read(path)?, len).map_err(CliError::input)?;
    let (answer, trial) = objective.roll_out(&x, args.seed).map_err(CliError::input)?;
    crate::output::say(&answer.to_string())?;
    match &args.series {
        Some(file) => Ok(primo_learn::series::write_csv(
            file,
            objective.space,
            trial.series.as_ref(),
        )?),
        None => Ok(()),
    }
}

fn print_start(o: &Objective) -> Result<(), CliError> {
    let blocks = power_blocks(&o.skill, 0.2, 0.05, QUERY_DECAY)?;
    // Blocks are [q̂, weights, goals, τ]; the vector puts q̂ last.
    let mut std: Vec<f32> = blocks
        .iter()
        .flat_map(|b| std::iter::repeat_n(b.variance.sqrt(), b.len))
        .collect();
    std.rotate_left(1);
    let mut start = o.base.clone();
    start.push(o.bottle as f32);
    let out = serde_json::json!({
        "layout": "weights (dof x kernels, row by row), goals (dof), tau (s), query (l)",
        "space": o.space,
        "dof": o.skill.dof(),
        "kernels": o.skill.kernels(),
        "bottle": o.bottle,
        "start": start,
        "std": std,
    });
    crate::output::say(&out.to_string())
}

fn serve(o: &Objective, seed: u64, len: usize) -> Result<(), CliError> {
    let stdin = std::io::stdin();
    let mut stdout = std::io::stdout();
    for (i, line) in stdin.lock().lines().enumerate() {
        let line = line.map_err(|e| CliError::other(format!("stdin: {e}")))?;
        if line.trim().is_empty() {
            continue;
        }
        let what = format!("stdin line {}", i + 1);
        let answer = parse_params(&what, &line, len)
            .and_then(|x| {
                o.roll_out(&x, seed.wrapping_add(i as u64))
                    .map(|(answer, _)| answer)
            })
            .unwrap_or_else(|e| serde_json::json!({ "error": e }));
        writeln!(stdout, "{answer}")
            .and_then(|()| stdout.flush())
            .map_err(CliError::stdout)?;
    }
    Ok(())
}
