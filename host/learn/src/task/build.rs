//! Building a checked task: its demonstrations read, their columns
//! checked (by name, across demonstrations) and against the limits, and
//! the skill fitted.

use primo_mtsics::path::read_text;
use primo_robot::envelope::{ColumnLimit, Limits};
use primo_skill::Skill;
use primo_skill::coupled::Repulsion;
use primo_skill::csv::{Demo, check_rotation_vectors, parse_demo};
use primo_skill::dmpfile::{DmpFile, orientation_groups};
use primo_skill::shaping::Via;
use primo_skill::skill::same_columns;

use crate::Error;

use super::goals::LearnedGoals;
use super::spec::{Built, LimitPush, LimitsSpec, Task};

impl Task {
    /// Reads the demonstrations, checks that their columns match by name
    /// (each against the first) and that they pass the limits, and fits the
    /// skill. Not for the built-in pour (its cell builds its own skill).
    pub fn build(&self) -> Result<Built, Error> {
        let spec = self
            .limits
            .as_ref()
            .ok_or_else(|| Error::Invalid("the built-in pour builds its skill itself".into()))?;
        let mut limits = spec.limits()?;
        let mut demos: Vec<(String, Demo)> = Vec::new();
        for d in &self.demos {
            let name = d.file.display().to_string();
            // Named in the task file, not by a setting: checked when it was
            // loaded, so this is rare.
            let text = read_text(&d.file).map_err(|f| Error::Invalid(format!("{name}: {f}")))?;
            let demo = parse_demo(&name, &text)?;
            check_rotation_vectors(&name, &demo)?;
            if let Some((first, reference)) = demos.first() {
                same_columns(&reference.names, &demo.names).map_err(|why| {
                    Error::Invalid(format!(
                        "{name}: {why} (the columns of {first}, the first demonstration)"
                    ))
                })?;
            } else {
                self.exempt_orientations(spec, &mut limits, &demo.names)?;
            }
            limits.covers(&demo.names).map_err(|why| {
                Error::Invalid(format!("{name}: {why} ({})", self.limits_place()))
            })?;
            let times: Vec<f64> = demo.times.iter().map(|t| f64::from(*t)).collect();
            let rows: Vec<f64> = demo.positions.iter().map(|v| f64::from(*v)).collect();
            limits.check(&demo.names, times, &rows).map_err(|why| {
                Error::Invalid(format!(
                    "{name}: the demonstration itself is beyond the task's limits: {why}"
                ))
            })?;
            demos.push((name, demo));
        }
        if let LimitsSpec::Columns { columns, .. } = spec
            && let Some((_, first)) = demos.first()
            && let Some(extra) = columns.keys().find(|c| !first.names.contains(c))
        {
            return Err(Error::Invalid(format!(
                "{}: [movement.limits] {extra}: not a column of the demonstrations ({})",
                self.file.display(),
                first.names.join(",")
            )));
        }
        let dt = match (self.dt, demos.first()) {
            (Some(dt), _) => dt,
            (None, Some((_, d))) => median_step(&d.times),
            (None, None) => return Err(Error::Invalid("no demonstrations".into())),
        };
        let examples: Vec<(&[f32], &Demo)> = self
            .demos
            .iter()
            .zip(&demos)
            .map(|(t, (_, d))| (&t.query[..], d))
            .collect();
        let fitted = Skill::fit_demos(&examples, self.kernels, self.scaling, self.final_velocity)?;
        let files: Vec<(&[f32], &DmpFile)> = (examples.iter().zip(&fitted))
            .map(|((q, _), f)| (*q, f))
            .collect();
        let mut skill = Skill::from_files(&files, self.regression)?;
        if let Some(o) = &self.obstacles {
            skill = skill.with_obstacles(o.avoidance())?;
        }
        if !self.vias.is_empty() {
            let vias = (self.vias.iter())
                .map(|(time, column, value)| Via {
                    time: *time as f32,
                    column: column.clone(),
                    value: *value as f32,
                })
                .collect();
            skill = skill.with_vias(vias)?;
        }
        if let Some(push) = &self.limit_push {
            let repel = repulsion(&limits, skill.names(), push).map_err(|why| {
                Error::Invalid(format!(
                    "{}: [movement] limit_margin: {why}",
                    self.file.display()
                ))
            })?;
            skill = skill.with_repulsion(repel)?;
        }
        let goals = LearnedGoals::of_task(self, &skill, &limits)?;
        Ok(Built {
            skill,
            fitted,
            limits,
            dt,
            goals,
        })
    }

