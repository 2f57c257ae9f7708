//! Wire round-trips (property tests): any request or reply, with any
//! values (NaN, ±∞, −0.0 included), encodes to one frame that the reader
//! cuts out whole and the decoder gives back bit for bit.
use heapless::Vec as HVec;
use primo_core::dmp::Shape;
use primo_core::generalize::Method;
use primo_core::golden::{SearchConfig, Status as SearchStatus};
use primo_core::power::{Block, MAX_BLOCKS, PowerConfig};
use primo_core::secant::{Rule, SecantConfig};
use primo_protocol::fault::{DETAIL, Fault, FaultKind};
use primo_protocol::frame::{self as wire, Frame, FrameError, FrameReader, MAX_FRAME};
use primo_protocol::learner::{
    CHUNK, Capacities, DmpStart, LearnerSetup, MAX_DOF, MAX_QUERY, Outcome, Reply, Request,
    Rollout, Setup, Status,
};
use proptest::collection::vec;
use proptest::prelude::*;
use serde::Serialize;
use serde::de::DeserializeOwned;

/// Any `f32` bit pattern, with the special values made likely.
fn float() -> impl Strategy<Value = f32> {
    prop_oneof![
        any::<u32>().prop_map(f32::from_bits),
        prop::sample::select(vec![0.0, -0.0, f32::NAN, f32::INFINITY, f32::MIN, 1e-45]),
        -1e3f32..1e3,
    ]
}

fn floats<const N: usize>() -> impl Strategy<Value = HVec<f32, N>> {
    vec(float(), 0..=N).prop_map(|v| HVec::from_slice(&v).unwrap())
}

fn search_config() -> impl Strategy<Value = SearchConfig> {
    (float(), float(), float(), float(), any::<u32>()).prop_map(
        |(low, high, desired, precision, max_rollouts)| SearchConfig {
            low,
            high,
            desired,
            precision,
            max_rollouts,
        },
    )
}

fn secant_config() -> impl Strategy<Value = SecantConfig<MAX_QUERY>> {
    (
        floats::<MAX_QUERY>(),
        floats::<MAX_QUERY>(),
        floats::<MAX_QUERY>(),
        float(),
        any::<u32>(),
        float(),
        prop::sample::select(vec![Rule::Broyden, Rule::Fixed, Rule::Weighted]),
    )
        .prop_map(
            |(low, high, desired, precision, max_rollouts, gain, rule)| SecantConfig {
                low,
                high,
                desired,
                precision,
                max_rollouts,
                gain,
                rule,
            },
        )
}

fn power_config() -> impl Strategy<Value = PowerConfig> {
    // Mostly lengths of one or two varint bytes: ten blocks of the
    // largest do not fit a frame.
    let len = prop_oneof![4 => 0usize..300, 1 => any::<usize>()];
    let block = (len, float(), float()).prop_map(|(len, variance, decay)| Block {
        len,
        variance,
        decay,
    });
    (
        vec(block, 0..=MAX_BLOCKS),
        any::<u16>(),
        any::<bool>(),
        any::<usize>(),
        float(),
    )
        .prop_map(
            |(blocks, rollouts_per_update, roll_out_mean, sampler, query_gain)| PowerConfig {
                blocks: HVec::from_slice(&blocks).unwrap(),
                rollouts_per_update,
                roll_out_mean,
                sampler,
                query_gain,
            },
        )
}

fn setup() -> impl Strategy<Value = Setup> {
    let learner = prop_oneof![
        search_config().prop_map(LearnerSetup::Golden),
        search_config().prop_map(LearnerSetup::Illinois),
        secant_config().prop_map(LearnerSetup::Secant),
        (power_config(), floats::<MAX_QUERY>())
            .prop_map(|(config, query)| LearnerSetup::Power { config, query }),
        (secant_config(), floats::<MAX_QUERY>(), any::<u16>()).prop_map(
            |(config, query, first_goal)| LearnerSetup::SecantGoals {
                config,
                query,
                first_goal
            }
        ),
    ];
    let regression = prop_oneof![
        prop::option::of(float()).prop_map(|bandwidth| Method::Lwr { bandwidth }),
        (prop::option::of(float()), float()).prop_map(|(length_scale, noise)| Method::Gpr {
            length_scale,
            noise
        }),
        float().prop_map(|ridge| Method::ProMp { ridge }),
    ];
    (
        learner,
        any::<u8>(),
        any::<u16>(),
        regression,
        any::<u64>(),
        any::<u8>(),
    )
        .prop_map(
            |(learner, examples, theta_len, regression, seed, query_dim)| Setup {
                learner,
                examples,
                theta_len,
                regression,
                seed,
                query_dim,
            },
        )
}

fn request() -> impl Strategy<Value = Request> {
    let shape =
        (float(), float(), float(), any::<u32>()).prop_map(|(alpha, width, margin, scaled)| {
            Shape {
                alpha,
                width,
                margin,
                scaled,
            }
        });
    prop_oneof![
        any::<u16>().prop_map(|version| Request::Hello { version }),
        setup().prop_map(Request::Configure),
        (
            any::<u8>(),
            floats::<MAX_QUERY>(),
            any::<u16>(),
            floats::<CHUNK>()
        )
            .prop_map(|(index, query, offset, values)| Request::Example {
                index,
                query,
                offset,
                values
            }),
        Just(Request::Ask),
        any::<u16>().prop_map(|offset| Request::Fetch { offset }),
        (floats::<MAX_QUERY>(), float())
            .prop_map(|(error, reward)| Request::Tell(Outcome { error, reward })),
        Just(Request::Status),
        (shape, any::<u8>(), floats::<MAX_DOF>(), float()).prop_map(
            |(shape, kernels, start, dt)| Request::DmpStart(DmpStart {
                shape,
                kernels,
                start,
                dt
            })
        ),
        Just(Request::DmpNext),
        Just(Request::Infeasible),
    ]
}

