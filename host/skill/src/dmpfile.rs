//! The JSON file of a fitted DMP (`primo dmp fit --out dmp.json`), and the
//! fit and run behind `primo dmp`.
//!
//! ```json
//! { "format": "primo-dmp", "version": 6, "names": ["x", "qw", "qx", "qy", "qz"],
//!   "orientations": [{ "columns": ["qw", "qx", "qy", "qz"], "goal": [1, 0, 0, 0] }],
//!   "dmp": { "tau": 1.0, "alpha": 25.0, "width": 1682.0, "margin": 1.0,
//!            "start": [0, 0.5, 0, 0], "goal": [1, 0, 0, 0], "scaled": [true, false, false, false],
//!            "weights": [[...], [...], [...], [...]] } }
//! ```
//!
//! `names` are the demonstration's columns. Four adjacent columns named
//! `<p>qw, <p>qx, <p>qy, <p>qz` (any common prefix `p`, e.g. `qw…` or
//! `tool_qw…`) are one orientation, a unit quaternion: it is fitted as an
//! orientation DMP ([`primo_core::orientation`]), three DoFs of `dmp` that
//! hold `log(q ⊗ ḡ)` with `g` the group's `goal`; every other column is one
//! DoF. A run writes the same columns back, the quaternions unit-norm. An
//! orientation that turns further than 270° (a screw, a wrist's spin) has
//! an `axis` besides (the unit axis of its turn): its three DoFs are then
//! its swing and twist about that axis ([`primo_core::orientation::from_coordinates`]),
//! which unwind any number of turns.
//!
//! A rhythmic DMP (`primo dmp fit --rhythmic`) is the same format with a
//! `rhythmic` object (the fields of [`RhythmicDmp`]) in place of `dmp` and
//! `orientations`: one period, replayed at any frequency and amplitude.
//!
//! `format` and `version` are checked on load; a newer version is refused
//! rather than misread. Version 1 files (no orientations), version 2
//! files (no `margin`: none), version 3 files (no `reference`: scaled
//! per DoF) and version 4 files (no `axis`: the rotation vector, as they
//! were fitted) still load, with their old meaning. The fields of `dmp` are those of
//! [`primo_core::dmp::Dmp`] (the book's DMP file reference, docs/src/reference/dmp-file.md).

use primo_core::dmp::{FitOptions, Margin, Scaling, Trajectory};
use primo_core::orientation::{
    chart_coordinates, checked_axis, from_coordinates, nearest_coordinates, unwrapped_in,
};
use primo_core::quaternion::Quaternion;
use primo_core::rhythmic::{RhythmicDmp, RhythmicRun};
use serde::{Deserialize, Serialize};

use crate::csv::Demo;
use crate::{Error, HOST_MAX_DOF, HostDmp, MAX_KERNELS};

/// The most samples a caller should ask a run for (10,000 s at 1 kHz):
/// `primo dmp run` and the Python package refuse more.
pub const MAX_ROWS: usize = 10_000_000;

/// How a discrete DMP scales its forcing term to a new start and goal
/// (`primo dmp fit --scaling`, a task file's `scaling`, Python's
/// `scaling=`). The book's DMP chapter compares them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AmplitudeScaling {
    /// Each column by its own `(g − y0)/(g_d − y0_d)`, a column that
    /// starts and ends (almost) together unscaled ([`Scaling::Auto`]).
    #[default]
    PerDof,
    /// None: the shape as demonstrated ([`Scaling::Never`]).
    None,
    /// The position columns together (Koutras & Doulgeri 2020,
    /// [`Scaling::Global`]); orientations unscaled.
    Global,
}

impl AmplitudeScaling {
    /// The names, as given.
    pub const NAMES: [&str; 3] = ["per-dof", "none", "global"];

    /// The choice named `name` (one of [`AmplitudeScaling::NAMES`]).
    pub fn parse(name: &str) -> Option<AmplitudeScaling> {
        match name {
            "per-dof" => Some(AmplitudeScaling::PerDof),
            "none" => Some(AmplitudeScaling::None),
            "global" => Some(AmplitudeScaling::Global),
            _ => None,
        }
    }

