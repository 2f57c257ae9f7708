//! The learner behind the wire: same roll-outs as the learners used
//! directly, idempotent retransmissions, clear faults.

use heapless::Vec as HVec;
use primo_core::dmp::{Dmp, FitOptions};
use primo_core::generalize::{Generalizer, Method};
use primo_core::golden::{ErrorLearner, GoldenSection, SearchConfig, Status as SearchStatus};
use primo_core::power::{Block, Power, PowerConfig};
use primo_core::secant::{Rule, Secant, SecantConfig};
use primo_learner::{Coprocessor as Service, THETA, UNREAD};
use primo_protocol::fault::FaultKind;
use primo_protocol::frame::{self as wire, FrameReader, MAX_FRAME};
use primo_protocol::learner::{
    CHUNK, DmpStart, LearnerSetup, MAX_QUERY, Outcome, Reply, Request, Setup,
};

const LWR: Method = Method::Lwr { bandwidth: None };

fn search() -> SearchConfig {
    SearchConfig {
        low: 0.1,
        high: 1.5,
        desired: 0.5,
        precision: 1e-4,
        max_rollouts: 30,
    }
}

/// Two 2-DoF demos, fitted with 6 kernels: θ has 2·6 + 2 + 1 = 15 values.
fn examples() -> (Dmp<2, 6>, Vec<(f32, Vec<f32>)>) {
    let t: Vec<f32> = (0..101).map(|i| i as f32 / 100.0).collect();
    let mut out = Vec::new();
    let mut template = None;
    for (q, amp) in [(0.3f32, 1.0f32), (1.0, 2.0)] {
        let y: Vec<f32> = t
            .iter()
            .flat_map(|&s| [amp * s * s * (3.0 - 2.0 * s), 0.2 * (3.0 * s).sin()])
            .collect();
        let dmp = Dmp::<2, 6>::fit(&t, &y, 2, 6, &FitOptions::default()).unwrap();
        let mut theta = vec![0.0; dmp.param_len()];
        dmp.params(&mut theta).unwrap();
        out.push((q, theta));
        template.get_or_insert(dmp);
    }
    (template.unwrap(), out)
}

fn configure(s: &mut Service, learner: LearnerSetup) {
    configure_dim(s, learner, 1);
}

/// Configures `learner` with the two examples, each at the query with all
/// `query_dim` components equal to its 1-D query.
fn configure_dim(s: &mut Service, learner: LearnerSetup, query_dim: u8) {
    let (_, ex) = examples();
    let setup = Setup {
        learner,
        examples: ex.len() as u8,
        theta_len: ex[0].1.len() as u16,
        regression: LWR,
        seed: 11,
        query_dim,
    };
    assert_eq!(s.respond(&Request::Configure(setup)), Reply::Ok);
    for (i, (q, theta)) in ex.iter().enumerate() {
        let query = HVec::from_slice(&[*q; MAX_QUERY][..usize::from(query_dim)]).unwrap();
        for (c, chunk) in theta.chunks(CHUNK).enumerate() {
            let r = s.respond(&Request::Example {
                index: i as u8,
                query: query.clone(),
                offset: (c * CHUNK) as u16,
                values: HVec::from_slice(chunk).unwrap(),
            });
            assert_eq!(r, Reply::Ok, "example {i} chunk {c}");
        }
    }
}

/// A 1-D query or error.
fn q1(v: f32) -> HVec<f32, MAX_QUERY> {
    HVec::from_slice(&[v]).unwrap()
}

/// PoWER over `[q̂, Δθ]` with a query of `query_dim` values and θ of 15.
fn power_config(query_dim: usize) -> PowerConfig {
    PowerConfig::paper(&[
        Block {
            len: query_dim,
            variance: 0.01,
            decay: 0.9,
        },
        Block {
            len: 15,
            variance: 0.05,
            decay: 1.0,
        },
    ])
    .unwrap()
}

