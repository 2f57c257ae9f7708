//! `primo experiment`: the paper's experiments on the simulated cell.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use primo_learn::algorithm::{Algorithm, ERROR_LEARNERS};
use primo_learn::experiment::claim::{check, claim};
use primo_learn::experiment::{
    Done, THRESHOLDS, Variant, check_power, check_volumes, golden_settings, golden_skill,
    power_skill,
};
use primo_learn::experiment::{
    PowerSetup, PowerStats, median_rollouts, power_budget, write_golden, write_power_experiment,
};
use primo_learn::stats::Estimate;

use crate::args::Glass;
use crate::error::CliError;
use crate::output::say;
use crate::progress::Progress;

/// `primo experiment …`.
#[derive(Debug, clap::Subcommand)]
pub enum ExperimentCommand {
    /// Fig. 3: error learning per volume, by each of the five error
    /// learners (golden section, Illinois, secant, fixed gain, weighted gain).
    Golden {
        /// Bottle volumes, l.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "0.3,0.4,0.5,0.6,0.7,0.8,0.9,1.0"
        )]
        volumes: Vec<f64>,
        /// Stop at |error| below this, l.
        #[arg(long, default_value_t = 0.002)]
        precision: f64,
        /// Seed of the scale's noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output directory.
        #[arg(long, default_value = "experiment-golden")]
        out: PathBuf,
        /// Replace an earlier result in --out.
        #[arg(long)]
        force: bool,
    },
    /// Figs. 5–6: extended against ordinary PoWER in joint space, and PoWER
    /// with the query learned from the error.
    Power {
        /// Seeded runs per variant.
        #[arg(long, default_value_t = 20)]
        runs: usize,
        /// Kernels per joint (30 gives the paper's 219 parameters).
        #[arg(long, default_value_t = 30)]
        kernels: usize,
        /// Updates per run (4 roll-outs each).
        #[arg(long, default_value_t = 100)]
        updates: u32,
        /// The glass (the paper's second experiment: small).
        #[arg(long, value_enum, default_value_t = Glass::Small)]
        glass: Glass,
        /// Seed of the first run.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output directory.
        #[arg(long, default_value = "experiment-power")]
        out: PathBuf,
        /// Replace an earlier result in --out.
        #[arg(long)]
        force: bool,
    },
}

/// Runs a `primo experiment` command.
pub fn run(command: ExperimentCommand) -> Result<(), CliError> {
    match command {
        ExperimentCommand::Golden {
            volumes,
            precision,
            seed,
            out,
            force,
        } => golden(&volumes, precision, seed, &out, force),
        ExperimentCommand::Power {
            runs,
            kernels,
            updates,
            glass,
            seed,
            out,
            force,
        } => power(runs, kernels, updates, glass, seed, &out, force),
    }
}

/// Runs `experiment` with its runs' progress on stderr, cleared at the end.
fn with_runs<T>(name: &str, experiment: impl FnOnce(&(dyn Fn(Done) + Sync)) -> T) -> T {
    let command = format!("primo experiment {name}");
    let progress = Mutex::new(Progress::new());
    let result = experiment(&|done: Done| {
        if let Ok(mut p) = progress.lock() {
            p.total = u32::try_from(done.of).unwrap_or(u32::MAX);
            p.runs(&command, u32::try_from(done.runs).unwrap_or(u32::MAX));
        }
    });
    if let Ok(p) = progress.lock() {
        p.clear();
    }
    result
}

fn golden(
    volumes: &[f64],
    precision: f64,
    seed: u64,
    out: &Path,
    force: bool,
) -> Result<(), CliError> {
    let started = std::time::Instant::now();
    check(out, &primo_learn::experiment::golden::FILES, force)?;
    // The learners take it as f32: it must stay positive and finite there.
    let single = precision as f32;
    if !(single.is_finite() && single > 0.0) {
        return Err(CliError::input(format!(
            "--precision {precision}: must be a positive volume in litres"
        )));
    }
    check_volumes(volumes)?;
    let (cell, skill) = golden_skill()?;
    for v in volumes {
        golden_settings(&cell, *v, Algorithm::Golden, precision, seed)
            .map_err(|e| CliError::input(format!("--volumes {v}: {e}")))?;
    }
    let _held = claim(out, &primo_learn::experiment::golden::FILES, force)?;
    let runs = with_runs("golden", |progress| {
        primo_learn::experiment::golden(&skill, &cell, volumes, precision, seed, progress)
    })?;
    write_golden(out, &runs, precision)?;
    let names = [
        "golden",
        "illinois",
        "secant",
        "fixed-gain",
        "weighted-gain",
    ];
    say(&format!(
        "volume {}   (roll-outs to |error| < {} ml)",
        names.map(|n| format!("{n:>14}")).join(""),
        precision * 1e3
    ))?;
    for row in runs.chunks(ERROR_LEARNERS.len()) {
        let cells: Vec<String> = row
            .iter()
            .map(|r| {
                let n = r
                    .rollouts_to_precision
                    .map_or("-".to_string(), |n| n.to_string());
                format!("{n:>14}")
            })
            .collect();
        let volume = row.first().map_or(f64::NAN, |r| r.volume);
        say(&format!("{volume:>5.2} l{}", cells.join("")))?;
    }
    let medians: Vec<String> = ERROR_LEARNERS
        .iter()
        .zip(names)
        .map(|(m, n)| {
            let worst = runs
                .iter()
                .filter(|r| r.method == *m)
                .map(|r| r.worst_overpour)
                .fold(0.0, f64::max);
            format!(
                "{n} {} (worst over-pour {:.0} ml)",
                median_rollouts(&runs, *m).unwrap_or(f64::NAN),
                worst * 1e3
            )
        })
        .collect();
    say(&format!(
        "median: {}; {:.1} s; wrote {}",
        medians.join(", "),
        started.elapsed().as_secs_f64(),
        out.display()
    ))
}