    /// The core's scaling for a demonstration whose position DoFs are
    /// `positions` (bit `d`: DMP DoF `d`), or those of `scaled` (a skill's
    /// examples scale per DoF as the first does).
    fn of(self, positions: u32, scaled: Option<u32>) -> Scaling {
        match self {
            AmplitudeScaling::PerDof => scaled.map_or(Scaling::AutoWhere(positions), Scaling::Mask),
            AmplitudeScaling::None => Scaling::Never,
            AmplitudeScaling::Global => Scaling::Global(positions),
        }
    }
}

/// The `format` field's value.
pub const FORMAT: &str = "primo-dmp";
/// The version this primo writes; it reads versions 1 to this one.
/// 2: orientations; 3: the kernels' `margin`; 4: global scaling's
/// `reference` (absent: per DoF, as every earlier version scales); 5: an
/// orientation's chart `axis` (absent: the rotation vector); 6: the DMP's
/// `goal_velocity` (absent: it ends at rest).
pub const VERSION: u32 = 6;

/// An orientation among the columns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Orientation {
    /// Its four column names, `w, x, y, z`.
    pub columns: [String; 4],
    /// Its goal, `[w, x, y, z]`.
    pub goal: [f32; 4],
    /// The axis of its chart ([`primo_core::orientation::chart_axis`]):
    /// absent (`[0, 0, 0]`) where its three DoFs are the rotation vector
    /// `log(q ⊗ ḡ)`, a unit vector where they are swing and twist about
    /// it (a turn beyond 270°).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub axis: [f32; 3],
}

fn is_zero(axis: &[f32; 3]) -> bool {
    *axis == [0.0; 3]
}

/// A DMP with the names of its columns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DmpFile {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`VERSION`] when written by this primo.
    pub version: u32,
    /// Column names, as in the demonstration's header.
    pub names: Vec<String>,
    /// The orientations among the columns (none in version 1).
    #[serde(default)]
    pub orientations: Vec<Orientation>,
    /// The DMP itself.
    pub dmp: HostDmp,
}

#[derive(Deserialize)]
struct Header {
    format: String,
    version: u32,
    #[serde(default)]
    rhythmic: Option<serde::de::IgnoredAny>,
}

/// The host's rhythmic DMP: up to 16 DoF, 128 kernels.
pub type HostRhythmic = RhythmicDmp<HOST_MAX_DOF, MAX_KERNELS>;

/// A rhythmic DMP with the names of its columns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RhythmicFile {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`VERSION`] when written by this primo.
    pub version: u32,
    /// Column names, as in the demonstration's header.
    pub names: Vec<String>,
    /// The DMP itself.
    pub rhythmic: HostRhythmic,
}

/// A DMP file of either kind.
#[derive(Debug, Clone, PartialEq)]
pub enum Fitted {
    /// A discrete movement (with orientations, if any).
    Discrete(DmpFile),
    /// A periodic one.
    Rhythmic(RhythmicFile),
}

/// Checks `format` and `version` and reads either kind; `file` names the
/// file in error messages.
pub fn parse(file: &str, text: &str) -> Result<Fitted, Error> {
    let header = header(file, text)?;
    if header.rhythmic.is_none() {
        return DmpFile::parse(file, text).map(Fitted::Discrete);
    }
    let parsed: RhythmicFile = serde_json::from_str(text).map_err(|e| at(file, e))?;
    if parsed.names.len() != parsed.rhythmic.dof() {
        return Err(Error::File(format!(
            "{file}: {} names for a rhythmic DMP with {} DoF",
            parsed.names.len(),
            parsed.rhythmic.dof()
        )));
    }
    Ok(Fitted::Rhythmic(parsed))
}

fn at(file: &str, e: serde_json::Error) -> Error {
    Error::File(format!("{file}:{}:{}: {e}", e.line(), e.column()))
}

