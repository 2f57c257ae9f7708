//! The paper's experiments, one seeded run at a time, and the files
//! `primo experiment` writes: `golden_run` and `power_run` call the same
//! library functions as the command line's parallel loops
//! (`primo_learn::experiment::{golden_run, power_run}`) with the GIL
//! released, and return plain data (dicts of numbers and NumPy columns)
//! that pickles, so runs can be spread over processes or Ray and
//! gathered; `write_golden` and `write_power` rebuild the runs from
//! those roll-outs and write them with the command line's writers.

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use primo_learn::algorithm::{Algorithm, ERROR_LEARNERS};
use primo_learn::experiment::claim::{check, claim};
use primo_learn::experiment::{
    PowerCurves, PowerRun, SearchRun, THRESHOLDS, Variant, golden_run as golden_seeded,
    golden_skill, power_run as power_seeded, power_skill,
};
use primo_learn::experiment::{PowerSetup, write_golden as golden_files, write_power_experiment};
use primo_learn::pour::trial::Trial;
use primo_learn::rollouts::Record;
use primo_sim::cell::CellConfig;
use primo_skill::Skill;

use crate::cell::{glass_kind, seed_of};
use crate::errors::{invalid, learn};

/// A cell and its fitted skill, shared by the runs that use it.
type Built = Arc<(CellConfig, Skill)>;

/// The skills built so far in this process, by name: a sweep's runs fit
/// each once (a handful of names: the golden one, power per glass and
/// kernel count).
static SKILLS: Mutex<Vec<(String, Built)>> = Mutex::new(Vec::new());

/// The skill named `key`, built by `build` the first time.
fn cached(
    key: String,
    build: impl FnOnce() -> Result<(CellConfig, Skill), primo_learn::Error>,
) -> Result<Built, primo_learn::Error> {
    let find = |key: &str| {
        SKILLS
            .lock()
            .ok()
            .and_then(|s| s.iter().find(|(k, _)| k == key).map(|(_, b)| b.clone()))
    };
    if let Some(built) = find(&key) {
        return Ok(built);
    }
    let built = Arc::new(build()?);
    if let Ok(mut skills) = SKILLS.lock() {
        skills.push((key, built.clone()));
    }
    Ok(built)
}

/// A name as the library's serde names it (`fixed-gain`, `extended`).
fn parse<T: serde::de::DeserializeOwned>(what: &str, name: &str, expected: &str) -> PyResult<T> {
    serde_json::from_value(serde_json::Value::String(name.to_string()))
        .map_err(|_| invalid(format!("{what}: `{name}`, expected {expected}")))
}

/// The library's name of `value`.
fn name_of(value: &impl serde::Serialize) -> String {
    match serde_json::to_value(value) {
        Ok(serde_json::Value::String(s)) => s,
        _ => String::new(),
    }
}

const VARIANTS: &str = "\"extended\", \"ordinary\" or \"error-learned\"";
const METHODS: &str = "\"golden\", \"illinois\", \"secant\", \"fixed-gain\" or \"weighted-gain\"";

/// The roll-outs' columns of numbers.
const FLOATS: [&str; 5] = ["query", "poured", "spilled", "error", "reward"];

/// A run's roll-outs as columns: `rollout`, `update`, `mean`, `query`,
/// `poured`, `spilled`, `error`, `reward` (NumPy arrays) and `rejected`
/// (a list: why the gate refused the movement, or None).
fn columns<'py>(py: Python<'py>, records: &[Record<Trial>]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let ints = |f: fn(&Record<Trial>) -> u32| -> Vec<i64> {
        records.iter().map(|r| i64::from(f(r))).collect()
    };
    d.set_item(
        "rollout",
        numpy::PyArray1::from_vec(py, ints(|r| r.rollout)),
    )?;
    d.set_item("update", numpy::PyArray1::from_vec(py, ints(|r| r.update)))?;
    let mean: Vec<bool> = records.iter().map(|r| r.mean).collect();
    d.set_item("mean", numpy::PyArray1::from_vec(py, mean))?;
    let values: [fn(&Record<Trial>) -> f64; 5] = [
        |r| f64::from(r.volume()),
        |r| r.trial.poured,
        |r| r.trial.spilled,
        |r| r.trial.error,
        |r| r.trial.reward,
    ];
    for (key, value) in FLOATS.iter().zip(values) {
        let column: Vec<f64> = records.iter().map(value).collect();
        d.set_item(*key, numpy::PyArray1::from_vec(py, column))?;
    }
    let rejected: Vec<Option<&str>> = records
        .iter()
        .map(|r| r.trial.rejected.as_deref())
        .collect();
    d.set_item("rejected", PyList::new(py, rejected)?)?;
    Ok(d)
}

