//! Measures the firmware's costs on the target, under QEMU with
//! `-icount shift=0` (virtual time counts instructions; SysTick is
//! calibrated against a loop of known length): instructions per 7×30 DMP
//! step (plain, and with one obstacle's coupling term), per 3×30
//! orientation DMP step and per 219-parameter PoWER update,
//! the stack the service needs for a whole PoWER run, frames and all, as
//! the firmware runs it; and the scale's instructions per ADC reading and
//! per weighing request, and its stack.
#![no_std]
#![no_main]

use cortex_m::peripheral::{SYST, syst::SystClkSource};
use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use heapless::Vec;
use primo_core::coupling::{Coupling, Obstacles, Sphere};
use primo_core::dmp::{DEFAULT_ALPHA, DEFAULT_OVERLAP, Dmp, Shape};
use primo_core::generalize::Method;
use primo_core::orientation::OrientationDmp;
use primo_core::power::{Block, PowerConfig};
use primo_core::quaternion::Quaternion;
use primo_device::scale::{Calibration, Scale, ScaleConfig, Settings as ScaleSettings};
use primo_learner::{Coprocessor as Service, THETA};
use primo_protocol::frame::{self as wire, FrameReader, MAX_FRAME};
use primo_protocol::learner::{
    CHUNK, DmpStart, LearnerSetup, MAX_DOF, Outcome, Query, Reply, Request, Setup,
};
use primo_protocol::replay::Replay;
use primo_protocol::scale::{self, STREAM, ScaleRequest, Unit, WeighMode};

const UPDATES: u32 = 20;
const STEPS: u32 = 1000;
const KERNELS: usize = 30;

/// SysTick ticks elapsed while `f` runs (24-bit counter, counting down).
fn ticks(syst: &mut SYST, f: impl FnOnce()) -> u64 {
    syst.clear_current();
    let start = SYST::get_current();
    f();
    u64::from(start.wrapping_sub(SYST::get_current()) & 0x00FF_FFFF)
}

/// Instructions per tick as (instructions, ticks) of a loop of known length.
fn calibrate(syst: &mut SYST) -> (u64, u64) {
    const N: u32 = 100_000;
    let t = ticks(syst, || {
        // SAFETY: a register-only countdown loop, two instructions a turn.
        unsafe {
            core::arch::asm!("1:", "subs {0}, #1", "bne 1b", inout(reg) N => _);
        }
    });
    (2 * u64::from(N), t.max(1))
}

fn fail(what: &str) -> ! {
    hprintln!("footprint: {} failed", what);
    primo_firmware::exit(false)
}

/// One request through the firmware's path: encode, frame reader,
/// `Service::handle`, decode.
fn send(service: &mut Service, seq: &mut u32, request: &Request) -> Reply {
    *seq += 1;
    let (mut buf, mut out) = ([0u8; MAX_FRAME], [0u8; MAX_FRAME]);
    let Ok(frame) = wire::encode(*seq, request, &mut buf) else {
        fail("encode")
    };
    let mut reader = FrameReader::new();
    for b in frame {
        if let Some(raw) = reader.push(*b) {
            let reply = service.handle(raw, &mut out);
            match wire::decode::<Reply>(reply.split_last().map_or(&[], |(_, r)| r)) {
                Ok(wire::Frame {
                    body: Reply::Error(f),
                    ..
                }) => {
                    hprintln!("footprint: {}", f.detail.as_str());
                    fail("request")
                }
                Ok(f) => return f.body,
                Err(_) => fail("decode"),
            }
        }
    }
    fail("framing")
}

/// A 7 × 30 DMP of 2 s with smooth, made-up weights (the coprocessor
/// builds its DMPs from a shape and θ too; fitting is the host's job).
fn reach() -> Dmp<MAX_DOF, KERNELS> {
    let mut theta = [0.0f32; THETA];
    for (i, w) in theta.iter_mut().enumerate() {
        *w = 50.0 * libm::sinf(0.37 * i as f32);
    }
    let n = MAX_DOF * KERNELS;
    theta[n..n + MAX_DOF].copy_from_slice(&[0.3, -0.2, 0.5, 1.1, 0.0, 0.4, -0.6]);
    theta[THETA - 1] = 2.0;
    // The width `Dmp::fit` gives 30 kernels at the default overlap.
    let width = DEFAULT_OVERLAP * ((KERNELS - 1) * (KERNELS - 1)) as f32;
    let shape = Shape {
        alpha: DEFAULT_ALPHA,
        width,
        margin: 0.0,
        scaled: 0x7F,
    };
    Dmp::from_shape(&shape, MAX_DOF, KERNELS, &[0.0; MAX_DOF], &theta)
        .unwrap_or_else(|_| fail("dmp"))
}