/// The whole `Δθ` of the roll-out in flight, fetched chunk by chunk.
fn fetch(s: &mut Service, len: usize) -> Vec<f32> {
    let mut delta = Vec::new();
    while delta.len() < len {
        match s.respond(&Request::Fetch {
            offset: delta.len() as u16,
        }) {
            Reply::Chunk { offset, values } => {
                assert_eq!(usize::from(offset), delta.len());
                delta.extend_from_slice(&values);
            }
            other => panic!("fetch: {other:?}"),
        }
    }
    delta
}

#[test]
fn golden_section_through_the_service_is_the_learner_itself() {
    let mut s = Service::new();
    configure(&mut s, LearnerSetup::Golden(search()));
    let mut direct = GoldenSection::new(search()).unwrap();
    let cell = |q: f32| 0.7 - q;
    // Beyond 0.8 nothing can be rolled out (the second query is).
    let feasible = |q: f32| q <= 0.8;
    let mut infeasible = 0;
    let mut n = 0;
    loop {
        let reply = s.respond(&Request::Ask);
        let Some(q) = direct.ask() else {
            assert_eq!(reply, Reply::Finished(direct.status()));
            break;
        };
        let Reply::Rollout(r) = reply else {
            panic!("{reply:?}")
        };
        assert_eq!((r.number, r.query[0].to_bits()), (n, q.to_bits()));
        // Asking again before telling is the same roll-out.
        assert_eq!(s.respond(&Request::Ask), Reply::Rollout(r.clone()));
        if feasible(q) {
            let outcome = Outcome {
                error: q1(cell(q)),
                reward: 0.0,
            };
            assert_eq!(s.respond(&Request::Tell(outcome)), Reply::Ok);
            direct.tell(cell(q)).unwrap();
        } else {
            assert_eq!(s.respond(&Request::Infeasible), Reply::Ok);
            direct.tell_infeasible().unwrap();
            infeasible += 1;
        }
        n += 1;
    }
    assert!(infeasible > 0);
    assert_eq!(direct.status(), SearchStatus::Converged);
    let Reply::Status(st) = s.respond(&Request::Status) else {
        panic!()
    };
    assert_eq!(st.search, SearchStatus::Converged);
    assert_eq!(st.rollouts, n);
    assert_eq!(st.best_query, direct.best().map(|b| q1(b.query)));
}

#[test]
fn power_through_the_service_gives_the_same_bits() {
    let mut s = Service::new();
    configure(
        &mut s,
        LearnerSetup::Power {
            config: power_config(1),
            query: q1(0.6),
        },
    );
    let mut start = vec![0.0f32; 16];
    start[0] = 0.6;
    let mut direct = Power::<16, 3>::new(&start, power_config(1), 11).unwrap();
    for i in 0..40u32 {
        let mean = direct.next_is_mean();
        let theta = direct.ask().to_vec();
        let Reply::Rollout(r) = s.respond(&Request::Ask) else {
            panic!()
        };
        assert_eq!((r.number, r.mean, r.delta_len), (i, mean, 15));
        let mut got = r.query.to_vec();
        got.extend(fetch(&mut s, 15));
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&got), bits(&theta), "roll-out {i}");
        let reward = 1.0 / (1.0 + theta.iter().map(|x| x * x).sum::<f32>());
        let out = Outcome {
            error: q1(0.0),
            reward,
        };
        assert_eq!(s.respond(&Request::Tell(out)), Reply::Ok);
        direct.tell(reward).unwrap();
    }
    let Reply::Status(st) = s.respond(&Request::Status) else {
        panic!()
    };
    assert_eq!((st.rollouts, st.updates), (40, direct.updates()));
    assert_eq!(st.best, direct.best().map(|b| b.reward));
}