/// `key` of the mapping `run` (`what` names the run in messages).
fn field<'py, T>(what: &str, run: &Bound<'py, PyAny>, key: &str) -> PyResult<T>
where
    T: for<'a> FromPyObject<'a, 'py>,
{
    let value = run
        .get_item(key)
        .map_err(|_| invalid(format!("{what}: no `{key}`")))?;
    value
        .extract::<T>()
        .map_err(|_| invalid(format!("{what}: `{key}` is not what a run holds")))
}

/// Column `key` of a run's roll-outs, of `n` values.
fn column<'py, T>(what: &str, columns: &Bound<'py, PyAny>, key: &str, n: usize) -> PyResult<Vec<T>>
where
    T: for<'a> FromPyObject<'a, 'py>,
{
    let values: Vec<T> = field(what, columns, key)?;
    if values.len() != n {
        return Err(invalid(format!(
            "{what}[\"{key}\"]: {} values for {n} roll-outs",
            values.len()
        )));
    }
    Ok(values)
}

/// The roll-outs of a run's `rollouts` columns (see [`columns`]).
fn records_of(what: &str, run: &Bound<'_, PyAny>) -> PyResult<Vec<Record<Trial>>> {
    let what = format!("{what}[\"rollouts\"]");
    let c: Bound<'_, PyAny> = field(&what, run, "rollouts")?;
    let rollout: Vec<u32> = field(&what, &c, "rollout")?;
    let n = rollout.len();
    let update: Vec<u32> = column(&what, &c, "update", n)?;
    let mean: Vec<bool> = column(&what, &c, "mean", n)?;
    let rejected: Vec<Option<String>> = column(&what, &c, "rejected", n)?;
    let [query, poured, spilled, error, reward] =
        FLOATS.map(|key| column::<f64>(&what, &c, key, n));
    let (query, poured, spilled, error, reward) = (query?, poured?, spilled?, error?, reward?);
    Ok((0..n)
        .map(|i| Record {
            rollout: rollout[i],
            update: update[i],
            mean: mean[i],
            query: vec![query[i] as f32],
            trial: Trial {
                poured: poured[i],
                spilled: spilled[i],
                error: error[i],
                reward: reward[i],
                rejected: rejected[i].clone(),
                series: None,
                readings: None,
            },
        })
        .collect())
}

/// One seeded run of the golden experiment (Fig. 3), as
/// ``primo experiment golden --volumes VOLUME --seed SEED --precision
/// PRECISION`` runs it: the error learner ``method`` (``"golden"``,
/// ``"illinois"``, ``"secant"``, ``"fixed-gain"``, ``"weighted-gain"``)
/// learns to pour 0.2 l from a bottle holding ``volume`` l into the normal
/// glass (Cartesian space, 30 kernels) until |error| < ``precision`` l,
/// the scale's noise from ``seed``. Runs on one core with the GIL
/// released.
///
/// Returns a dict: ``volume``, ``method``, ``seed``, ``precision``,
/// ``rollouts_to_precision`` (int or None), ``worst_overpour`` (l) and
/// ``rollouts``, the roll-outs as columns (``rollout``, ``update``,
/// ``mean``, ``query``, ``poured``, ``spilled``, ``error``, ``reward``:
/// NumPy arrays; ``rejected``: a list of None or why the gate refused).
///
/// >>> from primo.experiments import golden_run
/// >>> run = golden_run(0.5, method="secant", seed=1)
/// >>> run["rollouts_to_precision"], len(run["rollouts"]["error"])
/// (3, 3)
/// >>> bool(abs(run["rollouts"]["error"][-1]) < 0.002)
/// True
#[pyfunction]
#[pyo3(signature = (volume, method="golden", seed=None, precision=0.002))]
pub fn golden_run<'py>(
    py: Python<'py>,
    volume: f64,
    method: &str,
    seed: Option<Bound<'py, PyAny>>,
    precision: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let algorithm: Algorithm = parse("method", method, METHODS)?;
    if !ERROR_LEARNERS.contains(&algorithm) {
        return Err(invalid(format!("method: `{method}`, expected {METHODS}")));
    }
    let seed = seed.map_or(Ok(1), |s| seed_of("seed", &s))?;
    let run = py
        .detach(|| {
            let built = cached("golden".into(), golden_skill)?;
            let (cell, skill) = &*built;
            golden_seeded(skill, cell, volume, algorithm, precision, seed)
        })
        .map_err(|e| match e {
            e @ (primo_learn::Error::Invalid(_) | primo_learn::Error::Setting { .. }) => {
                invalid(format!("volume {volume}: {e}"))
            }
            e => learn(e),
        })?;
    let d = PyDict::new(py);
    d.set_item("volume", run.volume)?;
    d.set_item("method", name_of(&run.method))?;
    d.set_item("seed", seed)?;
    d.set_item("precision", precision)?;
    d.set_item("rollouts_to_precision", run.rollouts_to_precision)?;
    d.set_item("worst_overpour", run.worst_overpour)?;
    d.set_item("rollouts", columns(py, &run.records)?)?;
    Ok(d)
}

