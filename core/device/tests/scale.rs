//! The next stable reading ([`WeighMode::Next`]), as property tests: after
//! any history, it is made of the samples after the request alone, comes
//! as soon as they hold still, or is the fault `NotSettled` exactly at its
//! deadline; and through the device, its deferred frame answers the
//! request's sequence number once, retransmissions included.
use primo_device::answer as serve;
use primo_device::scale::{Scale, ScaleConfig};
use primo_learner::Coprocessor;
use primo_protocol::fault::FaultKind;
use primo_protocol::frame::{self as wire, MAX_FRAME};
use primo_protocol::learner::Reply as LearnerReply;
use primo_protocol::replay::Replay;
use primo_protocol::scale::{
    CalibrationPoint, FILTER, FRESH, Reply, Request, ScaleReply, ScaleRequest, Unit, WINDOW,
    WeighMode,
};
use proptest::collection::vec;
use proptest::prelude::*;

/// Counts at 0 g; 1000 counts a gram.
const ZERO: i32 = 10_000;

fn calibrated() -> Scale {
    let mut s = Scale::new(ScaleConfig::LAB);
    let settle = |s: &mut Scale, counts| (0..FILTER + WINDOW).for_each(|_| s.push(counts));
    settle(&mut s, ZERO);
    s.respond(&ScaleRequest::Calibrate(CalibrationPoint::Low {
        grams: 0.0,
    }));
    settle(&mut s, ZERO + 1_000_000);
    let high = ScaleRequest::Calibrate(CalibrationPoint::High { grams: 1000.0 });
    assert_eq!(s.respond(&high), Some(Reply::OK));
    s
}

fn next(within: u16) -> ScaleRequest {
    ScaleRequest::Weigh {
        mode: WeighMode::Next { within },
        unit: Unit::G,
    }
}

/// Pushes `counts(i)` for the i-th sample after a deferred request until
/// it is answered: the answer and the samples it took.
fn answer(s: &mut Scale, counts: impl Fn(u32) -> i32) -> (Reply, u32) {
    for i in 1..=u32::from(u16::MAX) {
        s.push(counts(i));
        if let Some(answer) = s.deferred() {
            return (answer, i);
        }
    }
    panic!("no answer")
}

proptest! {
    /// Whatever came before (loads, noise, an unsettled pan), a load that
    /// holds within ±1 count from the request on is answered at exactly
    /// [`FRESH`] samples, with its own value.
    #[test]
    fn a_still_load_is_answered_at_fresh_with_its_value(
        before in vec(-50_000i32..3_000_000, 0..300),
        grams in 0i32..4000,
        noise in vec(-1i32..=1, 16),
        within in FRESH..2000,
    ) {
        let mut s = calibrated();
        before.iter().for_each(|c| s.push(*c));
        prop_assert_eq!(s.respond(&next(within)), None);
        let load = ZERO + 1000 * grams;
        let (reply, took) = answer(&mut s, |i| load + noise[i as usize % noise.len()]);
        prop_assert_eq!(took, u32::from(FRESH));
        let Reply::Scale(ScaleReply::Reading(r)) = reply else {
            return Err(TestCaseError::fail(format!("{reply:?}")));
        };
        prop_assert!(r.stable);
        prop_assert!((r.digits - 100 * grams).abs() <= 1, "{r:?}");
    }

    /// A load that keeps moving by more than a digit a sample is not
    /// settled: the fault comes at the deadline, not a sample sooner.
    #[test]
    fn a_moving_load_faults_at_the_deadline(
        start in 0i32..1000,
        step in 20i32..200,
        within in FRESH..600,
    ) {
        let mut s = calibrated();
        prop_assert_eq!(s.respond(&next(within)), None);
        let (reply, took) = answer(&mut s, |i| ZERO + 1000 * start + step * i as i32);
        prop_assert_eq!(took, u32::from(within));
        prop_assert!(matches!(reply, Reply::Learner(LearnerReply::Error(f)) if f.kind == FaultKind::NotSettled));
    }
}

/// The scale device's answering of frames: the learner service and the
/// scale behind one replay.
struct Device {
    service: Box<Coprocessor>,
    replay: Replay,
}

impl Device {
    /// The deferred reply frame, once `scale` gives it.
    fn deferred<'a>(
        &mut self,
        scale: &mut Scale,
        out: &'a mut [u8; MAX_FRAME],
    ) -> Option<&'a [u8]> {
        let reply = scale.deferred()?;
        let len = self.replay.deferred(&reply, out)?;
        out.get(..len)
    }
}

/// Sends `request` as frame `seq` through the device; the reply frame.
fn send(device: &mut Device, scale: &mut Scale, seq: u32, request: ScaleRequest) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME];
    let frame = wire::encode(seq, &Request::Scale(request), &mut buf).unwrap();
    let raw = &frame[..frame.len() - 1];
    let mut out = [0u8; MAX_FRAME];
    let len = serve(
        &mut device.service,
        scale,
        &mut device.replay,
        Ok(raw),
        &mut out,
    );
    out[..len].to_vec()
}

#[test]
fn the_deferred_frame_answers_its_request_once() {
    let mut service = Device {
        service: Box::new(Coprocessor::new()),
        replay: Replay::new(),
    };
    let mut s = calibrated();
    let mut out = [0u8; MAX_FRAME];
    assert!(send(&mut service, &mut s, 7, next(FRESH)).is_empty());
    let mut frame = None;
    for i in 1..=FRESH {
        s.push(ZERO + 123_000);
        // A retransmission while it waits: nothing, and the wait goes on.
        if i == 50 {
            assert!(send(&mut service, &mut s, 7, next(FRESH)).is_empty());
        }
        if let Some(f) = service.deferred(&mut s, &mut out) {
            assert_eq!(i, FRESH);
            frame = Some(f.to_vec());
        }
    }
    let frame = frame.expect("answered");
    let reply = wire::decode::<Reply>(&frame[..frame.len() - 1]).unwrap();
    assert_eq!(reply.seq, 7);
    let Reply::Scale(ScaleReply::Reading(r)) = reply.body else {
        panic!("{:?}", reply.body)
    };
    assert_eq!((r.digits, r.stable), (12_300, true));
    // After the answer, a retransmission gets the same bytes again.
    assert_eq!(send(&mut service, &mut s, 7, next(FRESH)), frame);
    // A later request supersedes a waiting one: its answer is dropped.
    assert!(send(&mut service, &mut s, 8, next(FRESH)).is_empty());
    assert!(!send(&mut service, &mut s, 9, ScaleRequest::Identify).is_empty());
    for _ in 0..2 * FRESH {
        s.push(ZERO);
        assert_eq!(service.deferred(&mut s, &mut out), None);
    }
}
