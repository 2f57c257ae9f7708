//! The golden experiment (the paper's Fig. 3): every error learner
//! learning to pour 0.2 l from several bottle volumes, in Cartesian space,
//! and what it writes.

use std::path::Path;

use primo_sim::cell::{CellConfig, GlassKind};
use primo_skill::Skill;
use primo_skill::csv::Csv;
use serde::Serialize;

use crate::Error;
use crate::algorithm::{Algorithm, ERROR_LEARNERS};
use crate::error::Setting;
use crate::learner::Learner;
use crate::output::{write_file, write_json};
use crate::plot::panels::write_png;
use crate::plot::{Line, Panel};
use crate::pour::report::ERROR_FLOOR_ML;
use crate::pour::settings::Settings;
use crate::pour::simulate::learn;
use crate::pour::skill::{Space, built_in_skill};
use crate::pour::trial::Trial;
use crate::rollouts::Record;
use crate::stats::median;

use super::parallel::{Done, parallel_reporting};

/// One learning run of the golden experiment.
#[derive(Debug, Clone, Serialize)]
pub struct SearchRun {
    /// Liquid in the bottle, l.
    pub volume: f64,
    /// The learner.
    pub method: Algorithm,
    /// First roll-out with |error| below the precision, if any.
    pub rollouts_to_precision: Option<u32>,
    /// The most poured beyond the target in any roll-out, l (0 if never):
    /// what a search spills over the glass's mark on a real cell.
    pub worst_overpour: f64,
    /// Per roll-out: query and error (l).
    #[serde(skip)]
    pub records: Vec<Record<Trial>>,
}

impl SearchRun {
    /// The figures of a run's roll-outs, to `precision` (l).
    pub fn of(
        volume: f64,
        method: Algorithm,
        precision: f64,
        records: Vec<Record<Trial>>,
    ) -> SearchRun {
        SearchRun {
            volume,
            method,
            rollouts_to_precision: records
                .iter()
                .find(|r| r.trial.error.abs() < precision)
                .map(|r| r.rollout),
            worst_overpour: records.iter().map(|r| r.trial.error).fold(0.0, f64::max),
            records,
        }
    }
}

/// The golden experiment's cell and skill: the normal glass, Cartesian
/// space, 30 kernels per DoF, fitted to the built-in demonstrations.
pub fn golden_skill() -> Result<(CellConfig, Skill), Error> {
    let cell = CellConfig::standard(GlassKind::Normal);
    let skill = built_in_skill(&cell, Space::Cartesian, 30)?;
    Ok((cell, skill))
}

/// The settings of one golden-experiment run, checked: the paper's for
/// the error learner `method` pouring 0.2 l from `volume` l in `cell`,
/// to `precision` (l), the scale's noise from `seed`. The message of a
/// refused volume does not name it (callers do).
pub fn golden_settings(
    cell: &CellConfig,
    volume: f64,
    method: Algorithm,
    precision: f64,
    seed: u64,
) -> Result<Settings, Error> {
    if !ERROR_LEARNERS.contains(&method) {
        return Err(Error::Invalid(format!("{method}: not an error learner")));
    }
    let mut s = Settings::paper(method, volume, 0.2, seed);
    s.precision = precision;
    s.validate()?;
    let capacity = cell.bottle_litres();
    if volume > capacity {
        return Err(Error::Invalid(format!(
            "the cell's bottle holds {capacity:.3} l"
        )));
    }
    Ok(s)
}

/// One seeded run of the golden experiment (Fig. 3): `method` learns to
/// pour 0.2 l from `volume` l ([`golden_settings`]) on the skill of
/// [`golden_skill`]. [`golden`] runs it for every volume and learner.
pub fn golden_run(
    skill: &Skill,
    cell: &CellConfig,
    volume: f64,
    method: Algorithm,
    precision: f64,
    seed: u64,
) -> Result<SearchRun, Error> {
    let s = golden_settings(cell, volume, method, precision, seed)?;
    let records = learn(skill, cell, &s, &mut Learner::local(), |_| {})?;
    Ok(SearchRun::of(volume, method, precision, records))
}

/// The most bottle volumes of one golden experiment (the paper's: 8),
/// each learned by every error learner.
pub const MAX_VOLUMES: usize = 1_000;

/// Checks the number of a golden experiment's volumes.
pub fn check_volumes(volumes: &[f64]) -> Result<(), Error> {
    if !(1..=MAX_VOLUMES).contains(&volumes.len()) {
        return Err(Error::setting(
            Setting::Volumes,
            format!("({} values)", volumes.len()),
            format!("at least 1 and at most {MAX_VOLUMES} volumes"),
        ));
    }
    Ok(())
}