/// One seeded run of the power experiment (Figs. 5 and 6), as
/// ``primo experiment power --seed SEED --runs 1 --kernels KERNELS
/// --updates UPDATES --glass GLASS`` runs it for ``variant``
/// (``"extended"``: PoWER over ``[q̂, Δθ]``, s1 = 0.2; ``"ordinary"``:
/// s1 = 0; ``"error-learned"``: the query learned from the error,
/// ``primo pour --method power-el``): from the generalized start for a 0.5 l bottle, pouring
/// 0.2 l, ``updates`` updates of 4 roll-outs each, then one roll-out of
/// the final mean, in joint space. Runs on one core with the GIL
/// released.
///
/// Returns a dict: ``variant``, ``seed``, ``kernels``, ``updates``,
/// ``glass``, ``parameters`` (learned: ``[q̂, Δθ]``), the figures of
/// ``power_runs.csv`` (``rollouts_to`` and ``updates_to``: ``{0.95: n,
/// 0.99: n}``, None where the mean policy never got there; ``regret``;
/// ``final_error``, ``final_spilled``, ``final_reward``: the final
/// mean's |error| and spill in l, its reward) and ``rollouts``, every
/// roll-out as columns (as ``golden_run``'s; the mean policy's are
/// those with ``mean``: its learning curve).
///
/// >>> from primo.experiments import power_run
/// >>> run = power_run(seed=1, variant="ordinary", kernels=10, updates=2)
/// >>> run["parameters"], len(run["rollouts"]["reward"])
/// (79, 9)
/// >>> run["rollouts"]["rollout"][run["rollouts"]["mean"]].tolist()
/// [1, 5, 9]
#[pyfunction]
#[pyo3(signature = (seed=None, variant="extended", kernels=30, updates=100, glass="small"))]
pub fn power_run<'py>(
    py: Python<'py>,
    seed: Option<Bound<'py, PyAny>>,
    variant: &str,
    kernels: usize,
    updates: u32,
    glass: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let kind: Variant = parse("variant", variant, VARIANTS)?;
    let glass_kind = glass_kind(glass)?;
    let seed = seed.map_or(Ok(1), |s| seed_of("seed", &s))?;
    let (records, parameters) = py
        .detach(|| {
            let built = cached(format!("power/{glass}/{kernels}"), || {
                power_skill(glass_kind, kernels)
            })?;
            let (cell, skill) = &*built;
            let records = power_seeded(skill, cell, kind, updates, seed)?;
            Ok::<_, primo_learn::Error>((records, skill.param_len() + 1))
        })
        .map_err(learn)?;
    let figures = PowerRun::of(seed, &records);
    let d = PyDict::new(py);
    d.set_item("variant", kind.name())?;
    d.set_item("seed", seed)?;
    d.set_item("kernels", kernels)?;
    d.set_item("updates", updates)?;
    d.set_item("glass", glass)?;
    d.set_item("parameters", parameters)?;
    let by_level = |values: [Option<u32>; 2]| -> PyResult<Bound<'py, PyDict>> {
        let levels = PyDict::new(py);
        for (level, v) in THRESHOLDS.iter().zip(values) {
            levels.set_item(level, v)?;
        }
        Ok(levels)
    };
    d.set_item("rollouts_to", by_level(figures.rollouts_to)?)?;
    d.set_item("updates_to", by_level(figures.updates_to)?)?;
    d.set_item("regret", figures.regret)?;
    d.set_item("final_error", figures.error)?;
    d.set_item("final_spilled", figures.spilled)?;
    d.set_item("final_reward", figures.reward)?;
    d.set_item("rollouts", columns(py, &records)?)?;
    Ok(d)
}