/// An orientation DMP of 2 s, 30 kernels per axis, smooth made-up weights:
/// a turn of about 90° toward the identity.
fn turn() -> OrientationDmp<KERNELS> {
    let mut theta = [0.0f32; 3 * KERNELS + 4];
    for (i, w) in theta.iter_mut().enumerate().take(3 * KERNELS) {
        *w = 20.0 * libm::sinf(0.41 * i as f32);
    }
    theta[3 * KERNELS + 3] = 2.0;
    let shape = Shape {
        alpha: DEFAULT_ALPHA,
        width: DEFAULT_OVERLAP * ((KERNELS - 1) * (KERNELS - 1)) as f32,
        margin: 0.0,
        scaled: 0,
    };
    let start = [0.9, -0.6, 0.8];
    let log = Dmp::from_shape(&shape, 3, KERNELS, &start, &theta).unwrap_or_else(|_| fail("log"));
    OrientationDmp::from_parts(log, Quaternion::IDENTITY).unwrap_or_else(|_| fail("turn"))
}

/// Ticks of [`STEPS`] steps of [`reach`] and of [`turn`]. A function of
/// its own, so its runs are off the stack when the service's is measured.
#[inline(never)]
fn step_costs(syst: &mut SYST, dmp: &Dmp<MAX_DOF, KERNELS>) -> (u64, u64, u64) {
    let Ok(mut run) = dmp.start(&dmp.execution()) else {
        fail("start")
    };
    let mut ok = true;
    let dmp_ticks = ticks(syst, || {
        for _ in 0..STEPS {
            ok &= run.step(dmp, 0.001).is_ok();
        }
    });
    if !ok {
        fail("step");
    }
    let orientation = turn();
    let Ok(mut turning) = orientation.start(&orientation.execution()) else {
        fail("turn start")
    };
    let mut w: f32 = 0.0;
    let turn_ticks = ticks(syst, || {
        for _ in 0..STEPS {
            ok &= turning.step(&orientation, 0.001).is_ok();
            w += turning.orientation().w;
        }
    });
    if !ok || !w.is_finite() {
        fail("turn step");
    }
    // The same reach with a ball by its first three DoFs' path (as if they
    // were x, y, z): the term is computed every step.
    let exec = dmp.execution();
    let ball = Sphere {
        center: [0.15, -0.1, 0.3],
        radius: 0.05,
    };
    let Ok(obstacles) = Obstacles::<1>::new([0, 1, 2], &[ball], &exec.start, &exec.goal) else {
        fail("obstacles")
    };
    let Ok(mut coupled) = dmp.start(&exec) else {
        fail("coupled start")
    };
    let coupled_ticks = ticks(syst, || {
        for _ in 0..STEPS {
            ok &= coupled
                .step_with(dmp, 0.001, &[&obstacles as &dyn Coupling])
                .is_ok();
        }
    });
    if !ok {
        fail("coupled step");
    }
    (dmp_ticks, turn_ticks, coupled_ticks)
}

/// PoWER over `[q̂, Δθ]` of 219 parameters through the service: two
/// examples, every roll-out's `Δθ` fetched and its movement streamed.
/// Returns the ticks spent in the tells that completed an update.
fn power_run(service: &mut Service, syst: &mut SYST, dmp: &Dmp<MAX_DOF, KERNELS>) -> u64 {
    let mut seq = 0;
    let config = PowerConfig::paper(&[
        Block {
            len: 1,
            variance: 0.01,
            decay: 0.9,
        },
        Block {
            len: THETA,
            variance: 1e-4,
            decay: 1.0,
        },
    ])
    .unwrap_or_else(|_| fail("config"));
    let setup = Setup {
        learner: LearnerSetup::Power {
            config,
            query: Query::from_slice(&[0.5]).unwrap_or_default(),
        },
        examples: 2,
        theta_len: THETA as u16,
        regression: Method::Lwr { bandwidth: None },
        seed: 3,
        query_dim: 1,
    };
    send(service, &mut seq, &Request::Configure(setup));
    let mut theta = [0.0f32; THETA];
    if dmp.params(&mut theta).is_err() {
        fail("params");
    }
    for (i, q) in [0.3f32, 1.0].iter().enumerate() {
        for (c, chunk) in theta.chunks(CHUNK).enumerate() {
            let values = Vec::from_slice(chunk).unwrap_or_default();
            let offset = (c * CHUNK) as u16;
            send(
                service,
                &mut seq,
                &Request::Example {
                    index: i as u8,
                    query: Query::from_slice(&[*q]).unwrap_or_default(),
                    offset,
                    values,
                },
            );
        }
    }
    let start: Vec<f32, MAX_DOF> = dmp.start_position().iter().copied().collect();
    let mut update_ticks = 0;
    for i in 0..UPDATES * 4 {
        let Reply::Rollout(r) = send(service, &mut seq, &Request::Ask) else {
            fail("ask")
        };
        let mut offset = 0;
        while offset < r.delta_len {
            send(service, &mut seq, &Request::Fetch { offset });
            offset += CHUNK as u16;
        }
        let motion = DmpStart {
            shape: dmp.shape(),
            kernels: KERNELS as u8,
            start: start.clone(),
            dt: 0.01,
        };
        send(service, &mut seq, &Request::DmpStart(motion));
        while let Reply::Setpoint { done: false, .. } = send(service, &mut seq, &Request::DmpNext) {
        }
        let q = r.query.first().copied().unwrap_or(0.0);
        let tell = Request::Tell(Outcome {
            error: Query::new(),
            reward: 1.0 / (1.0 + q * q),
        });
        let t = ticks(syst, || {
            send(service, &mut seq, &tell);
        });
        // The fourth tell of an update runs the update.
        if i % 4 == 3 {
            update_ticks += t;
        }
    }
    update_ticks
}

