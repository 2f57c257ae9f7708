//! The pour as a kind of run ([`Pour`]): what it logs of itself (the
//! settings and seed, the skill: demonstration files, kernels, space,
//! glass; the cell), how a roll-out is made (on the simulated cell or the
//! real instruments) and what it reports. A resumed run takes all of it
//! from the log; only where the instruments and the learner are connected
//! (the robot's address, the scale's port, the coprocessor) may change.

use std::path::{Path, PathBuf};

use primo_protocol::learner::Setup;
use primo_skill::Skill;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::algorithm::Algorithm;
use crate::clock::Seconds;
use crate::error::Setting;
use crate::learner::Learner;
use crate::rollouts::{Ending, Entry, Point, Record, Stop};
use crate::run::{Cell, Event, Execute, Failure, Kind, LearnerSpec, Start, run};
use crate::runlog::RunEvent;

use super::report::{PourSummary, RolloutSummary, write_pour};
use super::rig::{Instruments, InstrumentsSpec, Operator, Rig, Simulated, roll_out};
use super::series::write_csv;
use super::settings::{Settings, setup};
use super::skill::{Built, Converted, SkillSpec, Space};
use super::trial::Trial;
use super::weigh::ScaleSpec;

/// Where the roll-outs happen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CellSpec {
    /// The simulated cell in this process.
    Simulated,
    /// A real cell's instruments.
    Instruments(InstrumentsSpec),
}

/// A pour: what it learns, with which skill, where.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Pour {
    /// What to learn and how.
    pub settings: Settings,
    /// The skill.
    pub skill: SkillSpec,
    /// Where.
    pub cell: CellSpec,
}

/// What a pour reports beside the run's own events.
#[derive(Debug, Clone, PartialEq)]
pub enum Note {
    /// A demonstration file in the earlier Cartesian columns was
    /// converted to the quaternion columns.
    Converted(Converted),
    /// The real cell's instruments are open.
    Cell {
        /// Where they are.
        spec: InstrumentsSpec,
        /// The scale's serial number.
        scale_serial: String,
    },
}

/// How a pour ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Finished {
    /// The settings.
    pub settings: Settings,
    /// The last roll-out (PoWER: the last roll-out of the mean).
    pub last: Record<Trial>,
    /// Error learning reached the precision at this roll-out.
    pub converged_at: Option<u32>,
    /// Why the learner stopped.
    pub stop: Stop,
    /// The roll-out `series.csv` holds, if any.
    pub series_of: Option<u32>,
    /// Whether the cell records series (the simulated one does).
    pub simulated: bool,
    /// The output directory.
    pub dir: PathBuf,
}

/// What a resumed pour may take: where its instruments are now, and a
/// new roll-out budget.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Resumed {
    /// The real cell's instruments, if they moved.
    pub instruments: Option<InstrumentsSpec>,
    /// A new roll-out budget.
    pub max_rollouts: Option<u32>,
}

/// A pour's skill fitted, and its cell.
#[derive(Debug, Clone)]
pub struct Prepared {
    built: Built,
    simulated: Simulated,
}

impl Kind for Pour {
    const NAME: &'static str = "pour";
    type Trial = Trial;
    type Built = Prepared;
    type Person = Box<dyn Operator>;
    type Moved = Resumed;
    type Note = Note;
    type Finished = Finished;

    fn validate(&self, learner: &LearnerSpec) -> Result<(), Error> {
        self.settings.validate()?;
        self.skill.validate()?;
        let capacity = self.skill.cell().bottle_litres();
        if self.settings.bottle > capacity {
            return Err(Error::setting(
                Setting::Bottle,
                self.settings.bottle,
                format!("the cell's bottle holds {capacity:.3} l"),
            ));
        }
        if let CellSpec::Instruments(spec) = &self.cell {
            spec.validate()?;
        }
        if learner.on_scale() && !on_primo_scale(&self.cell)? {
            return Err(Error::setting(
                Setting::Coprocessor,
                crate::run::ON_SCALE,
                "the learner runs on primo's scale: a real cell's scale postcard:PORT or \
                 qemu:LOAD_CELL",
            ));
        }
        Ok(())
    }

