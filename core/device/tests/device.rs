//! The scale device's loop over fake adapters: a host's frames in and
//! replies out, a load cell's counts, a settings store; a calibration and
//! a tare kept over a "reboot", a saturated ADC weighed as an overload.

use std::collections::VecDeque;

use primo_device::scale::{Scale, ScaleConfig, Settings};
use primo_device::{LoadCell, Port, ScaleDevice, SettingsStore};
use primo_learner::Coprocessor as Service;
use primo_protocol::fault::FaultKind;
use primo_protocol::frame::{self as wire, FrameReader, MAX_FRAME};
use primo_protocol::learner::Reply as LearnerReply;
use primo_protocol::scale::{
    CalibrationPoint, FILTER, Reply, Request, ScaleReply, ScaleRequest, Unit, WINDOW, WeighMode,
};

#[derive(Default)]
struct Host {
    input: VecDeque<u8>,
    output: Vec<u8>,
}

impl Port for Host {
    fn try_read_byte(&mut self) -> Option<u8> {
        self.input.pop_front()
    }

    fn write_all(&mut self, bytes: &[u8]) {
        self.output.extend_from_slice(bytes);
    }
}

impl Host {
    fn send(&mut self, seq: u32, request: ScaleRequest) {
        let mut buf = [0u8; MAX_FRAME];
        let frame = wire::encode(seq, &Request::Scale(request), &mut buf).unwrap();
        self.input.extend(frame);
    }

    /// The replies sent so far, decoded (streamed readings and all).
    fn replies(&mut self) -> Vec<(u32, Reply)> {
        let out = std::mem::take(&mut self.output);
        out.split(|&b| b == 0)
            .filter(|f| !f.is_empty())
            .map(|f| {
                let frame = wire::decode::<Reply>(f).unwrap();
                (frame.seq, frame.body)
            })
            .collect()
    }
}

/// Samples, or a saturated ADC's errors.
struct Cell(VecDeque<Result<i32, primo_loadcell::Error>>);

impl LoadCell for Cell {
    type Error = primo_loadcell::Error;

    fn sample(&mut self) -> Result<Option<i32>, Self::Error> {
        self.0.pop_front().transpose()
    }
}

impl Cell {
    fn settle(counts: i32) -> Self {
        Cell((0..FILTER + WINDOW).map(|_| Ok(counts)).collect())
    }
}

#[derive(Default)]
struct Store {
    kept: Option<Settings>,
    stores: usize,
}

impl SettingsStore for Store {
    type Error = ();

    fn load(&mut self) -> Option<Settings> {
        self.kept
    }

    fn store(&mut self, settings: &Settings) -> Result<(), ()> {
        self.kept = Some(*settings);
        self.stores += 1;
        Ok(())
    }
}

struct Parts {
    service: Box<Service>,
    scale: Box<Scale>,
    reader: Box<FrameReader>,
}

impl Parts {
    fn new() -> Self {
        Parts {
            service: Box::new(Service::new()),
            scale: Box::new(Scale::new(ScaleConfig::LAB)),
            reader: Box::new(FrameReader::new()),
        }
    }

    fn device(&mut self) -> ScaleDevice<'_> {
        ScaleDevice::new(&mut self.service, &mut self.scale, &mut self.reader)
    }
}

/// Samples of `counts` until stable, then `request`: its reply.
fn ask(
    d: &mut ScaleDevice,
    host: &mut Host,
    store: &mut Store,
    counts: i32,
    seq: u32,
    request: ScaleRequest,
) -> Reply {
    let pass = d.poll(host, &mut Cell::settle(counts), store);
    assert!(!pass.idle);
    host.replies();
    host.send(seq, request);
    let pass = d.poll(host, &mut Cell(VecDeque::new()), store);
    assert!(pass.stored.is_none_or(|r| r.is_ok()));
    let mut replies = host.replies();
    assert_eq!(replies.len(), 1, "{replies:?}");
    let (got, reply) = replies.remove(0);
    assert_eq!(got, seq);
    reply
}

fn weigh() -> ScaleRequest {
    ScaleRequest::Weigh {
        mode: WeighMode::Stable,
        unit: Unit::G,
    }
}

fn grams(reply: &Reply) -> Option<i32> {
    match reply {
        Reply::Scale(ScaleReply::Reading(r)) => Some(r.digits),
        _ => None,
    }
}

#[test]
fn a_calibration_and_tare_survive_a_reboot_through_the_store() {
    let (mut host, mut store) = (Host::default(), Store::default());
    let mut parts = Parts::new();
    let mut d = parts.device();
    assert!(!d.boot(&mut store), "nothing kept: factory settings");
    let idle = d.poll(&mut host, &mut Cell(VecDeque::new()), &mut store);
    assert!(idle.idle && idle.stored.is_none());
    let low = ScaleRequest::Calibrate(CalibrationPoint::Low { grams: 0.0 });
    let high = ScaleRequest::Calibrate(CalibrationPoint::High { grams: 1000.0 });
    assert_eq!(
        ask(&mut d, &mut host, &mut store, 10_000, 1, low),
        Reply::OK
    );
    assert_eq!(
        ask(&mut d, &mut host, &mut store, 1_010_000, 2, high),
        Reply::OK
    );
    assert_eq!(
        ask(
            &mut d,
            &mut host,
            &mut store,
            120_000,
            3,
            ScaleRequest::Tare
        ),
        Reply::OK
    );
    let r = ask(&mut d, &mut host, &mut store, 520_000, 4, weigh());
    assert_eq!(grams(&r), Some(40_000), "{r:?}");
    assert_eq!(store.stores, 3);

    // Reboot: new statics, the store's settings.
    let mut parts = Parts::new();
    let mut d = parts.device();
    assert!(d.boot(&mut store));
    let r = ask(&mut d, &mut host, &mut store, 520_000, 1, weigh());
    assert_eq!(grams(&r), Some(40_000), "{r:?}");
}

#[test]
fn a_saturated_adc_weighs_as_an_overload_not_the_last_reading() {
    let (mut host, mut store) = (Host::default(), Store::default());
    let mut parts = Parts::new();
    let mut d = parts.device();
    let low = ScaleRequest::Calibrate(CalibrationPoint::Low { grams: 0.0 });
    let high = ScaleRequest::Calibrate(CalibrationPoint::High { grams: 1000.0 });
    ask(&mut d, &mut host, &mut store, 10_000, 1, low);
    ask(&mut d, &mut host, &mut store, 1_010_000, 2, high);
    let saturated = primo_loadcell::Error::OutOfRange {
        counts: primo_loadcell::MAX,
    };
    let mut cell = Cell((0..FILTER + WINDOW).map(|_| Err(saturated)).collect());
    let _ = d.poll(&mut host, &mut cell, &mut store);
    host.replies();
    host.send(3, weigh());
    let _ = d.poll(&mut host, &mut Cell(VecDeque::new()), &mut store);
    match host.replies().as_slice() {
        [(3, Reply::Learner(LearnerReply::Error(fault)))] => {
            assert_eq!(fault.kind, FaultKind::Overload)
        }
        other => panic!("{other:?}"),
    }
    // A pin error drops the pass's samples, no more.
    let pin = primo_loadcell::Error::NotReady;
    let mut cell = Cell([Err(pin), Ok(5)].into_iter().collect());
    let _ = d.poll(&mut host, &mut cell, &mut store);
    assert_eq!(cell.0.len(), 1, "stopped at the error");
}