/// The files an experiment `kind` writes.
fn files(kind: &str) -> PyResult<&'static [&'static str]> {
    match kind {
        "golden" => Ok(&primo_learn::experiment::golden::FILES),
        "power" => Ok(&primo_learn::experiment::power::FILES),
        _ => Err(invalid(format!(
            "kind: `{kind}`, expected \"golden\" or \"power\""
        ))),
    }
}

/// Checks, creating nothing, that the experiment ``kind`` (``"golden"``
/// or ``"power"``) may write its files into ``out``: a directory or none
/// yet, in use by no other primo, and holding no earlier result unless
/// ``force`` (then it is replaced). A sweep asks before its runs begin,
/// so that hours of runs are not lost to a directory that is taken.
///
/// >>> import tempfile, pathlib
/// >>> from primo.experiments import check_out
/// >>> out = pathlib.Path(tempfile.mkdtemp())
/// >>> (out / "summary.json").write_text("an earlier result")
/// 17
/// >>> try:
/// ...     check_out(out, "golden")
/// ... except ValueError as e:
/// ...     print(str(e).removeprefix(str(out / "summary.json")))
/// : an earlier result is here: choose another directory, or give force=True to replace it
/// >>> check_out(out, "golden", force=True)
#[pyfunction]
#[pyo3(signature = (out, kind, force=false))]
pub fn check_out(out: PathBuf, kind: &str, force: bool) -> PyResult<()> {
    check(&out, files(kind)?, force).map_err(claimed)
}

/// A refused output directory, in the Python arguments' terms.
fn claimed(e: primo_learn::Error) -> PyErr {
    match e {
        e @ primo_learn::Error::HoldsResult { .. } => invalid(format!(
            "{e}: choose another directory, or give force=True to replace it"
        )),
        e => learn(e),
    }
}

/// The one value of `key` all `runs` share (`what` names the key in the
/// message when they differ).
fn shared<'py, T>(runs: &[Bound<'py, PyAny>], key: &str) -> PyResult<T>
where
    T: for<'a> FromPyObject<'a, 'py> + PartialEq + std::fmt::Debug,
{
    let mut value: Option<T> = None;
    for (i, run) in runs.iter().enumerate() {
        let v: T = field(&format!("runs[{i}]"), run, key)?;
        match &value {
            Some(first) if *first != v => {
                return Err(invalid(format!(
                    "runs: `{key}` differs ({first:?} and {v:?}); these files hold runs of one \
                     setting (write each setting's runs into its own directory)"
                )));
            }
            Some(_) => {}
            None => value = Some(v),
        }
    }
    value.ok_or_else(|| invalid("runs: no runs to write"))
}

/// Writes what ``primo experiment golden`` writes (``golden.csv``,
/// ``summary.json``, ``golden.png``) into the directory ``out`` (made if
/// missing; one holding an earlier result is refused unless ``force``,
/// and one another primo is writing into always, as by ``check_out``)
/// for ``runs``, dicts of ``golden_run`` (all of one
/// ``precision`` and seed), in order: those of ``primo experiment golden
/// --volumes V1,V2,… --seed S`` are each volume's five learners in the
/// order golden, illinois, secant, fixed-gain, weighted-gain, and the
/// files are then the command's, byte for byte. The figures are computed
/// again from the roll-outs.
///
/// >>> import tempfile, pathlib
/// >>> from primo.experiments import golden_run, write_golden
/// >>> out = pathlib.Path(tempfile.mkdtemp())
/// >>> write_golden(out, [golden_run(0.5, m) for m in ["golden", "secant"]])
/// >>> (out / "golden.csv").read_text().splitlines()[1]
/// '0.5,golden,1,0.5,0.228517,0.028517'
#[pyfunction]
#[pyo3(signature = (out, runs, force=false))]
pub fn write_golden(
    py: Python<'_>,
    out: PathBuf,
    runs: Vec<Bound<'_, PyAny>>,
    force: bool,
) -> PyResult<()> {
    let precision: f64 = shared(&runs, "precision")?;
    let _seed: u64 = shared(&runs, "seed")?;
    let searches = runs
        .iter()
        .enumerate()
        .map(|(i, run)| {
            let what = format!("runs[{i}]");
            let method: String = field(&what, run, "method")?;
            let method: Algorithm = parse(&format!("{what}[\"method\"]"), &method, METHODS)?;
            let volume: f64 = field(&what, run, "volume")?;
            Ok(SearchRun::of(
                volume,
                method,
                precision,
                records_of(&what, run)?,
            ))
        })
        .collect::<PyResult<Vec<_>>>()?;
    let _held = claim(&out, &primo_learn::experiment::golden::FILES, force).map_err(claimed)?;
    py.detach(|| golden_files(&out, &searches, precision))
        .map_err(learn)
}

