//! The scale firmware's state machine fed an arbitrary session: ADC
//! samples (held for a while, so loads settle), raw bytes on the ADC line,
//! and scale requests (postcard from the input) as frames through the
//! scale device's answering (the learner service and the scale behind one
//! replay), some corrupted. No panic; a sample survives the ADC line's
//! codec; every reply is a frame that decodes, numbered as the request (a
//! corrupted one as UNREAD), a weighing of the next stable reading's once
//! its samples came (none when the next request came first); a stable
//! weighing is stable and finite, or a weighing's typed fault; a weighing is uncalibrated exactly when the
//! scale says so; settings change only on an `Ok` to zero, tare or a
//! calibration, and survive the settings page's frame bit for bit.
#![no_main]

use libfuzzer_sys::fuzz_target;
use primo_device::scale::{SampleReader, Scale, ScaleConfig, Settings, encode_sample};
use primo_learner::{Coprocessor, UNREAD};
use primo_protocol::fault::FaultKind;
use primo_protocol::frame::{self as wire, MAX_FRAME};
use primo_protocol::learner::Reply as LearnerReply;
use primo_protocol::replay::Replay;
use primo_protocol::scale::{Reply, Request, ScaleReply, ScaleRequest, WeighMode};

/// The scale device's answering of frames: the learner service and the
/// scale behind one replay.
struct Device {
    service: Box<Coprocessor>,
    replay: Replay,
}

/// Operations per session.
const MAX_OPS: usize = 300;

/// Sends `request` as frame `seq` (one byte changed when `corrupt`);
/// returns the reply, `None` for a corrupted request or a deferred one.
fn send(
    service: &mut Device,
    scale: &mut Scale,
    seq: u32,
    request: &ScaleRequest,
    corrupt: Option<u8>,
) -> Option<Reply> {
    let mut buf = [0u8; MAX_FRAME];
    let frame = wire::encode(seq, &Request::Scale(request.clone()), &mut buf).ok()?;
    let mut raw = frame[..frame.len() - 1].to_vec();
    if let Some(at) = corrupt {
        let at = usize::from(at) % raw.len();
        raw[at] ^= 0x5a;
    }
    let mut out = [0u8; MAX_FRAME];
    let len = primo_device::answer(
        &mut service.service,
        scale,
        &mut service.replay,
        Ok(&raw),
        &mut out,
    );
    let reply = &out[..len];
    let Some((end, body)) = reply.split_last() else {
        assert!(
            corrupt.is_none()
                && matches!(
                    request,
                    ScaleRequest::Weigh {
                        mode: WeighMode::Next { .. },
                        ..
                    }
                )
        );
        return None;
    };
    assert_eq!(*end, 0);
    let reply = wire::decode::<Reply>(body).expect("the reply decodes");
    let expected = if corrupt.is_some() { UNREAD } else { seq };
    assert_eq!(reply.seq, expected);
    if corrupt.is_some() {
        assert!(
            matches!(&reply.body, Reply::Learner(LearnerReply::Error(f)) if f.kind == FaultKind::BadFrame)
        );
        return None;
    }
    Some(reply.body)
}

/// Pushes `counts` and checks the deferred answer it may complete.
fn push(
    service: &mut Device,
    scale: &mut Scale,
    counts: i32,
    pending: &mut Option<(u32, ScaleRequest, bool)>,
) {
    scale.push(counts);
    let mut out = [0u8; MAX_FRAME];
    let Some(len) = scale
        .deferred()
        .and_then(|reply| service.replay.deferred(&reply, &mut out))
    else {
        return;
    };
    let frame = &out[..len];
    let (seq, request, calibrated) = pending
        .take()
        .expect("a deferred answer to a waiting request");
    let reply = wire::decode::<Reply>(&frame[..frame.len() - 1]).expect("the reply decodes");
    assert_eq!(reply.seq, seq);
    check(&request, &reply.body, calibrated);
}