    /// Orientation columns (`…qw,…qx,…qy,…qz`, the rule of `primo dmp
    /// fit`) take no per-column limits: a unit quaternion's components say
    /// nothing of how far or fast it turns, and primo writes them
    /// unit-norm. An entry for one is refused; they pass the check.
    fn exempt_orientations(
        &self,
        spec: &LimitsSpec,
        limits: &mut Limits,
        names: &[String],
    ) -> Result<(), Error> {
        let groups = orientation_groups(names);
        let columns = groups.iter().flat_map(|(group, _)| group);
        if let LimitsSpec::Columns {
            columns: limited, ..
        } = spec
            && let Some((group, name)) = groups
                .iter()
                .find_map(|(g, _)| g.iter().find(|c| limited.contains_key(*c)).map(|c| (g, c)))
        {
            return Err(Error::Invalid(format!(
                "{}: [movement.limits] {name}: a component of the orientation {} (a unit \
                 quaternion); per-column limits do not apply to orientations: remove the entry",
                self.file.display(),
                group.join(",")
            )));
        }
        if let Limits::Envelope(e) = limits {
            e.columns.extend(columns.map(|name| ColumnLimit {
                name: name.clone(),
                min: f64::NEG_INFINITY,
                max: f64::INFINITY,
                max_speed: f64::INFINITY,
            }));
        }
        Ok(())
    }

    fn limits_place(&self) -> String {
        format!("the limits in {}", self.file.display())
    }
}

/// `push` against the limits of the columns `names`: the robot's joints'
/// (the columns are its joints) or each column's and the workspace box's.
fn repulsion(limits: &Limits, names: &[String], push: &LimitPush) -> Result<Repulsion, String> {
    let mut bounds: Vec<(String, f32, f32)> = Vec::new();
    match limits {
        Limits::Robot(robot) => {
            for name in names {
                let Some(joint) = robot.chain.joint(name) else {
                    return Err(format!(
                        "`{name}` is no joint of {}: the push keeps joint trajectories from \
                         the joints' limits, not a tool's pose",
                        robot.chain.robot
                    ));
                };
                let l = &joint.limits;
                bounds.push((name.clone(), l.lower as f32, l.upper as f32));
            }
        }
        Limits::Envelope(e) => {
            let mut push = |name: &str, min: f64, max: f64| match bounds
                .iter_mut()
                .find(|(n, ..)| n == name)
            {
                Some((_, lo, hi)) => (*lo, *hi) = (lo.max(min as f32), hi.min(max as f32)),
                None => bounds.push((name.to_string(), min as f32, max as f32)),
            };
            // Orientation columns have infinite limits: none.
            for c in e
                .columns
                .iter()
                .filter(|c| c.min.is_finite() || c.max.is_finite())
            {
                push(&c.name, c.min, c.max);
            }
            if let Some(w) = &e.workspace {
                for (i, name) in w.columns.iter().enumerate() {
                    push(name, w.min[i], w.max[i]);
                }
            }
        }
    }
    Ok(Repulsion {
        limits: bounds,
        margin: push.margin as f32,
        gain: push.gain as f32,
    })
}