/// The header, checked.
fn header(file: &str, text: &str) -> Result<Header, Error> {
    // Anything but a JSON object (a CSV, say) is no DMP file at all:
    // say so rather than where the JSON parser stopped.
    if !text.trim_start().starts_with('{') {
        let first = text.lines().next().unwrap_or("");
        let first: String = first.chars().take(40).collect();
        return Err(Error::File(format!(
            "{file}: not a primo DMP file (the JSON object `{{\"format\": \"{FORMAT}\", ...}}` \
             that `primo dmp fit` writes); it begins `{}`",
            first.escape_debug()
        )));
    }
    let header: Header = serde_json::from_str(text).map_err(|e| at(file, e))?;
    if header.format != FORMAT {
        return Err(Error::File(format!(
            "{file}: format is `{}`, expected `{FORMAT}`",
            header.format
        )));
    }
    if !(1..=VERSION).contains(&header.version) {
        return Err(Error::File(format!(
            "{file}: unsupported version {} (this primo reads versions 1 to {VERSION})",
            header.version
        )));
    }
    Ok(header)
}

impl RhythmicFile {
    /// Fits one period (`period` seconds from the first sample, or the
    /// whole recording) with `kernels` kernels per DoF; orientation
    /// columns are refused (a rhythmic orientation DMP is not built).
    pub fn fit(
        file: &str,
        demo: &Demo,
        kernels: usize,
        period: Option<f32>,
    ) -> Result<Self, Error> {
        if !(3..=MAX_KERNELS).contains(&kernels) {
            return Err(Error::File(format!(
                "a rhythmic DMP needs 3 to {MAX_KERNELS} kernels per DoF, not {kernels}"
            )));
        }
        if let Some(Slot { column: c, .. }) = layout(&demo.names)
            .into_iter()
            .find(|s| s.kind == Column::Quaternion)
        {
            return Err(Error::File(format!(
                "{file}:1: columns {}…: orientations are not fitted as rhythmic DMPs",
                demo.names[c]
            )));
        }
        if demo.names.len() > HOST_MAX_DOF {
            return Err(Error::File(format!(
                "{file}:1: {} DoF, at most {HOST_MAX_DOF}",
                demo.names.len()
            )));
        }
        let rhythmic = HostRhythmic::fit(
            &demo.times,
            &demo.positions,
            demo.names.len(),
            kernels,
            period,
            &FitOptions::default(),
        )
        .map_err(|e| Error::File(format!("{file}: cannot fit a rhythmic DMP: {e}")))?;
        Ok(RhythmicFile {
            format: FORMAT.into(),
            version: VERSION,
            names: demo.names.clone(),
            rhythmic,
        })
    }

    /// Serializes to pretty JSON.
    pub fn to_json(&self) -> Result<String, serde_json::Error> {
        serde_json::to_string_pretty(self)
    }

    /// Runs `duration` seconds at step `dt`: times and rows. Each change
    /// takes effect from its time on (in time order; those at 0 from the
    /// start): the run glides onto a new amplitude or anchor and keeps its
    /// phase through a new frequency. Every change is checked first.
    pub fn run(
        &self,
        dt: f32,
        duration: f32,
        changes: &[Change],
    ) -> Result<impl Iterator<Item = (f32, Vec<f32>)> + '_, Error> {
        let movement = |e: primo_core::Error| Error::Movement(e.to_string());
        let mut run = self.rhythmic.start().map_err(movement)?;
        let mut changes = changes.to_vec();
        changes.sort_by(|a, b| a.at.total_cmp(&b.at));
        let mut scratch = run.clone();
        for c in &changes {
            c.apply(&mut scratch)?;
        }
        let steps = (duration / dt).round().max(0.0) as usize;
        let mut pending = changes.into_iter().peekable();
        let mut due = move |run: &mut RhythmicRun<HOST_MAX_DOF>, t: f32| {
            while let Some(c) = pending.next_if(|c| c.at <= t) {
                // Checked above on the scratch run: cannot fail.
                let _ = c.apply(run);
            }
        };
        due(&mut run, 0.0);
        // The caller checked `dt` > 0, so a step cannot fail; the rows
        // would stop if one ever did.
        let first = std::iter::once((0.0, run.position().to_vec()));
        let rest = (1..=steps).map_while(move |i| {
            due(&mut run, (i - 1) as f32 * dt);
            run.step(&self.rhythmic, dt).ok()?;
            Some((i as f32 * dt, run.position().to_vec()))
        });
        Ok(first.chain(rest))
    }
}

