//! The paper's experiments on the simulated cell, at reduced sizes (the
//! full sizes run with `primo experiment golden|power`).
use primo_learn::algorithm::Algorithm as Method;
use primo_learn::experiment;
use primo_learn::experiment::median_rollouts;
use primo_learn::learner::Learner;
use primo_learn::pour::rig::{Simulated, roll_out};
use primo_learn::pour::settings::Settings;
use primo_learn::pour::simulate::learn;
use primo_learn::pour::skill::Space;
use primo_learn::pour::skill::built_in_skill;
use primo_sim::cell::{CellConfig, GlassKind};

#[test]
fn error_learning_reaches_2_ml_for_every_bottle_volume() {
    let cell = CellConfig::standard(GlassKind::Normal);
    let skill = built_in_skill(&cell, Space::Cartesian, 30).unwrap();
    let volumes = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0];
    let runs = experiment::golden(&skill, &cell, &volumes, 0.002, 1, |_| {}).unwrap();
    for run in &runs {
        let n = run.rollouts_to_precision;
        println!("{} l {:?}: {n:?} roll-outs", run.volume, run.method);
        assert!(
            n.is_some(),
            "{} l {:?} did not reach 2 ml",
            run.volume,
            run.method
        );
        let last = run.records.last().unwrap();
        assert!(last.trial.error.abs() < 0.002 && last.trial.spilled == 0.0);
    }
    let median = |m| median_rollouts(&runs, m).unwrap();
    let (golden, illinois, secant) = (
        median(Method::Golden),
        median(Method::Illinois),
        median(Method::Secant),
    );
    println!("median roll-outs: golden {golden}, illinois {illinois}, secant {secant}");
    // Measured: golden 7.5, Illinois 5, secant 3.
    assert!(secant < illinois && illinois < golden);
    // The secant learner steps from its best roll-out: it never pours much
    // beyond the target, where golden section's second roll-out jumps to
    // the far end of the bracket.
    let worst = |m| {
        runs.iter()
            .filter(|r| r.method == m)
            .map(|r| r.worst_overpour)
            .fold(0.0, f64::max)
    };
    let first = runs
        .iter()
        .filter_map(|r| r.records.first())
        .map(|r| r.trial.error)
        .fold(0.0, f64::max);
    assert!(
        worst(Method::Secant) <= first,
        "{} {first}",
        worst(Method::Secant)
    );
    assert!(worst(Method::Golden) > 0.1);
}

#[test]
fn parameter_counts_match_the_paper() {
    let cell = CellConfig::standard(GlassKind::Small);
    for (kernels, count) in [(30, 219), (10, 79)] {
        let skill = built_in_skill(&cell, Space::Joint, kernels).unwrap();
        assert_eq!(skill.param_len() + 1, count, "{kernels} kernels");
    }
}

#[test]
fn joint_space_generalization_spills_where_cartesian_does_not() {
    let cell = CellConfig::standard(GlassKind::Small);
    let trial = |space| {
        let skill = built_in_skill(&cell, space, 30).unwrap();
        let mut rig = Simulated::new(cell, 0.5, 1).unwrap();
        roll_out(&mut rig, &skill, 0.2, 1, &[0.5], &[]).unwrap()
    };
    let (cartesian, joint) = (trial(Space::Cartesian), trial(Space::Joint));
    println!("cartesian {cartesian:?}\njoint {joint:?}");
    assert!(cartesian.spilled < 1e-4, "{cartesian:?}");
    assert!(joint.spilled > 0.03, "{joint:?}");
    // At the demonstrations' own queries the joint movements do not spill.
    let skill = built_in_skill(&cell, Space::Joint, 30).unwrap();
    for q in [0.3f32, 1.0] {
        let mut rig = Simulated::new(cell, q.into(), 1).unwrap();
        let t = roll_out(&mut rig, &skill, 0.2, 1, &[q], &[]).unwrap();
        assert!(
            t.spilled < 1e-3 && (t.poured - 0.2).abs() < 0.02,
            "q {q}: {t:?}"
        );
    }
}

#[test]
fn power_learns_to_pour_without_spilling_from_the_joint_space_start() {
    let cell = CellConfig::standard(GlassKind::Small);
    let skill = built_in_skill(&cell, Space::Joint, 30).unwrap();
    let (runs, updates) = (3, 25);
    let curves = experiment::power(&skill, &cell, runs, updates, 7, |_| {}).unwrap();
    for (variant, c) in experiment::Variant::ALL.iter().zip(&curves) {
        let name = variant.name();
        let zero = c.zero_reward as f64 / c.rollouts as f64;
        println!(
            "{name}: reward {:.3} -> {:.3}, spilled {:.1} -> {:.2} ml, |error| {:.1} -> {:.2} ml, {:.0} % reward 0",
            c.reward.mean[0],
            c.reward.last(),
            c.spilled.mean[0] * 1e3,
            c.spilled.last() * 1e3,
            c.error.mean[0] * 1e3,
            c.error.last() * 1e3,
            zero * 100.0
        );
        // The start and one point after each update; 4 roll-outs per
        // update and the final mean's.
        assert_eq!(c.reward.mean.len(), updates as usize + 1);
        assert_eq!(c.rollouts, runs * (4 * updates as usize + 1));
        // Point 0 is the generalized start, the same in every run: it spills.
        assert!(c.spilled.mean[0] > 0.05 && c.reward.std[0] < 1e-3, "{name}");
        // Measured over 8 seeds at this size: final reward 0.98-1.0, spill
        // below 1.4 ml, 20-35 % of roll-outs with reward 0 (exploring with
        // s as a variance: 98-99 %, and the reward only reached 0.44).
        // Whether extended beats ordinary at this size depends on the seed:
        // not asserted.
        assert!(c.reward.last() > 0.9, "{name} did not learn");
        assert!(c.spilled.last() < 0.005, "{name} still spills");
        assert!(zero < 0.5, "{name}: {:.0} % reward 0", zero * 100.0);
    }
}

#[test]
fn runs_are_reproducible() {
    let cell = CellConfig::standard(GlassKind::Small);
    let skill = built_in_skill(&cell, Space::Joint, 10).unwrap();
    let run = || {
        let mut s = Settings::paper(Method::Power, 0.5, 0.2, 3);
        s.max_rollouts = 12;
        learn(&skill, &cell, &s, &mut Learner::local(), |_| {}).unwrap()
    };
    assert_eq!(run(), run());
}