#[test]
fn streamed_setpoints_are_the_generalized_dmp_integrated() {
    let mut s = Service::new();
    configure(&mut s, LearnerSetup::Golden(search()));
    let Reply::Rollout(r) = s.respond(&Request::Ask) else {
        panic!()
    };
    let (template, ex) = examples();
    let mut g = Generalizer::<2, 1, 15>::new(1, 15, LWR);
    for (q, theta) in &ex {
        g.add_example(&[*q], theta).unwrap();
    }
    g.build().unwrap();
    let mut theta = [0.0f32; 15];
    g.generalize(&r.query, &mut theta).unwrap();
    let start = [0.05f32, -0.1];
    let dmp = Dmp::<2, 6>::from_shape(&template.shape(), 2, 6, &start, &theta).unwrap();
    let mut run = dmp.start(&dmp.execution()).unwrap();
    let dt = 0.002;
    let req = Request::DmpStart(DmpStart {
        shape: template.shape(),
        kernels: 6,
        start: HVec::from_slice(&start).unwrap(),
        dt,
    });
    assert_eq!(s.respond(&req), Reply::Ok);
    let mut steps = 0;
    loop {
        run.step(&dmp, dt).unwrap();
        let Reply::Setpoint {
            time,
            position,
            done,
        } = s.respond(&Request::DmpNext)
        else {
            panic!()
        };
        assert_eq!(time.to_bits(), run.time().to_bits());
        assert_eq!(position.as_slice(), run.position());
        steps += 1;
        if done {
            break;
        }
    }
    assert_eq!(steps, (dmp.tau() / dt).round() as usize);
    assert!(matches!(
        s.respond(&Request::DmpNext),
        Reply::Error(f) if f.kind == FaultKind::BadState
    ));
}

/// Sends `req` as frame `seq` through [`Service::handle`].
fn exchange(s: &mut Service, seq: u32, req: &Request) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME];
    let frame = wire::encode(seq, req, &mut buf).unwrap().to_vec();
    let mut reader = FrameReader::new();
    let mut out = [0u8; MAX_FRAME];
    let mut reply = Vec::new();
    for b in &frame {
        if let Some(raw) = reader.push(*b) {
            reply = s.handle(raw, &mut out).to_vec();
        }
    }
    reply
}

fn reply_of(bytes: &[u8]) -> wire::Frame<Reply> {
    wire::decode(&bytes[..bytes.len() - 1]).unwrap()
}

#[test]
fn a_retransmitted_request_gets_the_same_reply_and_changes_nothing() {
    let mut s = Service::new();
    configure(&mut s, LearnerSetup::Golden(search()));
    let ask = exchange(&mut s, 1, &Request::Ask);
    let tell = Request::Tell(Outcome {
        error: q1(0.3),
        reward: 0.0,
    });
    let told = exchange(&mut s, 2, &tell);
    // The host missed the reply and sends the tell again: same bytes, and
    // the search has still seen one roll-out.
    assert_eq!(exchange(&mut s, 2, &tell), told);
    let Reply::Status(st) = reply_of(&exchange(&mut s, 3, &Request::Status)).body else {
        panic!()
    };
    assert_eq!(st.rollouts, 1);
    // A new ask is a new roll-out, with a higher query (ε > 0).
    let (Reply::Rollout(a), Reply::Rollout(b)) = (
        reply_of(&ask).body,
        reply_of(&exchange(&mut s, 4, &Request::Ask)).body,
    ) else {
        panic!()
    };
    assert!(b.query[0] > a.query[0] && b.number == 1);
}

#[test]
fn corrupt_frames_get_a_bad_frame_reply_and_change_nothing() {
    let mut s = Service::new();
    configure(&mut s, LearnerSetup::Golden(search()));
    let mut buf = [0u8; MAX_FRAME];
    let mut frame = wire::encode(5, &Request::Ask, &mut buf).unwrap().to_vec();
    frame[1] ^= 0x40;
    let mut out = [0u8; MAX_FRAME];
    let mut reader = FrameReader::new();
    let mut replies = Vec::new();
    for b in &frame {
        if let Some(raw) = reader.push(*b) {
            replies.push(reply_of(s.handle(raw, &mut out)));
        }
    }
    assert_eq!(replies.len(), 1);
    assert_eq!(replies[0].seq, UNREAD);
    assert!(matches!(&replies[0].body, Reply::Error(f) if f.kind == FaultKind::BadFrame));
    // Nothing was asked: telling is a bad state.
    let tell = Request::Tell(Outcome {
        error: q1(0.1),
        reward: 0.0,
    });
    assert!(matches!(s.respond(&tell), Reply::Error(f) if f.kind == FaultKind::BadState));
}