/// A change to a rhythmic run at a time: any of frequency, amplitude and
/// anchor ([`RhythmicFile::run`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Change {
    /// From this time on, s (≥ 0).
    pub at: f32,
    /// The frequency, Hz.
    pub frequency: Option<f32>,
    /// Amplitudes relative to the demonstrated, one per column.
    pub amplitude: Option<Vec<f32>>,
    /// The oscillation's centre, one value per column.
    pub anchor: Option<Vec<f32>>,
}

impl Change {
    fn apply(&self, run: &mut RhythmicRun<HOST_MAX_DOF>) -> Result<(), Error> {
        let at = |what: String| match self.at {
            0.0 => Error::Movement(what),
            t => Error::Movement(format!("at {t} s: {what}")),
        };
        if !(self.at.is_finite() && self.at >= 0.0) {
            return Err(Error::Movement(format!(
                "a change at {} s: its time must be a number of seconds >= 0",
                self.at
            )));
        }
        if let Some(hz) = self.frequency {
            run.set_frequency(hz)
                .map_err(|_| at(format!("frequency {hz}: must be in 0.001..=1000 Hz")))?;
        }
        if let Some(a) = &self.amplitude {
            run.set_amplitude(a)
                .map_err(|e| at(format!("amplitude: {e}")))?;
        }
        if let Some(g) = &self.anchor {
            run.set_anchor(g).map_err(|e| at(format!("anchor: {e}")))?;
        }
        Ok(())
    }
}

/// What a column of the demonstration is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Column {
    /// One DoF.
    Scalar,
    /// The `w` of an orientation (the next three are its `x, y, z`).
    Quaternion,
}

/// A column, or an orientation's four, and where it sits in the DMP.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Slot {
    /// Its (first) column.
    column: usize,
    /// What it is.
    kind: Column,
    /// Its (first) DoF in the DMP.
    dof: usize,
    /// An orientation's index among the orientations.
    orientation: usize,
}

/// The layout of `names`: one slot per column, one per orientation (its
/// `x, y, z` are part of its `w`'s slot).
fn layout(names: &[String]) -> Vec<Slot> {
    let mut out = Vec::new();
    let (mut i, mut dof, mut orientation) = (0, 0, 0);
    while i < names.len() {
        let group = names[i].strip_suffix("qw").filter(|prefix| {
            ["qx", "qy", "qz"]
                .iter()
                .enumerate()
                .all(|(k, axis)| names.get(i + 1 + k) == Some(&format!("{prefix}{axis}")))
        });
        let kind = if group.is_some() {
            Column::Quaternion
        } else {
            Column::Scalar
        };
        out.push(Slot {
            column: i,
            kind,
            dof,
            orientation,
        });
        match kind {
            Column::Quaternion => (i, dof, orientation) = (i + 4, dof + 3, orientation + 1),
            Column::Scalar => (i, dof) = (i + 1, dof + 1),
        }
    }
    out
}

/// The orientation groups among columns `names` (the module docs' rule):
/// each group's four column names and its first DoF in the DMP.
pub fn orientation_groups(names: &[String]) -> Vec<([String; 4], usize)> {
    layout(names)
        .into_iter()
        .filter(|s| s.kind == Column::Quaternion)
        .map(|s| (std::array::from_fn(|k| names[s.column + k].clone()), s.dof))
        .collect()
}

