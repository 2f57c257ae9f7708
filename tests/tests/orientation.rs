//! A Cartesian pour whose bottle orientation passes ±180° all along: the
//! cell's bottle frame turned half a turn about the bottle's own axis. The
//! bottle is symmetric about its axis and the arm holds it as before, so
//! the cell and the pour are the same, but the demonstrated orientations
//! now lie about 180° from the base frame's and the expert's tremor carries
//! them across it. A rotation vector wraps by 2π there; the quaternion
//! columns do not, and the skill, the gate and the cell pour as they do in
//! the usual frame.

use primo_learn::pour::rig::{Simulated, roll_out};
use primo_learn::pour::skill::Space;
use primo_learn::pour::skill::{built_in_demos, fit};
use primo_robot::Pose;
use primo_sim::cell::{CellConfig, GlassKind};
use primo_skill::csv::{Demo, check_rotation_vectors};
use primo_skill::{Plan, Skill};

/// The quaternion columns of a Cartesian row.
fn orientation(row: &[f64]) -> [f64; 4] {
    [row[3], row[4], row[5], row[6]]
}

fn dot(a: [f64; 4], b: [f64; 4]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `q ⊗ (0, 0, 0, 1)`: `q` followed by half a turn about its own z axis.
fn half_turned([w, x, y, z]: [f64; 4]) -> [f64; 4] {
    [-z, y, -x, w]
}

fn skill(demos: Vec<(f32, Demo)>) -> Skill {
    let named: Vec<(String, f32, Demo)> = demos
        .into_iter()
        .map(|(q, d)| (format!("the {q} l demonstration"), q, d))
        .collect();
    fit(Space::Cartesian, &named, 30).unwrap()
}

fn plan(skill: &Skill, cell: &CellConfig) -> Plan {
    skill.plan(&[0.5], &[], cell.dt).unwrap()
}

#[test]
fn a_pour_through_180_degrees_plans_continuously_and_pours_as_in_the_usual_frame() {
    let cell = CellConfig::standard(GlassKind::Normal);
    let mut turned = cell;
    turned.grasp = cell
        .grasp
        .then(&Pose::from_quaternion([0.0; 3], [0.0, 0.0, 0.0, 1.0]));
    let demos = built_in_demos(&cell, Space::Cartesian).unwrap();
    let turned_demos: Vec<(f32, Demo)> = demos
        .iter()
        .map(|(q, d)| {
            let mut d = d.clone();
            for row in d.positions.chunks_exact_mut(7) {
                let q = half_turned(orientation(
                    &row.iter().map(|v| f64::from(*v)).collect::<Vec<_>>(),
                ));
                for (v, t) in row[3..].iter_mut().zip(q) {
                    *v = t as f32;
                }
            }
            (*q, d)
        })
        .collect();
    for (q, d) in &turned_demos {
        // The angle from the base frame, 2·acos|w|, crosses 180° (w
        // changes sign) again and again.
        let w: Vec<f32> = d.positions.chunks_exact(7).map(|r| r[3]).collect();
        let crossings = w.windows(2).filter(|p| p[0] * p[1] < 0.0).count();
        assert!(crossings > 10, "{q} l: {crossings} crossings");
        // As rotation vectors the recording wraps, and is refused.
        let positions = d
            .positions
            .chunks_exact(7)
            .flat_map(|r| {
                let o = orientation(&r.iter().map(|v| f64::from(*v)).collect::<Vec<_>>());
                let v = Pose::from_quaternion([0.0; 3], o).rotation_vector();
                [r[0], r[1], r[2]].into_iter().chain(v.map(|x| x as f32))
            })
            .collect();
        let rotation_vectors = Demo {
            names: ["x", "y", "z", "rx", "ry", "rz"].map(String::from).to_vec(),
            times: d.times.clone(),
            positions,
        };
        assert!(check_rotation_vectors("demo", &rotation_vectors).is_err());
    }
    let (usual, through) = (skill(demos), skill(turned_demos));
    let (a, b) = (plan(&usual, &cell), plan(&through, &turned));
    assert_eq!((a.t.len(), b.dof), (b.t.len(), 7));
    let mut last: Option<[f64; 4]> = None;
    let (mut low, mut high) = (f64::MAX, f64::MIN);
    for (ra, rb) in a.rows.chunks_exact(7).zip(b.rows.chunks_exact(7)) {
        let o = orientation(rb);
        // Unit, continuous from step to step, and the usual plan's
        // orientation turned half a turn; the mouth the same.
        assert!((dot(o, o).sqrt() - 1.0).abs() < 1e-5, "{rb:?}");
        if let Some(p) = last {
            assert!(dot(p, o) > 1.0 - 1e-5, "{p:?} to {o:?}");
        }
        last = Some(o);
        assert!(
            dot(o, half_turned(orientation(ra))).abs() > 1.0 - 1e-6,
            "{ra:?} {rb:?}"
        );
        assert!(
            (0..3).all(|k| (ra[k] - rb[k]).abs() < 1e-6),
            "{ra:?} {rb:?}"
        );
        low = low.min(o[0]);
        high = high.max(o[0]);
    }
    // The plan itself passes 180° (w changes sign) without a jump.
    assert!(low < 0.0 && high > 0.0, "w in [{low}, {high}]");
    // Through the turned cell's gate and physics it pours what the usual
    // frame pours.
    let pour = |skill: &Skill, cell: CellConfig| {
        let mut rig = Simulated::new(cell, 0.5, 1).unwrap();
        roll_out(&mut rig, skill, 0.2, 1, &[0.5], &[]).unwrap()
    };
    let (a, b) = (pour(&usual, cell), pour(&through, turned));
    println!("usual frame {a:?}\nturned {b:?}");
    assert!(a.rejected.is_none() && b.rejected.is_none(), "{b:?}");
    assert!(
        (a.poured - b.poured).abs() < 1e-5 && b.spilled < 1e-4,
        "{a:?} {b:?}"
    );
}