#[test]
fn faults_say_what_is_wrong() {
    let mut s = Service::new();
    let fault = |r: Reply| match r {
        Reply::Error(f) => (f.kind, f.detail.to_string()),
        other => panic!("{other:?}"),
    };
    let (k, d) = fault(s.respond(&Request::Hello { version: 99 }));
    assert_eq!(k, FaultKind::Version);
    assert!(d.contains("99"), "{d}");
    assert!(matches!(
        s.respond(&Request::Hello {
            version: primo_protocol::VERSION
        }),
        Reply::Hello { .. }
    ));
    assert_eq!(fault(s.respond(&Request::Ask)).0, FaultKind::BadState);
    assert_eq!(
        fault(s.respond(&Request::Infeasible)).0,
        FaultKind::BadState
    );
    let too_long = Setup {
        learner: LearnerSetup::Golden(search()),
        examples: 2,
        theta_len: THETA as u16 + 1,
        regression: LWR,
        seed: 1,
        query_dim: 1,
    };
    let (k, d) = fault(s.respond(&Request::Configure(too_long)));
    assert_eq!(k, FaultKind::Capacity);
    assert!(d.contains(&(THETA + 1).to_string()), "{d}");
    let mut bad = search();
    bad.desired = 9.0;
    let (k, _) = fault(s.respond(&Request::Configure(Setup {
        learner: LearnerSetup::Illinois(bad),
        examples: 0,
        theta_len: 0,
        regression: LWR,
        seed: 1,
        query_dim: 1,
    })));
    assert_eq!(k, FaultKind::Invalid);
    // Examples out of order, and a NaN outcome.
    configure(&mut s, LearnerSetup::Golden(search()));
    let chunk = Request::Example {
        index: 0,
        query: q1(0.3),
        offset: 0,
        values: HVec::from_slice(&[0.0; CHUNK]).unwrap(),
    };
    assert_eq!(fault(s.respond(&chunk)).0, FaultKind::BadState);
    s.respond(&Request::Ask);
    let nan = Request::Tell(Outcome {
        error: q1(f32::NAN),
        reward: 0.0,
    });
    assert_eq!(fault(s.respond(&nan)).0, FaultKind::Invalid);
}

/// A setup with no examples over a `query_dim`-dimensional query.
fn bare(learner: LearnerSetup, query_dim: u8, theta_len: u16) -> Setup {
    Setup {
        learner,
        examples: 0,
        theta_len,
        regression: LWR,
        seed: 5,
        query_dim,
    }
}

fn secant_config(n: usize) -> SecantConfig<MAX_QUERY> {
    SecantConfig {
        low: HVec::from_slice(&[-1.0; MAX_QUERY][..n]).unwrap(),
        high: HVec::from_slice(&[2.0; MAX_QUERY][..n]).unwrap(),
        desired: HVec::from_slice(&[0.5; MAX_QUERY][..n]).unwrap(),
        precision: 1e-4,
        max_rollouts: 30,
        gain: 1.0,
        rule: Rule::Broyden,
    }
}

/// Starts the movement of the roll-out in flight: the examples' 2 DoFs,
/// from 0.
fn start_movement(s: &mut Service) {
    let start = DmpStart {
        shape: examples().0.shape(),
        kernels: 6,
        start: HVec::from_slice(&[0.0, 0.0]).unwrap(),
        dt: 0.01,
    };
    assert_eq!(s.respond(&Request::DmpStart(start)), Reply::Ok);
}

/// Tells the service and the secant learner used directly the same error.
fn tell_both(s: &mut Service, direct: &mut Secant<MAX_QUERY>, error: HVec<f32, MAX_QUERY>) {
    let outcome = Outcome {
        error: error.clone(),
        reward: 0.0,
    };
    assert_eq!(s.respond(&Request::Tell(outcome)), Reply::Ok);
    direct.tell(&error).unwrap();
}

