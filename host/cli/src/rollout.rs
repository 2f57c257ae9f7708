//! `primo rollout`: parameter vectors executed on the simulated cell, an
//! objective for any optimizer.

use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};

use primo_learn::pour::objective::{Objective, Start, layout};
use primo_learn::pour::settings::check_target;
use primo_learn::pour::trial::Trial;

use crate::args::Glass;
use crate::error::CliError;
use crate::output::{check_out_file, read};
use crate::pour::SkillArgs;

/// `primo rollout` options.
#[derive(Debug, clap::Args)]
pub struct RolloutArgs {
    /// JSON array `[weights (dof×kernels, row by row), goals (dof), τ,
    /// q̂]` (in Cartesian space the DoFs are x, y, z and the orientation's
    /// three log coordinates, its goal a rotation vector from the
    /// demonstrated goals' mean): θ is absolute; the movement executed is
    /// θ + G(q̂) − G(bottle). `--print-start`'s output is accepted too (its
    /// `start`).
    #[arg(long, conflicts_with_all = ["serve", "print_start"])]
    params: Option<PathBuf>,
    /// Answer every line on stdin with one JSON line: a roll-out for a
    /// JSON array (line n with seed `--seed` + n − 1), `{"invalid": why}`
    /// for anything else (a blank line, not UTF-8, not an array of the
    /// layout's length); the server goes on until stdin ends.
    #[arg(long, conflicts_with = "print_start")]
    serve: bool,
    /// Print the cell (glass, bottle, target, space), the layout, the
    /// generalized start vector and PoWER's exploration std.
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

/// Parses a roll-out vector: a JSON array of numbers (or `--print-start`'s
/// object, its `start`), checked against the objective's layout.
fn parse_params(o: &Objective, what: &str, text: &str) -> Result<Vec<f32>, String> {
    let parsed = serde_json::from_str::<serde_json::Value>(text).and_then(|v| {
        let start = v.get("start").cloned();
        serde_json::from_value::<Vec<f64>>(start.unwrap_or(v))
    });
    let values = match parsed {
        Ok(v) => v,
        Err(_) if text.trim().is_empty() => {
            return Err(format!("{what}: blank: expected a JSON array of numbers"));
        }
        Err(e) => {
            let start: String = text.trim().chars().take(40).collect();
            return Err(format!(
                "{what}: `{start}` is not a JSON array of numbers (nor --print-start's \
                 output): {e}"
            ));
        }
    };
    o.vector(&values).map_err(|e| format!("{what}: {e}"))
}

/// One roll-out as a JSON answer, and the trial.
fn roll_out(
    o: &Objective,
    x: &[f32],
    seed: u64,
    record: bool,
) -> Result<(serde_json::Value, Trial), String> {
    let trial = o.roll_out(x, seed, record).map_err(|e| e.to_string())?;
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

/// Runs `primo rollout`.
pub fn run(args: &RolloutArgs) -> Result<(), CliError> {
    check_target(args.bottle, args.target)?;
    let spec = args
        .skill
        .spec(primo_learn::pour::skill::Space::Joint, Glass::Small)?;
    if let Some(series) = &args.series {
        let mut inputs: Vec<(&str, &Path)> = spec
            .demos
            .iter()
            .map(|d| ("--demo", d.file.as_path()))
            .collect();
        inputs.extend(args.params.as_deref().map(|p| ("--params", p)));
        check_out_file("--series", series, &inputs)?;
    }
    let objective = Objective::new(&spec, args.bottle, args.target)?;
    for c in objective.converted() {
        eprintln!("primo rollout: {c}");
    }
    if args.print_start {
        return print_start(&objective, spec.glass);
    }
    if args.serve {
        return serve(&objective, args.seed);
    }
    let path = args
        .params
        .as_deref()
        .ok_or_else(|| CliError::input("give --params FILE, --serve or --print-start"))?;
    let x = parse_params(
        &objective,
        &path.display().to_string(),
        &read(Some("--params"), path)?,
    )
    .map_err(CliError::input)?;
    let (answer, trial) =
        roll_out(&objective, &x, args.seed, args.series.is_some()).map_err(CliError::input)?;
    crate::output::say(&answer.to_string())?;
    match &args.series {
        Some(file) => Ok(primo_learn::pour::series::write_csv(
            file,
            objective.space(),
            trial.series.as_ref(),
        )?),
        None => Ok(()),
    }
}

fn print_start(o: &Objective, glass: primo_sim::cell::GlassKind) -> Result<(), CliError> {
    let Start { start, std } = o.start()?;
    let out = serde_json::json!({
        "glass": glass,
        "target": o.target(),
        "layout": layout(o.space()),
        "space": o.space(),
        "dof": o.skill().dof(),
        "kernels": o.skill().kernels(),
        "bottle": o.bottle(),
        "start": start,
        "std": std,
    });
    crate::output::say(&out.to_string())
}

fn serve(o: &Objective, seed: u64) -> Result<(), CliError> {
    let mut stdin = std::io::stdin().lock();
    let mut stdout = std::io::stdout();
    let mut line = Vec::new();
    for i in 0u64.. {
        line.clear();
        let read = stdin
            .read_until(b'\n', &mut line)
            .map_err(|e| CliError::other(format!("stdin: {e}")))?;
        if read == 0 {
            return Ok(());
        }
        let what = format!("stdin line {}", i + 1);
        let answer = std::str::from_utf8(&line)
            .map_err(|e| format!("{what}: not UTF-8 text ({e})"))
            .and_then(|text| parse_params(o, &what, text))
            .and_then(|x| roll_out(o, &x, seed.wrapping_add(i), false).map(|(a, _)| a))
            .unwrap_or_else(|why| serde_json::json!({ "invalid": why }));
        writeln!(stdout, "{answer}")
            .and_then(|()| stdout.flush())
            .map_err(CliError::stdout)?;
    }
    Ok(())
}