fn power(
    runs: usize,
    kernels: usize,
    updates: u32,
    glass: Glass,
    seed: u64,
    out: &Path,
    force: bool,
) -> Result<(), CliError> {
    let started = std::time::Instant::now();
    check_power(runs, updates)?;
    check(out, &primo_learn::experiment::power::FILES, force)?;
    let (cell, skill) = power_skill(glass.into(), kernels)?;
    let _held = claim(out, &primo_learn::experiment::power::FILES, force)?;
    let curves = with_runs("power", |progress| {
        primo_learn::experiment::power(&skill, &cell, runs, updates, seed, progress)
    })?;
    let parameters = skill.param_len() + 1;
    let seconds = started.elapsed().as_secs_f64();
    let setup = PowerSetup {
        updates,
        kernels,
        parameters,
        glass: glass.into(),
    };
    let comparison = write_power_experiment(out, setup, &curves, seconds)?;
    for (variant, c) in Variant::ALL.iter().zip(&curves) {
        say(&format!(
            "{:>13}: start |error| {:.1} ml spilled {:.1} ml -> final |error| {:.2} ± {:.2} ml, spilled {:.2} ± {:.2} ml, reward {:.3}; {:.0} % of roll-outs reward 0, {} rejected",
            variant.name(),
            c.error.mean.first().copied().unwrap_or(f64::NAN) * 1e3,
            c.spilled.mean.first().copied().unwrap_or(f64::NAN) * 1e3,
            c.error.last() * 1e3,
            c.error.std.last().copied().unwrap_or(f64::NAN) * 1e3,
            c.spilled.last() * 1e3,
            c.spilled.std.last().copied().unwrap_or(f64::NAN) * 1e3,
            c.reward.last(),
            100.0 * c.zero_reward as f64 / c.rollouts.max(1) as f64,
            c.rejected,
        ))?;
    }
    let e = |x: &Estimate, scale: f64, digits: usize| {
        format!(
            "{:.*} [{:.*}, {:.*}]",
            digits,
            x.value * scale,
            digits,
            x.low * scale,
            digits,
            x.high * scale
        )
    };
    // A run that never reached a level counts as the budget plus one.
    let never = f64::from(power_budget(updates).map_err(CliError::from)? + 1);
    for (k, level) in THRESHOLDS.iter().enumerate() {
        let c = &comparison;
        let to = |s: &PowerStats| reached_in(&s.rollouts_to[k], s.reached[k], runs, never);
        say(&format!(
            "to mean reward {level}: roll-outs, median [90 % CI]: extended {}, ordinary {}, \
             error-learned {}; saved against ordinary: by extended {}, by error-learned {}",
            to(&c.extended),
            to(&c.ordinary),
            to(&c.error_learned),
            e(&c.rollouts_saved[k], 1.0, 0),
            e(&c.rollouts_saved_by_error_learning[k], 1.0, 0),
        ))?;
    }
    say(&format!(
        "regret Σ(1 − r): extended {}, ordinary {}, error-learned {}; ordinary/extended final \
         error x{}, spill x{}; {} parameters, {runs} runs x {updates} updates each; {:.1} s; \
         wrote {}",
        e(&comparison.extended.regret, 1.0, 1),
        e(&comparison.ordinary.regret, 1.0, 1),
        e(&comparison.error_learned.regret, 1.0, 1),
        e(&comparison.error_ratio, 1.0, 2),
        e(&comparison.spill_ratio, 1.0, 2),
        parameters,
        seconds,
        out.display()
    ))
}

/// Roll-outs to a level over `runs` runs of which `reached` reached it:
/// the median and its interval, but never the count that stands for
/// "not reached" (`never`) as if it were one.
fn reached_in(x: &Estimate, reached: usize, runs: usize, never: f64) -> String {
    if 2 * reached <= runs {
        return format!("not reached by the median run ({reached}/{runs} reached)");
    }
    let high = match x.high >= never {
        true => "not reached".to_string(),
        false => format!("{:.0}", x.high),
    };
    format!(
        "{:.0} [{:.0}, {high}] ({reached}/{runs} reached)",
        x.value, x.low
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_the_median_run_never_reached_is_said_so() {
        let x = |value, low, high| Estimate { value, low, high };
        assert_eq!(
            reached_in(&x(62.0, 21.0, 62.0), 1, 3, 62.0),
            "not reached by the median run (1/3 reached)"
        );
        assert_eq!(
            reached_in(&x(25.0, 21.0, 62.0), 2, 3, 62.0),
            "25 [21, not reached] (2/3 reached)"
        );
        assert_eq!(
            reached_in(&x(25.0, 21.0, 33.0), 3, 3, 62.0),
            "25 [21, 33] (3/3 reached)"
        );
    }
}