/// The service's search converged after `n` roll-outs, at most 12, with
/// the best roll-out of the learner used directly.
fn assert_converged_as(s: &mut Service, direct: &Secant<MAX_QUERY>, n: u32) {
    assert_eq!(
        s.respond(&Request::Ask),
        Reply::Finished(SearchStatus::Converged)
    );
    let Reply::Status(st) = s.respond(&Request::Status) else {
        panic!()
    };
    assert_eq!((st.search, st.rollouts), (SearchStatus::Converged, n));
    let best = direct.best().unwrap();
    assert_eq!(st.best_query.as_deref(), Some(best.query));
    assert_eq!(st.best, Some(best.size));
    assert!(n <= 12, "{n} roll-outs");
}

#[test]
fn secant_through_the_service_is_the_learner_itself() {
    let mut s = Service::new();
    configure_dim(&mut s, LearnerSetup::Secant(secant_config(3)), 3);
    let mut direct = Secant::<MAX_QUERY>::new(secant_config(3)).unwrap();
    // measured = A q with A ≠ I; the target is A·(0.9, −0.2, 1.3).
    let cell = |q: &[f32]| {
        let m = [
            1.5 * q[0] + 0.2 * q[2],
            -0.3 * q[0] + 0.8 * q[1],
            0.1 * q[1] - 1.2 * q[2],
        ];
        let t = [1.61, -0.43, -1.58];
        HVec::<f32, MAX_QUERY>::from_iter((0..3).map(|i| t[i] - m[i]))
    };
    let mut n = 0;
    while let Some(q) = direct.ask() {
        let Reply::Rollout(r) = s.respond(&Request::Ask) else {
            panic!()
        };
        assert_eq!((r.number, r.query.as_slice(), r.delta_len), (n, q, 0));
        // The movement generalizes to the 3-D query.
        start_movement(&mut s);
        let error = cell(q);
        tell_both(&mut s, &mut direct, error);
        n += 1;
    }
    assert_converged_as(&mut s, &direct, n);
}

#[test]
fn power_over_a_two_dimensional_query_gives_the_same_bits() {
    let config = power_config(2);
    let mut s = Service::new();
    let query = HVec::from_slice(&[0.6, -0.4]).unwrap();
    let learner = LearnerSetup::Power {
        config: config.clone(),
        query,
    };
    configure_dim(&mut s, learner, 2);
    let mut start = vec![0.0f32; 17];
    start[..2].copy_from_slice(&[0.6, -0.4]);
    let mut direct = Power::<17, 3>::new(&start, config, 11).unwrap();
    for i in 0..12u32 {
        let theta = direct.ask().to_vec();
        let Reply::Rollout(r) = s.respond(&Request::Ask) else {
            panic!()
        };
        assert_eq!((r.number, r.delta_len), (i, 15));
        let mut got = r.query.to_vec();
        got.extend(fetch(&mut s, 15));
        assert_eq!(got, theta, "roll-out {i}");
        let reward = 1.0 / (1.0 + theta.iter().map(|x| x * x).sum::<f32>());
        let out = Outcome {
            error: HVec::new(),
            reward,
        };
        assert_eq!(s.respond(&Request::Tell(out)), Reply::Ok);
        direct.tell(reward).unwrap();
    }
    let Reply::Status(st) = s.respond(&Request::Status) else {
        panic!()
    };
    let best = direct.best().unwrap();
    assert_eq!(st.best_query.as_deref(), Some(&best.params[..2]));
}