/// The median time step of a recording, s.
fn median_step(times: &[f32]) -> f64 {
    let mut steps: Vec<f64> = times
        .windows(2)
        .map(|w| f64::from(w[1]) - f64::from(w[0]))
        .collect();
    steps.sort_by(f64::total_cmp);
    steps.get(steps.len() / 2).copied().unwrap_or(0.01)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The example throw's task in a directory of its own, its
    /// demonstrations resampled at 1 kHz (linearly) and stamped from
    /// `origin`: the same instants whatever the origin (those a recorder
    /// stamping from 1.7e9 s can hold), each stamp printed so that it
    /// reads back exactly.
    fn throw_at(origin: f64) -> Task {
        let examples =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/throw");
        let dir = std::env::temp_dir()
            .join(format!("primo-task-build-{}", std::process::id()))
            .join(origin.to_string());
        std::fs::create_dir_all(dir.join("demos")).unwrap();
        for name in ["fast", "slow"] {
            let file = examples.join(format!("demos/{name}.csv"));
            let demo = parse_demo("demo", &std::fs::read_to_string(file).unwrap()).unwrap();
            let mut out = format!("t,{}\n", demo.names.join(","));
            let rows: Vec<&[f32]> = demo.positions.chunks_exact(demo.names.len()).collect();
            let end = f64::from(*demo.times.last().unwrap());
            for i in 0..=(end * 1e3).round() as u32 {
                let since_first = (1.7e9 + f64::from(i) * 1e-3) - 1.7e9;
                let at = demo.times.partition_point(|t| f64::from(*t) <= since_first);
                let (k, l) = (at.saturating_sub(1), at.min(demo.times.len() - 1));
                let (a, b) = (f64::from(demo.times[k]), f64::from(demo.times[l]));
                let w = if l > k {
                    (since_first - a) / (b - a)
                } else {
                    0.0
                } as f32;
                out.push_str(&(origin + since_first).to_string());
                for (p, q) in rows[k].iter().zip(rows[l]) {
                    out.push_str(&format!(",{}", p + w * (q - p)));
                }
                out.push('\n');
            }
            std::fs::write(dir.join(format!("demos/{name}.csv")), out).unwrap();
        }
        let task = dir.join("throw.toml");
        std::fs::copy(examples.join("throw.toml"), &task).unwrap();
        Task::load(&task).unwrap()
    }

    /// Minimum jerk from 0 to 1 over `t` in [0, 1].
    fn min_jerk(t: f64) -> f64 {
        t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
    }

    /// A task over two reaches in `x, y, z` (to 0.6 and 0.8 m in `x`,
    /// along `profile` over one second), with `movement` as its
    /// `[movement]` keys, in a directory of its own.
    fn reaches(movement: &str, profile: fn(f64) -> f64) -> Task {
        let dir = std::env::temp_dir()
            .join(format!("primo-task-reaches-{}", std::process::id()))
            .join(format!("{}-{}", movement.len(), profile(0.5)));
        std::fs::create_dir_all(&dir).unwrap();
        for (name, reach) in [("near", 0.6), ("far", 0.8)] {
            let mut out = String::from("t,x,y,z\n");
            for i in 0..=100 {
                let t = f64::from(i) / 100.0;
                out.push_str(&format!("{t},{},0.1,0.2\n", reach * profile(t)));
            }
            std::fs::write(dir.join(format!("{name}.csv")), out).unwrap();
        }
        let text = format!(
            "version = 1\n\n[[demo]]\nfile = \"near.csv\"\nquery = [0.6]\n\n[[demo]]\n\
             file = \"far.csv\"\nquery = [0.8]\n\n[movement]\n{movement}\n\n\
             [movement.limits]\nx = {{ min = -1.0, max = 1.0, max_speed = 10.0 }}\ny = {{ min = -1.0, max = 1.0, max_speed = 10.0 }}\nz = {{ min = -1.0, max = 1.0, max_speed = 10.0 }}\n\n[goal]\ndesired = [0.7]\nlow = [0.5]\nhigh = [0.9]\nprecision = 0.01\n\n\
             [learner]\nmethod = \"golden\"\n\n[evaluate]\ncommand = [\"true\"]\n"
        );
        std::fs::write(dir.join("reach.toml"), text).unwrap();
        Task::load(&dir.join("reach.toml")).unwrap()
    }

    #[test]
    fn a_tasks_obstacles_steer_every_planned_movement() {
        let built = reaches("obstacles = [[0.35, 0.11, 0.2, 0.05]]", min_jerk)
            .build()
            .unwrap();
        let plan = built.skill.plan(&[0.7], &[], 0.002).unwrap();
        let clearance = plan
            .rows
            .chunks_exact(3)
            .map(|p| {
                ((p[0] - 0.35).powi(2) + (p[1] - 0.11).powi(2) + (p[2] - 0.2).powi(2)).sqrt() - 0.05
            })
            .fold(f64::INFINITY, f64::min);
        assert!(clearance > 0.0, "entered the ball: {clearance}");
        let end = &plan.rows[plan.rows.len() - 3..];
        assert!(
            (end[0] - 0.7).abs() < 1e-3 && (end[1] - 0.1).abs() < 1e-3,
            "{end:?}"
        );
        // Without them, the path goes through the ball.
        let plain = reaches("", min_jerk).build().unwrap();
        let through = plain.skill.plan(&[0.7], &[], 0.002).unwrap();
        assert!(
            through
                .rows
                .chunks_exact(3)
                .any(|p| (p[0] - 0.35).abs() < 0.01 && (p[1] - 0.11).abs() < 0.05)
        );
        // Columns the demonstrations lack are refused when the skill is built.
        let wrong = reaches(
            "obstacles = [[0.35, 0.11, 0.2, 0.05]]\nobstacle_columns = [\"x\", \"y\", \"w\"]",
            min_jerk,
        );
        let e = wrong.build().unwrap_err().to_string();
        assert!(
            e.contains("obstacles: no position column `w` among x,y,z"),
            "{e}"
        );
    }

    #[test]
    fn a_tasks_via_points_bend_every_planned_movement() {
        let built = reaches("via = [[0.5, \"y\", 0.3], [0.25, \"x\", 0.02]]", min_jerk)
            .build()
            .unwrap();
        for q in [0.6, 0.7, 0.9] {
            let plan = built.skill.plan(&[q], &[], 0.001).unwrap();
            let at = |t: f64| plan.t.iter().position(|s| (s - t).abs() < 1e-6).unwrap();
            assert!((plan.rows[3 * at(0.5) + 1] - 0.3).abs() < 1e-4, "q = {q}");
            assert!((plan.rows[3 * at(0.25)] - 0.02).abs() < 1e-4, "q = {q}");
            let end = &plan.rows[plan.rows.len() - 3..];
            assert!(
                (end[0] - f64::from(q)).abs() < 1e-3 && (end[1] - 0.1).abs() < 1e-3,
                "{end:?}"
            );
        }
        let e = reaches("via = [[0.5, \"w\", 0.3]]", min_jerk)
            .build()
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("via-points: no position column `w` among x,y,z"),
            "{e}"
        );
        let late = reaches("via = [[1.5, \"y\", 0.3]]", min_jerk)
            .build()
            .unwrap();
        let e = late.skill.plan(&[0.7], &[], 0.001).unwrap_err().to_string();
        assert!(e.contains("within the movement"), "{e}");
    }

    #[test]
    fn a_promp_generalizes_a_tasks_demonstrations() {
        let built = reaches("generalization = \"promp\"", min_jerk)
            .build()
            .unwrap();
        assert!(matches!(
            built.skill.regression(),
            primo_core::generalize::Method::ProMp { .. }
        ));
        for q in [0.5, 0.7, 0.9] {
            let plan = built.skill.plan(&[q], &[], 0.002).unwrap();
            let end = plan.rows[plan.rows.len() - 3];
            assert!((end - f64::from(q)).abs() < 1e-3, "q = {q}: {end}");
        }
    }

    #[test]
    fn a_tasks_demonstrated_final_velocity_is_generalized_with_the_movement() {
        // Reaches cut at the fastest point of their swing: each ends moving
        // at 1.875/2 of its reach per second.
        let swing = |t: f64| min_jerk(t / 2.0);
        let moving = reaches("final_velocity = \"demonstrated\"", swing)
            .build()
            .unwrap();
        let dmp = moving.skill.movement(&[0.7], &[]).unwrap().dmp;
        let expected = 0.7 * 1.875 / 2.0;
        assert!(
            (f64::from(dmp.goal_velocity()[0]) - expected).abs() < 0.02,
            "{:?}",
            dmp.goal_velocity()
        );
        let plan = moving.skill.plan(&[0.7], &[], 0.001).unwrap();
        let n = plan.t.len();
        let v = (plan.rows[3 * (n - 1)] - plan.rows[3 * (n - 2)]) / (plan.t[n - 1] - plan.t[n - 2]);
        assert!((v - expected).abs() < 0.02, "{v} m/s");
        // At rest (the default), the DMP carries no velocity to change.
        let resting = reaches("", swing).build().unwrap();
        let dmp = resting.skill.movement(&[0.7], &[]).unwrap().dmp;
        assert!(dmp.goal_velocity().is_empty());
    }

    #[test]
    fn a_tasks_limit_margin_keeps_an_extrapolated_overshoot_within_the_limits() {
        // Reaches that overshoot: the far one peaks at 0.995 under its
        // limit of 1; extrapolated to 0.9, at 1.12 beyond it.
        let overshoot =
            |t: f64| t * t * (3.0 - 2.0 * t) + (std::f64::consts::PI * t).sin().powi(2) * t;
        let plan = |built: &Built| {
            let plan = built.skill.plan(&[0.9], &[], 0.002).unwrap();
            let top = plan
                .rows
                .iter()
                .step_by(3)
                .copied()
                .fold(f64::MIN, f64::max);
            let checked = built.limits.check(&plan.names, plan.t.clone(), &plan.rows);
            (top, plan.rows[plan.rows.len() - 3], checked.is_ok())
        };
        let free = reaches("", overshoot).build().unwrap();
        let (top, _, passes) = plan(&free);
        assert!(top > 1.0 && !passes, "{top}");
        let held = reaches("limit_margin = 0.05", overshoot).build().unwrap();
        let (top, end, passes) = plan(&held);
        assert!(top < 1.0 && passes, "{top}");
        assert!((end - 0.9).abs() < 1e-3, "{end}");
        // On a robot, the joints' limits; a tool pose has none to keep from.
        let fr3 = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/fr3");
        let dir = std::env::temp_dir().join(format!("primo-task-fr3-push-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for f in ["near.csv", "far.csv"] {
            std::fs::copy(fr3.join(f), dir.join(f)).unwrap();
        }
        let text = std::fs::read_to_string(fr3.join("reach.toml"))
            .unwrap()
            .replace(
                "robot = \"../../host/franka/src/fr3.urdf\"",
                &format!(
                    "robot = \"{}\"\nlimit_margin = 0.05",
                    fr3.join("../../host/franka/src/fr3.urdf").display()
                ),
            );
        std::fs::write(dir.join("reach.toml"), text).unwrap();
        let built = Task::load(&dir.join("reach.toml"))
            .unwrap()
            .build()
            .unwrap();
        let plan = built.skill.plan(&[0.4], &[], built.dt).unwrap();
        built
            .limits
            .check(&plan.names, plan.t.clone(), &plan.rows)
            .unwrap();
    }

    #[test]
    fn demonstrations_stamped_in_unix_time_build_the_skill_from_0() {
        let (unix, zero) = (
            throw_at(1.7e9).build().unwrap(),
            throw_at(0.0).build().unwrap(),
        );
        assert_eq!(unix.dt, zero.dt);
        assert!((unix.dt - 1e-3).abs() < 1e-6, "{}", unix.dt);
        let examples = |b: &Built| -> Vec<(Vec<f32>, Vec<f32>)> {
            (b.skill.examples())
                .map(|(q, p)| (q.to_vec(), p.to_vec()))
                .collect()
        };
        assert_eq!(examples(&unix), examples(&zero));
        let plan = |b: &Built| b.skill.plan(&[1.5], &[], b.dt).unwrap();
        assert_eq!(plan(&unix), plan(&zero));
    }

    #[test]
    fn the_scaling_key_chooses_the_skills_scaling() {
        let mut task = throw_at(0.0);
        let per_dof = task.build().unwrap();
        assert!(per_dof.fitted.iter().all(|f| f.dmp.reference().is_none()));
        task.scaling = primo_skill::dmpfile::AmplitudeScaling::Global;
        let global = task.build().unwrap();
        for (f, demo) in global.fitted.iter().zip(&task.demos) {
            let demo = parse_demo("demo", &std::fs::read_to_string(&demo.file).unwrap()).unwrap();
            let span: Vec<f32> = (0..2)
                .map(|d| demo.positions[demo.positions.len() - 2 + d] - demo.positions[d])
                .collect();
            assert_eq!(f.dmp.reference(), Some(&span[..]));
        }
        // At an example's query the generalized movement is that example's
        // (LWR through two examples is exact there, to rounding).
        let q = task.demos[0].query.clone();
        let movement = global.skill.movement(&q, &[]).unwrap();
        let reference = movement.dmp.reference().unwrap();
        let example = global.fitted[0].dmp.reference().unwrap();
        for (a, b) in reference.iter().zip(example) {
            assert!((a - b).abs() < 1e-5 * b.abs().max(1.0), "{a} vs {b}");
        }
        // There both reproduce the demonstration, as fitted alike.
        let a = global.skill.plan(&q, &[], 1e-3).unwrap();
        let b = per_dof.skill.plan(&q, &[], 1e-3).unwrap();
        let apart = (a.rows.iter().zip(&b.rows)).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(a.t == b.t && apart < 1e-4, "{apart}");
    }
}