    fn check_moved(moved: &Self::Moved) -> Result<(), Error> {
        // A new budget is checked with the resumed run's settings.
        moved
            .instruments
            .as_ref()
            .map_or(Ok(()), InstrumentsSpec::validate)
    }

    /// Version 3 logs are the same; so are version 2 logs of joint-space
    /// runs (version 2's Cartesian movements were a rotation vector: a
    /// different skill and `Δθ`).
    fn reads(version: u32, logged: &Self) -> bool {
        version == 3 || (version == 2 && logged.skill.space == Space::Joint)
    }

    fn resume(&mut self, moved: Self::Moved, dir: &Path) -> Result<Vec<String>, Error> {
        match (&mut self.cell, moved.instruments) {
            (CellSpec::Instruments(logged), Some(now)) => *logged = now,
            (CellSpec::Simulated, Some(_)) => {
                return Err(Error::Invalid(format!(
                    "the run in {} is on the simulated cell: it cannot continue on \
                     instruments",
                    dir.display()
                )));
            }
            (_, None) => {}
        }
        // Where the instruments are is not a learned setting; the budget is.
        let budget = &mut self.settings.max_rollouts;
        Ok(moved
            .max_rollouts
            .and_then(|n| crate::run::budget_change(budget, n))
            .into_iter()
            .collect())
    }

    fn build(&self, note: &mut dyn FnMut(Note) -> Result<(), Error>) -> Result<Prepared, Error> {
        let built = self.skill.build()?;
        for c in &built.converted {
            note(Note::Converted(c.clone()))?;
        }
        let simulated = Simulated::new(built.cell, self.settings.bottle, self.settings.seed)?;
        Ok(Prepared { built, simulated })
    }

    fn skill(built: &Prepared) -> &Skill {
        &built.built.skill
    }

    fn method(&self) -> Algorithm {
        self.settings.method
    }

    fn setup(&self, built: &Prepared) -> Result<Setup, Error> {
        setup(&built.built.skill, &self.settings)
    }

    fn point(_: &Prepared, query: &[f32], delta: &[f32]) -> Point {
        Point::asked(query, delta)
    }

    fn max_rollouts(&self) -> u32 {
        self.settings.max_rollouts
    }

    fn execution<'a>(
        &'a self,
        built: &'a Prepared,
        at: Cell<'_, Self>,
    ) -> Result<Box<dyn Execute<Trial> + 'a>, Error> {
        let rig: Box<dyn Rig> = match &self.cell {
            CellSpec::Simulated => Box::new(built.simulated.clone()),
            CellSpec::Instruments(spec) => {
                let rig = Instruments::open(
                    spec.clone(),
                    &built.built.cell,
                    self.settings.bottle,
                    at.person,
                )?;
                (at.event)(Event::Note(Note::Cell {
                    spec: spec.clone(),
                    scale_serial: rig.scale_serial(),
                }))?;
                if at.spec.on_scale()
                    && let Some(link) = rig.scale_link()
                {
                    let what = format!("learner: on the scale, {}", link.name());
                    (at.event)(Event::Run(RunEvent::Learner(what)))?;
                    *at.learner = Learner::Remote(link);
                }
                Box::new(rig)
            }
        };
        Ok(Box::new(Pouring {
            rig,
            skill: &built.built.skill,
            target: self.settings.target,
        }))
    }

    fn report(
        &self,
        built: &Prepared,
        dir: &Path,
        run: &[Entry<Trial>],
        seconds: Seconds,
    ) -> Result<Finished, Error> {
        let s = &self.settings;
        let skill = &built.built.skill;
        let ending = Ending::of(run, s.method.is_power(), s.precision, |r| {
            Point::query(&r.query)
        })?;
        let records: Vec<_> = run.iter().map(|e| e.record.clone()).collect();
        let summary = PourSummary {
            settings: s,
            space: self.skill.space,
            parameters: s.method.learned_parameters(skill),
            rollouts: records.len(),
            converged_at: ending.converged_at,
            verdict: ending.stop.verdict(),
            last: RolloutSummary::of(ending.last),
            best: ending.best.map(|e| RolloutSummary::of(&e.record)),
            searched: (!s.method.is_power()).then(|| s.search_bounds()),
            seconds,
        };
        write_pour(dir, &records, &summary)?;
        // The best roll-out's time series: the simulated cell repeats it
        // exactly (the run itself keeps no series).
        let series = match (&self.cell, ending.best) {
            (CellSpec::Simulated, Some(e)) => {
                let mut recording = built.simulated.recording(1);
                roll_out(
                    &mut recording,
                    skill,
                    s.target,
                    e.record.rollout,
                    &e.record.query,
                    &e.delta,
                )?
                .series
            }
            _ => None,
        };
        write_csv(&dir.join("series.csv"), self.skill.space, series.as_ref())?;
        Ok(Finished {
            settings: *s,
            last: ending.last.clone(),
            converged_at: ending.converged_at,
            stop: ending.stop.clone(),
            series_of: series.as_ref().and(ending.best.map(|e| e.record.rollout)),
            simulated: matches!(self.cell, CellSpec::Simulated),
            dir: dir.to_path_buf(),
        })
    }
}