/// Writes what ``primo experiment power`` writes (``power_runs.csv``,
/// ``power.csv``, ``summary.json``, ``power.png``) into the directory
/// ``out`` (made if missing; refused as by ``write_golden``) for ``runs``,
/// dicts of ``power_run`` of one
/// setting (kernels, updates, glass): each variant's runs in the order
/// given, the variants on the same seeds in the same order (they are
/// compared seed by seed). ``seconds`` is the wall-clock time the summary
/// reports. For the runs of ``primo experiment power --seed S --runs N``
/// (seeds S, S + 1, …) the files are the command's, byte for byte, but
/// for that time. The figures are computed again from the roll-outs.
/// ``force`` replaces an earlier result in ``out``.
///
/// >>> import tempfile, pathlib
/// >>> from primo.experiments import power_run, write_power
/// >>> out = pathlib.Path(tempfile.mkdtemp())
/// >>> runs = [power_run(s, v, kernels=10, updates=2) for v in ["extended", "ordinary"] for s in [1, 2]]
/// >>> write_power(out, runs)
/// >>> (out / "power_runs.csv").read_text().splitlines()[0]
/// 'variant,seed,rollouts_to_0.95,updates_to_0.95,rollouts_to_0.99,updates_to_0.99,regret,final_error_l,final_spilled_l,final_reward'
#[pyfunction]
#[pyo3(signature = (out, runs, seconds=0.0, force=false))]
pub fn write_power(
    py: Python<'_>,
    out: PathBuf,
    runs: Vec<Bound<'_, PyAny>>,
    seconds: f64,
    force: bool,
) -> PyResult<()> {
    let setup = PowerSetup {
        updates: shared(&runs, "updates")?,
        kernels: shared(&runs, "kernels")?,
        parameters: shared(&runs, "parameters")?,
        glass: glass_kind(&shared::<String>(&runs, "glass")?)?,
    };
    let mut by_variant: [Vec<(u64, Vec<Record<Trial>>)>; 3] = Default::default();
    for (i, run) in runs.iter().enumerate() {
        let what = format!("runs[{i}]");
        let variant: String = field(&what, run, "variant")?;
        let variant: Variant = parse(&format!("{what}[\"variant\"]"), &variant, VARIANTS)?;
        let seed = seed_of(&format!("{what}[\"seed\"]"), &field(&what, run, "seed")?)?;
        let k = Variant::ALL.iter().position(|v| *v == variant).unwrap_or(0);
        by_variant[k].push((seed, records_of(&what, run)?));
    }
    let seeds = |k: usize| by_variant[k].iter().map(|(s, _)| *s).collect::<Vec<u64>>();
    let given: Vec<usize> = (0..by_variant.len())
        .filter(|k| !by_variant[*k].is_empty())
        .collect();
    if let [first, rest @ ..] = &given[..]
        && let Some(other) = rest.iter().find(|k| seeds(**k) != seeds(*first))
    {
        return Err(invalid(format!(
            "runs: {}'s seeds {:?} and {}'s {:?} differ; the variants are compared seed by seed",
            Variant::ALL[*first].name(),
            seeds(*first),
            Variant::ALL[*other].name(),
            seeds(*other)
        )));
    }
    if !(seconds.is_finite() && seconds >= 0.0) {
        return Err(invalid(format!("seconds: {seconds} is not a duration")));
    }
    let _held = claim(&out, &primo_learn::experiment::power::FILES, force).map_err(claimed)?;
    py.detach(|| {
        let curves = by_variant.map(|runs| PowerCurves::of(&runs));
        write_power_experiment(&out, setup, &curves, seconds).map(|_| ())
    })
    .map_err(learn)
}