/// The DMP DoF of the scalar column `name` among columns `names`, if it is
/// one (an orientation's columns are none).
pub fn scalar_dof(names: &[String], name: &str) -> Option<usize> {
    layout(names)
        .into_iter()
        .find(|s| s.kind == Column::Scalar && names.get(s.column).is_some_and(|n| n == name))
        .map(|s| s.dof)
}

/// DMP DoFs of a layout.
fn dmp_dof(layout: &[Slot]) -> usize {
    layout.last().map_or(0, |s| {
        s.dof + if s.kind == Column::Quaternion { 3 } else { 1 }
    })
}

impl DmpFile {
    /// Fits a DMP of `kernels` kernels per DoF to a demonstration (`file`
    /// names it in errors), its outer kernels placed by `margin`, its
    /// forcing term scaled by `scaling`; orientations as the module docs
    /// say.
    pub fn fit(
        file: &str,
        demo: &Demo,
        kernels: usize,
        margin: Margin,
        scaling: AmplitudeScaling,
    ) -> Result<Self, Error> {
        let options = FitOptions {
            margin,
            ..FitOptions::default()
        };
        DmpFile::fit_with(file, demo, kernels, (scaling, None), &options)
    }

    /// [`DmpFile::fit`] with the fit's other `options`, and, scaling per
    /// DoF, the amplitude-scaled DoFs given (bit `d`: DMP DoF `d`), as a
    /// skill fits every demonstration like its first (`None` decides per
    /// column, an orientation's never scaled).
    pub fn fit_with(
        file: &str,
        demo: &Demo,
        kernels: usize,
        (scaling, scaled): (AmplitudeScaling, Option<u32>),
        options: &FitOptions,
    ) -> Result<Self, Error> {
        DmpFile::fit_charted(file, demo, kernels, (scaling, scaled), None, options)
    }

    /// [`DmpFile::fit_with`] with the orientations' chart axes given (one
    /// per orientation, as [`Orientation::axis`]), as a skill charts every
    /// demonstration like its first (`None` decides per orientation:
    /// [`primo_core::orientation::chart_axis`]).
    pub fn fit_charted(
        file: &str,
        demo: &Demo,
        kernels: usize,
        (scaling, scaled): (AmplitudeScaling, Option<u32>),
        axes: Option<&[[f32; 3]]>,
        options: &FitOptions,
    ) -> Result<Self, Error> {
        if !(2..=MAX_KERNELS).contains(&kernels) {
            return Err(Error::File(format!(
                "a DMP needs 2 to {MAX_KERNELS} kernels per DoF, not {kernels}"
            )));
        }
        crate::csv::check_rotation_vectors(file, demo)?;
        let columns = demo.names.len();
        let layout = layout(&demo.names);
        let dof = dmp_dof(&layout);
        if dof > HOST_MAX_DOF {
            return Err(Error::File(format!(
                "{file}:1: {dof} DoF (an orientation counts 3), at most {HOST_MAX_DOF}"
            )));
        }
        let rows = demo.times.len();
        let mut positions = vec![0.0f32; rows * dof];
        let mut orientations = Vec::new();
        let mut scaled_mask = 0u32;
        for &Slot {
            column: c,
            kind,
            dof: d,
            ..
        } in &layout
        {
            let column = |k: usize| demo.positions.iter().skip(c + k).step_by(columns).copied();
            match kind {
                Column::Scalar => {
                    for (r, v) in column(0).enumerate() {
                        positions[r * dof + d] = v;
                    }
                    scaled_mask |= 1 << d;
                }
                Column::Quaternion => {
                    let quaternions: Vec<f32> = (0..rows)
                        .flat_map(|r| (0..4).map(move |k| (r, k)))
                        .map(|(r, k)| demo.positions[r * columns + c + k])
                        .collect();
                    let mut log = vec![0.0f32; rows * 3];
                    let given =
                        axes.map(|a| a.get(orientations.len()).copied().unwrap_or([0.0; 3]));
                    let charted = match given {
                        None => chart_coordinates(&quaternions, &mut log),
                        Some(axis) => checked_axis(axis).and_then(|axis| {
                            let mut rows = log.chunks_exact_mut(3);
                            let goal = unwrapped_in(&quaternions, &axis, &mut |e| {
                                if let Some(r) = rows.next() {
                                    r.copy_from_slice(e);
                                }
                            })?;
                            if let Some(last) = log.rchunks_exact_mut(3).next() {
                                last.fill(0.0);
                            }
                            Ok((goal, axis))
                        }),
                    };
                    let (goal, axis) = charted.map_err(|e| {
                        Error::File(format!(
                            "{file}: columns {}…{}: not an orientation: {e}",
                            demo.names[c],
                            demo.names[c + 3]
                        ))
                    })?;
                    for (r, e) in log.chunks_exact(3).enumerate() {
                        positions[r * dof + d..r * dof + d + 3].copy_from_slice(e);
                    }
                    orientations.push(Orientation {
                        columns: std::array::from_fn(|k| demo.names[c + k].clone()),
                        goal: goal.to_array(),
                        axis,
                    });
                }
            }
        }
        let options = FitOptions {
            scaling: scaling.of(scaled_mask, scaled),
            ..*options
        };
        let dmp = HostDmp::fit(&demo.times, &positions, dof, kernels, &options).map_err(|e| {
            Error::File(format!(
                "{file}: cannot fit {kernels} kernels to {rows} rows: {e}"
            ))
        })?;
        Ok(DmpFile {
            format: FORMAT.into(),
            version: VERSION,
            names: demo.names.clone(),
            orientations,
            dmp,
        })
    }