fuzz_target!(|data: &[u8]| {
    let mut service = Device {
        service: Box::new(Coprocessor::new()),
        replay: Replay::new(),
    };
    let mut pending = None;
    let mut scale = Scale::new(ScaleConfig::LAB);
    let mut adc = SampleReader::new();
    let mut seq = 1u32;
    let mut rest = data;
    for _ in 0..MAX_OPS {
        let Some((&control, after)) = rest.split_first() else {
            break;
        };
        rest = after;
        match control % 4 {
            // A sample held for 1..=64 periods, through the line's codec.
            0 => {
                let Some((bytes, after)) = rest.split_first_chunk::<3>() else {
                    break;
                };
                rest = after;
                let counts = i32::from_le_bytes([bytes[0], bytes[1], bytes[2], 0]) << 8 >> 8;
                let mut line = SampleReader::new();
                let got: Vec<i32> = encode_sample(counts)
                    .iter()
                    .filter_map(|b| line.push(*b))
                    .collect();
                assert_eq!(got, [counts]);
                for _ in 0..=(control >> 2) {
                    push(&mut service, &mut scale, counts, &mut pending);
                }
            }
            // Raw bytes on the ADC line.
            1 => {
                let n = usize::from(control >> 2).min(rest.len());
                let (bytes, after) = rest.split_at(n);
                rest = after;
                for b in bytes {
                    if let Some(counts) = adc.push(*b) {
                        assert!((-8_388_608..=8_388_607).contains(&counts));
                        push(&mut service, &mut scale, counts, &mut pending);
                    }
                }
            }
            // A request, intact or with a byte changed.
            op => {
                let Ok((request, after)) = postcard::take_from_bytes::<ScaleRequest>(rest) else {
                    break;
                };
                rest = after;
                seq += 1;
                let corrupt = (op == 3).then_some(control >> 2);
                let calibrated = scale.identity().calibrated;
                if corrupt.is_none() {
                    // A new request: the waiting one, if any, goes unanswered.
                    pending = None;
                }
                let Some(reply) = send(&mut service, &mut scale, seq, &request, corrupt) else {
                    assert!(scale.take_changed().is_none());
                    if corrupt.is_none() {
                        pending = Some((seq, request, calibrated));
                    }
                    continue;
                };
                check(&request, &reply, calibrated);
                let changed = scale.take_changed().copied();
                let setting = matches!(
                    request,
                    ScaleRequest::Zero | ScaleRequest::Tare | ScaleRequest::Calibrate(_)
                );
                assert_eq!(
                    changed.is_some(),
                    setting && reply == Reply::OK,
                    "{request:?}"
                );
                if let Some(settings) = changed {
                    page_round_trip(&settings);
                }
            }
        }
    }
});

/// What a reply to `request` must be.
fn check(request: &ScaleRequest, reply: &Reply, calibrated: bool) {
    match (request, reply) {
        (ScaleRequest::Weigh { mode, .. }, Reply::Scale(ScaleReply::Reading(r))) => {
            assert!(calibrated);
            assert!(r.stable || *mode == WeighMode::Now, "{r:?}");
            assert!(r.grams().is_finite());
        }
        (ScaleRequest::Weigh { .. }, Reply::Learner(LearnerReply::Error(f))) => {
            assert_eq!(f.kind == FaultKind::Uncalibrated, !calibrated, "{f:?}");
            assert!(matches!(
                f.kind,
                FaultKind::Uncalibrated
                    | FaultKind::Invalid
                    | FaultKind::NotSettled
                    | FaultKind::Overload
                    | FaultKind::Underload
            ));
        }
        (ScaleRequest::Identify, Reply::Scale(ScaleReply::Identity(i))) => {
            assert_eq!(i.calibrated, calibrated);
        }
        (
            ScaleRequest::Stream { .. }
            | ScaleRequest::Zero
            | ScaleRequest::Tare
            | ScaleRequest::Calibrate(_),
            Reply::Learner(LearnerReply::Ok | LearnerReply::Error(_)),
        ) => {}
        _ => panic!("{request:?} answered {reply:?}"),
    }
}

/// The settings page's frame gives the settings back, bit for bit.
fn page_round_trip(settings: &Settings) {
    let mut buf = [0u8; MAX_FRAME];
    let frame = wire::encode(0, settings, &mut buf).expect("settings fit a frame");
    let back = wire::decode::<Settings>(&frame[..frame.len() - 1]).expect("the page decodes");
    assert_eq!(format!("{:?}", back.body), format!("{settings:?}"));
}