/// A pour's roll-outs on its rig.
struct Pouring<'a> {
    rig: Box<dyn Rig>,
    skill: &'a Skill,
    target: f64,
}

impl Execute<Trial> for Pouring<'_> {
    fn roll(&mut self, rollout: u32, query: &[f32], delta: &[f32]) -> Result<Trial, Error> {
        roll_out(
            self.rig.as_mut(),
            self.skill,
            self.target,
            rollout,
            query,
            delta,
        )
    }
}

/// Whether the cell weighs with primo's scale (which can run the learner).
fn on_primo_scale(cell: &CellSpec) -> Result<bool, Error> {
    Ok(match cell {
        CellSpec::Instruments(spec) => {
            !matches!(ScaleSpec::parse(&spec.scale)?, ScaleSpec::MtSics(_))
        }
        CellSpec::Simulated => false,
    })
}

/// A pour run ([`run`] of a [`Pour`]): `operator` is asked at a real
/// cell, `event` told what happens.
pub fn pour(
    start: Start<Pour>,
    learner: &LearnerSpec,
    operator: Box<dyn Operator>,
    event: impl FnMut(Event<Pour>) -> Result<(), Error>,
) -> Result<(), Failure> {
    run(start, learner, operator, event)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::learner::examples_crc;
    use crate::run::Header;
    use crate::runlog::RunLog;
    use primo_sim::cell::GlassKind;

    struct Nobody;

    impl Operator for Nobody {
        fn reset(&mut self, _: u32, _: f64) -> Result<(), Error> {
            Ok(())
        }

        fn warn(&mut self, _: u32, _: &str) {}
    }

    /// A version 2 log of a Cartesian run (rotation-vector movements) is
    /// refused by its version; one of a joint-space run is the same in
    /// version 3 and resumes.
    #[test]
    fn a_version_2_log_resumes_in_joint_space_only() {
        for space in [Space::Cartesian, Space::Joint] {
            let dir = std::env::temp_dir()
                .join(format!("primo-pour-v2-{space:?}-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
            let mut settings = Settings::paper(Algorithm::Golden, 0.5, 0.2, 1);
            settings.max_rollouts = 1;
            let skill = SkillSpec {
                space,
                glass: GlassKind::Normal,
                kernels: 10,
                demos: Vec::new(),
            };
            let header = Header {
                version: 2,
                task_kind: None,
                examples: examples_crc(&skill.build().unwrap().skill),
                run: Pour {
                    settings,
                    skill,
                    cell: CellSpec::Simulated,
                },
            };
            RunLog::create(&dir, &header).unwrap();
            let resume = Start::Resume {
                dir: dir.clone(),
                moved: Resumed::default(),
            };
            let run = pour(
                resume,
                &LearnerSpec::default(),
                Box::new(Nobody),
                |_| Ok(()),
            );
            match space {
                Space::Cartesian => {
                    let e = run.unwrap_err().to_string();
                    assert!(
                        e.contains("run.log: run log version 2, this primo reads version 4"),
                        "{e}"
                    );
                }
                Space::Joint => assert!(run.is_ok(), "{:?}", run.err()),
            }
            std::fs::remove_dir_all(&dir).unwrap();
        }
    }
}