    /// Parses a discrete DMP file's text; `file` names it in error
    /// messages (see [`parse`] for either kind).
    pub fn parse(file: &str, text: &str) -> Result<Self, Error> {
        header(file, text)?;
        let parsed: Self = serde_json::from_str(text).map_err(|e| at(file, e))?;
        let layout = layout(&parsed.names);
        let groups: Vec<&[String]> = layout
            .iter()
            .filter(|s| s.kind == Column::Quaternion)
            .map(|s| &parsed.names[s.column..s.column + 4])
            .collect();
        let declared: Vec<&[String]> = parsed.orientations.iter().map(|o| &o.columns[..]).collect();
        if groups != declared {
            return Err(Error::File(format!(
                "{file}: `orientations` must list exactly the `…qw,…qx,…qy,…qz` column groups of \
                 `names`, in order"
            )));
        }
        if dmp_dof(&layout) != parsed.dmp.dof() {
            return Err(Error::File(format!(
                "{file}: {} names ({} DoF, an orientation counts 3) for a DMP with {} DoF",
                parsed.names.len(),
                dmp_dof(&layout),
                parsed.dmp.dof()
            )));
        }
        let mut parsed = parsed;
        for o in &mut parsed.orientations {
            Quaternion::from_array(o.goal)
                .normalized()
                .map_err(|e| Error::File(format!("{file}: goal of {}: {e}", o.columns[0])))?;
            o.axis = checked_axis(o.axis).map_err(|_| {
                Error::File(format!(
                    "{file}: axis of {}: {:?} is neither absent nor a direction",
                    o.columns[0], o.axis
                ))
            })?;
        }
        Ok(parsed)
    }

    /// Serializes to pretty JSON.
    pub fn to_json(&self) -> Result<String, serde_json::Error> {
        serde_json::to_string_pretty(self)
    }