/// Fig. 3: every error learner ([`ERROR_LEARNERS`]: golden section,
/// Illinois, secant, and the paper's fixed-gain rules) for every volume,
/// volume by volume; `progress` hears of every run finished.
pub fn golden(
    skill: &Skill,
    cell: &CellConfig,
    volumes: &[f64],
    precision: f64,
    seed: u64,
    progress: impl Fn(Done) + Sync,
) -> Result<Vec<SearchRun>, Error> {
    check_volumes(volumes)?;
    let jobs: Vec<(f64, Algorithm)> = volumes
        .iter()
        .flat_map(|v| ERROR_LEARNERS.map(|m| (*v, m)))
        .collect();
    let of = jobs.len();
    parallel_reporting(
        of,
        |i| {
            let (volume, method) = jobs[i];
            golden_run(skill, cell, volume, method, precision, seed)
        },
        |runs| progress(Done { runs, of }),
    )
    .into_iter()
    .collect()
}

/// `summary.json` of `primo experiment golden`.
#[derive(Debug, Serialize)]
struct GoldenSummary<'a> {
    precision: f64,
    runs: &'a [SearchRun],
    median_rollouts: [(Algorithm, Option<f64>); ERROR_LEARNERS.len()],
}

/// The median roll-outs to precision of `method` (runs that never reach it
/// count as their budget: a lower bound).
pub fn median_rollouts(runs: &[SearchRun], method: Algorithm) -> Option<f64> {
    let counts: Vec<f64> = runs
        .iter()
        .filter(|r| r.method == method)
        .map(|r| f64::from(r.rollouts_to_precision.unwrap_or(r.records.len() as u32)))
        .collect();
    (!counts.is_empty()).then(|| median(&counts))
}

/// The files [`write_golden`] writes.
pub const FILES: [&str; 3] = ["golden.csv", "golden.png", "summary.json"];

/// Writes `golden.csv`, `golden.png` and `summary.json` into `dir`.
pub fn write_golden(dir: &Path, runs: &[SearchRun], precision: f64) -> Result<(), Error> {
    let mut csv = Csv::new();
    for column in [
        "volume_l", "method", "rollout", "query_l", "poured_l", "error_l",
    ] {
        csv.text(column);
    }
    csv.end_row();
    for run in runs {
        for r in &run.records {
            csv.display(run.volume)
                .display(run.method)
                .display(r.rollout)
                .display(r.volume())
                .display(format_args!("{:.6}", r.trial.poured))
                .display(format_args!("{:.6}", r.trial.error));
            csv.end_row();
        }
    }
    write_file(&dir.join("golden.csv"), csv.as_bytes())?;
    let summary = GoldenSummary {
        precision,
        runs,
        median_rollouts: ERROR_LEARNERS.map(|m| (m, median_rollouts(runs, m))),
    };
    write_json(&dir.join("summary.json"), &summary)?;
    // Per learner: its runs' errors, one line a volume.
    let learners: Vec<(String, Vec<Labelled>)> = ERROR_LEARNERS
        .iter()
        .map(|m| {
            let mine: Vec<&SearchRun> = runs.iter().filter(|r| r.method == *m).collect();
            let curves = mine
                .iter()
                .map(|run| {
                    let error =
                        |r: &Record<Trial>| (f64::from(r.rollout), r.trial.error.abs() * 1e3);
                    (
                        format!("{} l", run.volume),
                        run.records.iter().map(error).collect(),
                    )
                })
                .collect();
            (format!("{} (n = {} volumes)", m, mine.len()), curves)
        })
        .collect();
    let series: Vec<Vec<Line>> = learners
        .iter()
        .map(|(_, curves)| {
            curves
                .iter()
                .map(|(label, p)| Line::new(label, p))
                .collect()
        })
        .collect();
    let mut panels: Vec<Panel> = learners
        .iter()
        .zip(&series)
        .map(|((title, _), s)| Panel {
            title,
            x_label: "roll-out",
            y_label: "|error| [ml]",
            series: s,
            log_y: true,
            floor: Some(ERROR_FLOOR_ML),
            hline: Some((precision * 1e3, "precision")),
        })
        .collect();
    // The learners side by side: roll-outs to the precision per volume.
    let keys = ERROR_LEARNERS.map(Algorithm::key);
    let reached: Vec<Vec<(f64, f64)>> = ERROR_LEARNERS
        .iter()
        .map(|m| {
            runs.iter()
                .filter(|r| r.method == *m)
                .map(|r| {
                    let n = r.rollouts_to_precision.map_or(f64::NAN, f64::from);
                    (r.volume, n)
                })
                .collect()
        })
        .collect();
    let compared: Vec<Line> = keys
        .iter()
        .zip(&reached)
        .map(|(k, p)| Line::new(k, p))
        .collect();
    let title = format!("Roll-outs to |error| < {} ml", precision * 1e3);
    panels.push(Panel {
        title: &title,
        x_label: "liquid in the bottle [l]",
        y_label: "roll-outs (not reached: no point)",
        series: &compared,
        ..Panel::default()
    });
    write_png(&dir.join("golden.png"), &panels, 1100)
}

/// A labelled curve.
type Labelled = (String, Vec<(f64, f64)>);