/// The scale calibrated at 1000 counts per gram, streaming every
/// reading: instruments per reading (a sample filtered, displayed, checked
/// for stability and streamed as a frame) and per stable weighing through
/// the service, and the stack of both.
fn scale_costs(service: &mut Service, scale: &mut Scale, syst: &mut SYST) -> (u64, u64, usize) {
    scale.restore(ScaleSettings {
        calibration: Some(Calibration {
            counts_low: 10_000,
            grams_low: 0.0,
            gain: 1e-3,
        }),
        ..ScaleSettings::default()
    });
    let mut out = [0u8; MAX_FRAME];
    let mut replay = Replay::new();
    let mut frame =
        |service: &mut Service, scale: &mut Scale, seq: u32, request: &scale::Request| {
            let mut buf = [0u8; MAX_FRAME];
            let Ok(bytes) = wire::encode(seq, request, &mut buf) else {
                fail("scale encode")
            };
            let raw = bytes.split_last().map_or(&[][..], |(_, r)| r);
            primo_device::answer(service, scale, &mut replay, Ok(raw), &mut out)
        };
    frame(
        service,
        scale,
        1,
        &scale::Request::Scale(ScaleRequest::Stream { every: 1 }),
    );
    let mut sent = 0;
    let (mut read_ticks, mut weigh_ticks) = (0, 0);
    let stack = primo_firmware::stack_used_by(|| {
        read_ticks = ticks(syst, || {
            for i in 0..STEPS {
                scale.push(260_000 + (i % 3) as i32);
                if let Some(reply) = scale.streamed() {
                    let mut buf = [0u8; MAX_FRAME];
                    sent += wire::encode(STREAM, &reply, &mut buf).map_or(0, |f| f.len());
                }
            }
        });
        let weigh = scale::Request::Scale(ScaleRequest::Weigh {
            mode: WeighMode::Stable,
            unit: Unit::G,
        });
        weigh_ticks = ticks(syst, || {
            sent += frame(service, scale, 2, &weigh);
        });
    });
    if sent == 0 {
        fail("scale");
    }
    (read_ticks, weigh_ticks, stack)
}

#[entry]
fn main() -> ! {
    static mut SERVICE: Service = Service::new();
    static mut SCALE: Scale = Scale::new(ScaleConfig::LAB);
    let Some(mut p) = cortex_m::Peripherals::take() else {
        fail("peripherals")
    };
    p.SYST.set_clock_source(SystClkSource::Core);
    p.SYST.set_reload(0x00FF_FFFF);
    p.SYST.enable_counter();
    let (calib_instr, calib_ticks) = calibrate(&mut p.SYST);
    let instructions = |ticks: u64, n: u32| ticks * calib_instr / calib_ticks / u64::from(n);

    let dmp = reach();
    let (dmp_ticks, turn_ticks, coupled_ticks) = step_costs(&mut p.SYST, &dmp);
    let mut update_ticks = 0;
    let stack = primo_firmware::stack_used_by(|| {
        update_ticks = power_run(SERVICE, &mut p.SYST, &dmp);
    });
    hprintln!(
        "calibration: {} instructions in {} ticks",
        calib_instr,
        calib_ticks
    );
    hprintln!(
        "dmp step 7x30: {} instructions",
        instructions(dmp_ticks, STEPS)
    );
    hprintln!(
        "dmp step 7x30 with one obstacle: {} instructions",
        instructions(coupled_ticks, STEPS)
    );
    hprintln!(
        "orientation step 3x30 (with the quaternion): {} instructions",
        instructions(turn_ticks, STEPS)
    );
    hprintln!(
        "power update 219: {} instructions",
        instructions(update_ticks, UPDATES)
    );
    hprintln!("service stack: {} bytes", stack);
    let (read_ticks, weigh_ticks, scale_stack) = scale_costs(SERVICE, SCALE, &mut p.SYST);
    hprintln!(
        "scale reading (filter, display, stability, streamed frame): {} instructions",
        instructions(read_ticks, STEPS)
    );
    hprintln!(
        "scale weighing request (decode, weigh, encode): {} instructions",
        instructions(weigh_ticks, 1)
    );
    hprintln!("scale stack: {} bytes", scale_stack);
    primo_firmware::exit(true)
}