    /// Runs the DMP from `t = 0` to `t = τ` at step `dt` and returns the
    /// times and the rows, one value per column. `start` and `goal` (one
    /// value per column; an orientation's four are normalized) replace
    /// the demonstrated ones; `tau` the demonstrated duration.
    pub fn run(
        &self,
        dt: f32,
        tau: Option<f32>,
        start: Option<&[f32]>,
        goal: Option<&[f32]>,
    ) -> Result<impl Iterator<Item = (f32, Vec<f32>)> + '_, Error> {
        let (prepared, steps) = self.steps(dt, tau, start, goal)?;
        Ok(steps.map(move |s| (s.time, prepared.columns(&s.position))))
    }

    /// [`DmpFile::run`] of an execution already prepared ([`DmpFile::prepare`],
    /// and perhaps shaped: [`crate::shaping`]).
    pub fn run_prepared<'a>(
        &'a self,
        prepared: &'a Prepared,
        dt: f32,
    ) -> Result<impl Iterator<Item = (f32, Vec<f32>)> + 'a, Error> {
        let steps = self
            .dmp
            .trajectory(&prepared.execution, dt)
            .map_err(|e| Error::Movement(e.to_string()))?;
        Ok(steps.map(move |s| (s.time, prepared.columns(&s.position))))
    }

    /// [`DmpFile::run`]'s samples in the DMP's coordinates, and what turns
    /// them into the columns: for a caller that writes the columns where
    /// it wants them ([`Prepared::each_column`]) rather than a row per
    /// sample.
    pub fn steps(
        &self,
        dt: f32,
        tau: Option<f32>,
        start: Option<&[f32]>,
        goal: Option<&[f32]>,
    ) -> Result<(Prepared, Trajectory<'_, HOST_MAX_DOF, MAX_KERNELS>), Error> {
        let prepared = self.prepare(tau, start, goal)?;
        let steps = self
            .dmp
            .trajectory(&prepared.execution, dt)
            .map_err(|e| Error::Movement(e.to_string()))?;
        Ok((prepared, steps))
    }

    /// The execution for `tau`, `start` and `goal` (as in
    /// [`DmpFile::run`]), with what turns the DMP's coordinates back into
    /// the columns: for a caller that steps the DMP itself.
    pub fn prepare(
        &self,
        tau: Option<f32>,
        start: Option<&[f32]>,
        goal: Option<&[f32]>,
    ) -> Result<Prepared, Error> {
        let mut exec = self.dmp.execution();
        if let Some(tau) = tau {
            exec.tau = tau;
        }
        let mut goals: Vec<Quaternion> = self
            .orientations
            .iter()
            .map(|o| Quaternion::from_array(o.goal))
            .collect();
        let layout = layout(&self.names);
        if let Some(goal) = goal {
            self.check_len("goal", goal)?;
            for s in &layout {
                match s.kind {
                    Column::Scalar => exec.goal[s.dof] = goal[s.column],
                    Column::Quaternion => {
                        let values = &goal[s.column..s.column + 4];
                        goals[s.orientation] = quaternion(values, "goal", &self.names[s.column])?;
                    }
                }
            }
        }
        if let Some(start) = start {
            self.check_len("start", start)?;
        }
        // An orientation's start is its coordinates relative to its goal:
        // re-expressed on the goal it runs to, so a new goal never moves it.
        let demonstrated = self.dmp.start_position().to_vec();
        for s in &layout {
            match (s.kind, start) {
                (Column::Scalar, Some(start)) => exec.start[s.dof] = start[s.column],
                (Column::Scalar, None) => {}
                (Column::Quaternion, _) => {
                    let reference = &demonstrated[s.dof..s.dof + 3];
                    let q = match start {
                        Some(start) => {
                            let values = &start[s.column..s.column + 4];
                            quaternion(values, "start", &self.names[s.column])?
                        }
                        None => {
                            let o = &self.orientations[s.orientation];
                            from_coordinates(reference, &Quaternion::from_array(o.goal), &o.axis)
                        }
                    };
                    let axis = &self.orientations[s.orientation].axis;
                    let e = nearest_coordinates(&q, &goals[s.orientation], reference, axis);
                    exec.start[s.dof..s.dof + 3].copy_from_slice(&e);
                }
            }
        }
        Ok(Prepared {
            execution: exec,
            goals,
            axes: self.orientations.iter().map(|o| o.axis).collect(),
            layout,
            width: self.names.len(),
        })
    }

    /// The DMP's DoF that holds the scalar column `name`, if there is one
    /// (not an orientation's).
    pub fn scalar_dof(&self, name: &str) -> Option<usize> {
        scalar_dof(&self.names, name)
    }

    fn check_len(&self, flag: &str, values: &[f32]) -> Result<(), Error> {
        if values.len() != self.names.len() {
            return Err(Error::Movement(format!(
                "--{flag}: {} values, expected one per column ({})",
                values.len(),
                self.names.join(",")
            )));
        }
        Ok(())
    }
}