#[test]
fn secant_on_the_goals_changes_only_the_goals_as_the_learner_itself() {
    let mut s = Service::new();
    let query = q1(0.6);
    // θ: 2 DoFs × 6 kernels, then the 2 goals (at 12), then τ.
    let learner = LearnerSetup::SecantGoals {
        config: secant_config(2),
        query: query.clone(),
        first_goal: 12,
    };
    configure(&mut s, learner);
    let mut direct = Secant::<MAX_QUERY>::new(secant_config(2)).unwrap();
    // The outcome moves with the goals through a map A ≠ I.
    let cell = |g: &[f32]| {
        let m = [0.8 * g[0] + 0.3 * g[1], -0.2 * g[0] + 1.4 * g[1]];
        HVec::<f32, MAX_QUERY>::from_iter([0.7 - m[0], 0.9 - m[1]])
    };
    let mut n = 0;
    while let Some(change) = direct.ask() {
        let Reply::Rollout(r) = s.respond(&Request::Ask) else {
            panic!()
        };
        assert_eq!((r.number, &r.query, r.delta_len), (n, &query, 15));
        let mut expected = vec![0.0f32; 15];
        expected[12..14].copy_from_slice(change);
        assert_eq!(fetch(&mut s, 15), expected, "roll-out {n}");
        // The movement G(q̂) + Δθ ends at the changed goals.
        start_movement(&mut s);
        let end = loop {
            match s.respond(&Request::DmpNext) {
                Reply::Setpoint {
                    position,
                    done: true,
                    ..
                } => break position,
                Reply::Setpoint { .. } => {}
                other => panic!("{other:?}"),
            }
        };
        let mut generalized = Generalizer::<8, MAX_QUERY, 15>::new(1, 15, LWR);
        for (q, theta) in examples().1 {
            generalized.add_example(&[q], &theta).unwrap();
        }
        generalized.build().unwrap();
        let mut theta = [0.0f32; 15];
        generalized.generalize(&query, &mut theta).unwrap();
        for (i, e) in end.iter().enumerate() {
            assert!(
                (e - (theta[12 + i] + change[i])).abs() < 0.05,
                "{end:?} {theta:?}"
            );
        }
        let error = cell(change);
        tell_both(&mut s, &mut direct, error);
        n += 1;
    }
    assert_converged_as(&mut s, &direct, n);
    // Goals beyond θ do not fit.
    let beyond = LearnerSetup::SecantGoals {
        config: secant_config(2),
        query,
        first_goal: 14,
    };
    let r = s.respond(&Request::Configure(bare(beyond, 1, 15)));
    assert!(
        matches!(r, Reply::Error(ref f) if f.kind == FaultKind::Capacity),
        "{r:?}"
    );
}

#[test]
fn query_dimensions_that_do_not_fit_are_invalid_and_change_nothing() {
    let mut s = Service::new();
    configure(&mut s, LearnerSetup::Golden(search()));
    s.respond(&Request::Ask);
    let status = s.respond(&Request::Status);
    let invalid = |r: Reply| matches!(r, Reply::Error(f) if f.kind == FaultKind::Invalid);
    let power = |query: &[f32], block: usize| LearnerSetup::Power {
        config: PowerConfig::paper(&[Block {
            len: block,
            variance: 0.01,
            decay: 1.0,
        }])
        .unwrap(),
        query: HVec::from_slice(query).unwrap(),
    };
    for bad in [
        bare(LearnerSetup::Secant(secant_config(1)), 0, 0),
        bare(LearnerSetup::Secant(secant_config(1)), 5, 0),
        bare(LearnerSetup::Secant(secant_config(2)), 3, 0),
        bare(LearnerSetup::Golden(search()), 2, 0),
        bare(LearnerSetup::Illinois(search()), 2, 0),
        bare(power(&[0.5], 4), 2, 2),
        // The blocks add up to θ + 1, not θ + query_dim.
        bare(power(&[0.5, 0.5], 3), 2, 2),
    ] {
        assert!(
            invalid(s.respond(&Request::Configure(bad.clone()))),
            "{bad:?}"
        );
        assert_eq!(s.respond(&Request::Status), status);
    }
    // Examples must have query_dim values; a wrong one changes nothing.
    let mut setup = bare(LearnerSetup::Secant(secant_config(2)), 2, 8);
    setup.examples = 1;
    assert_eq!(s.respond(&Request::Configure(setup)), Reply::Ok);
    let example = |query: &[f32]| Request::Example {
        index: 0,
        query: HVec::from_slice(query).unwrap(),
        offset: 0,
        values: HVec::from_slice(&[0.0; CHUNK]).unwrap(),
    };
    assert!(invalid(s.respond(&example(&[0.3]))));
    assert!(invalid(s.respond(&example(&[0.3, 0.1, 0.0]))));
    assert_eq!(s.respond(&example(&[0.3, 0.1])), Reply::Ok);
}