fn search_status() -> impl Strategy<Value = SearchStatus> {
    prop::sample::select(vec![
        SearchStatus::Running,
        SearchStatus::Converged,
        SearchStatus::BudgetExhausted,
        SearchStatus::BracketCollapsed,
        SearchStatus::Stalled,
        SearchStatus::Infeasible,
    ])
}

fn reply() -> impl Strategy<Value = Reply> {
    let capacities =
        any::<(u16, u8, u8, u8, u8)>().prop_map(|(theta, examples, dof, kernels, sampler)| {
            Capacities {
                theta,
                examples,
                dof,
                kernels,
                sampler,
            }
        });
    let rollout = (
        any::<u32>(),
        floats::<MAX_QUERY>(),
        any::<u16>(),
        any::<bool>(),
        any::<u32>(),
    )
        .prop_map(|(number, query, delta_len, mean, update)| Rollout {
            number,
            query,
            delta_len,
            mean,
            update,
        });
    let status = (
        any::<u32>(),
        any::<u32>(),
        search_status(),
        prop::option::of(floats::<MAX_QUERY>()),
        prop::option::of(float()),
    )
        .prop_map(|(rollouts, updates, search, best_query, best)| Status {
            rollouts,
            updates,
            search,
            best_query,
            best,
        });
    let kind = prop::sample::select(vec![
        FaultKind::Version,
        FaultKind::Capacity,
        FaultKind::BadState,
        FaultKind::BadFrame,
        FaultKind::Invalid,
    ]);
    // Any text, cut on a character boundary as Fault::new does.
    let fault = (kind, ".{0,80}").prop_map(|(kind, text)| Fault::new(kind, text));
    prop_oneof![
        (any::<u16>(), capacities).prop_map(|(version, capacities)| Reply::Hello {
            version,
            capacities
        }),
        Just(Reply::Ok),
        rollout.prop_map(Reply::Rollout),
        search_status().prop_map(Reply::Finished),
        (any::<u16>(), floats::<CHUNK>())
            .prop_map(|(offset, values)| Reply::Chunk { offset, values }),
        status.prop_map(Reply::Status),
        (float(), floats::<MAX_DOF>(), any::<bool>()).prop_map(|(time, position, done)| {
            Reply::Setpoint {
                time,
                position,
                done,
            }
        }),
        fault.prop_map(Reply::Error),
    ]
}

/// Encodes, cuts with the reader, decodes: the same sequence number and
/// the same bits (Debug tells −0.0 from 0.0; the re-encoding, NaN payloads).
fn round_trip<T: Serialize + DeserializeOwned + std::fmt::Debug>(
    seq: u32,
    body: &T,
) -> Result<(), TestCaseError> {
    let mut buf = [0u8; MAX_FRAME];
    let frame = match wire::encode(seq, body, &mut buf) {
        Ok(frame) => frame.to_vec(),
        Err(e) => {
            // Only a message too long for a frame: postcard ‖ CRC-32, one
            // COBS overhead byte (frames are under 254 bytes), 0x00.
            prop_assert_eq!(e, FrameError::Overflow);
            let mut plain = [0u8; 4 * MAX_FRAME];
            let n = postcard::to_slice(&Frame { seq, body }, &mut plain)
                .unwrap()
                .len();
            prop_assert!(n + 6 > MAX_FRAME, "{} bytes did not fit", n);
            return Ok(());
        }
    };
    let mut reader = FrameReader::new();
    let mut got = Vec::new();
    for b in &frame {
        if let Some(raw) = reader.push(*b) {
            got.push(raw.and_then(wire::decode::<T>));
        }
    }
    prop_assert_eq!(got.len(), 1, "one frame, cut at its only 0x00");
    let back = got.pop().unwrap().expect("decodes");
    prop_assert_eq!(back.seq, seq);
    prop_assert_eq!(format!("{:?}", back.body), format!("{body:?}"));
    let mut again = [0u8; MAX_FRAME];
    prop_assert_eq!(
        wire::encode(seq, &back.body, &mut again).unwrap(),
        &frame[..]
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 2000,
        failure_persistence: Some(Box::new(proptest::test_runner::FileFailurePersistence::WithSource("regressions"))),
        ..ProptestConfig::default()
    })]

    #[test]
    fn requests_round_trip(seq in any::<u32>(), body in request()) {
        round_trip(seq, &body)?;
    }

    #[test]
    fn replies_round_trip(seq in any::<u32>(), body in reply()) {
        round_trip(seq, &body)?;
    }

    #[test]
    fn fault_details_are_a_prefix_that_fits(text in ".{0,200}") {
        let f = Fault::new(FaultKind::Invalid, &text);
        prop_assert!(f.detail.len() <= DETAIL && text.starts_with(f.detail.as_str()));
    }
}