/// An execution of a [`DmpFile`]'s DMP, and the way back from its
/// coordinates to the file's columns.
#[derive(Debug, Clone, PartialEq)]
pub struct Prepared {
    /// Start, goal and `τ` in the DMP's coordinates.
    pub execution: primo_core::dmp::Execution<HOST_MAX_DOF>,
    goals: Vec<Quaternion>,
    axes: Vec<[f32; 3]>,
    layout: Vec<Slot>,
    width: usize,
}

impl Prepared {
    /// DMP coordinates → one value per column, orientations relative to
    /// their goals.
    pub fn columns(&self, dmp: &[f32]) -> Vec<f32> {
        let mut out = Vec::with_capacity(self.width);
        self.each_column(dmp, |v| out.push(v));
        out
    }

    /// [`Prepared::columns`], each value handed to `emit` in column order.
    pub fn each_column(&self, dmp: &[f32], mut emit: impl FnMut(f32)) {
        for s in &self.layout {
            match s.kind {
                Column::Scalar => emit(dmp.get(s.dof).copied().unwrap_or(0.0)),
                Column::Quaternion => {
                    let goal = self
                        .goals
                        .get(s.orientation)
                        .copied()
                        .unwrap_or(Quaternion::IDENTITY);
                    let e = dmp.get(s.dof..s.dof + 3).unwrap_or(&[0.0; 3]);
                    let axis = self.axes.get(s.orientation).copied().unwrap_or([0.0; 3]);
                    from_coordinates(e, &goal, &axis)
                        .to_array()
                        .into_iter()
                        .for_each(&mut emit);
                }
            }
        }
    }

    /// Whether every column is one DoF (no orientation): the DMP's
    /// velocities are the columns' then.
    pub fn is_plain(&self) -> bool {
        self.layout.iter().all(|s| s.kind == Column::Scalar)
    }
}

/// Four values as a unit quaternion (`flag` and `column` name it in errors).
fn quaternion(values: &[f32], flag: &str, column: &str) -> Result<Quaternion, Error> {
    let q = Quaternion::from_array([values[0], values[1], values[2], values[3]]);
    q.normalized()
        .map_err(|_| Error::Movement(format!("--{flag}: {column}…: not an orientation (zero)")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(s: &str) -> Vec<String> {
        s.split(',').map(String::from).collect()
    }

    #[test]
    fn a_csv_is_named_no_dmp_file() {
        let e = parse("reach.csv", "t,x,z\n0,0,0.1\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("reach.csv: not a primo DMP file"), "{e}");
        assert!(e.contains("it begins `t,x,z`"), "{e}");
    }

    #[test]
    fn orientation_columns_are_recognized_by_name() {
        let l = layout(&names("x,qw,qx,qy,qz,tool_qw,tool_qx,tool_qy,tool_qz,qw"));
        let kinds: Vec<Column> = l.iter().map(|s| s.kind).collect();
        assert_eq!(
            kinds,
            [
                Column::Scalar,
                Column::Quaternion,
                Column::Quaternion,
                Column::Scalar
            ]
        );
        assert_eq!(dmp_dof(&l), 1 + 3 + 3 + 1);
        let at: Vec<(usize, usize, usize)> =
            l.iter().map(|s| (s.column, s.dof, s.orientation)).collect();
        assert_eq!(at, [(0, 0, 0), (1, 1, 0), (5, 4, 1), (9, 7, 2)]);
        // Out of order or with another prefix: plain columns.
        let l = layout(&names("qw,qy,qx,qz,a_qw,b_qx,b_qy,b_qz"));
        assert!(l.iter().all(|s| s.kind == Column::Scalar));
    }
}
