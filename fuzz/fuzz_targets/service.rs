//! The coprocessor's service fed an arbitrary session: requests built from
//! the input (postcard), sent as frames, some repeated (retransmissions)
//! and some corrupted. No panic; every reply is a frame that decodes, with
//! the request's sequence number (or UNREAD for a corrupt frame); a
//! retransmission gets the same bytes; a fresh request gets exactly what
//! an in-process service answers; roll-outs, chunks and setpoints are
//! finite.
#![no_main]

use libfuzzer_sys::fuzz_target;
use primo_learner::{Coprocessor, UNREAD};
use primo_protocol::fault::FaultKind;
use primo_protocol::frame::{self as wire, MAX_FRAME};
use primo_protocol::learner::{Reply, Request};

/// Requests per session: enough to stream a whole movement.
const MAX_REQUESTS: usize = 400;

fn check_finite(reply: &Reply) {
    let values: &[f32] = match reply {
        Reply::Rollout(r) => &r.query,
        Reply::Chunk { values, .. } => values,
        Reply::Setpoint { time, position, .. } => {
            assert!(time.is_finite());
            position
        }
        _ => &[],
    };
    assert!(values.iter().all(|v| v.is_finite()), "{reply:?}");
}

fuzz_target!(|data: &[u8]| {
    // Boxed: a Coprocessor is 15 KiB.
    let mut wire_side = Box::new(Coprocessor::new());
    let mut in_process = Box::new(Coprocessor::new());
    // The last answered frame: its sequence number and reply bytes.
    let mut last: Option<(u32, Vec<u8>)> = None;
    let mut next_seq = 1u32;
    let mut rest = data;
    for _ in 0..MAX_REQUESTS {
        let Some((&control, after)) = rest.split_first() else {
            break;
        };
        let Ok((request, after)) = postcard::take_from_bytes::<Request>(after) else {
            break;
        };
        rest = after;
        let corrupt = control & 2 == 2;
        let repeated = last.as_ref().filter(|_| control & 1 == 1);
        let seq = match repeated {
            Some((seq, _)) => *seq,
            None => {
                next_seq += 1;
                next_seq
            }
        };
        let mut buf = [0u8; MAX_FRAME];
        let Ok(frame) = wire::encode(seq, &request, &mut buf) else {
            continue;
        };
        let mut raw = frame[..frame.len() - 1].to_vec();
        if corrupt {
            let at = usize::from(control >> 2) % raw.len();
            raw[at] ^= 0x5a;
        }
        let mut out = [0u8; MAX_FRAME];
        let reply_bytes = wire_side.handle(Ok(&raw), &mut out).to_vec();
        let (end, body) = reply_bytes.split_last().expect("a reply frame");
        assert_eq!(*end, 0);
        let reply = wire::decode::<Reply>(body).expect("the reply decodes");
        check_finite(&reply.body);
        if corrupt {
            // One changed byte never gets past the CRC.
            assert!(
                matches!(&reply.body, Reply::Error(f) if f.kind == FaultKind::BadFrame),
                "{reply:?}"
            );
            assert_eq!(reply.seq, UNREAD);
            continue;
        }
        assert_eq!(reply.seq, seq);
        match repeated {
            // Whatever the body, the same number is the same request.
            Some((_, bytes)) => {
                assert_eq!(&reply_bytes, bytes, "a retransmission changed the reply")
            }
            None => {
                let expected = in_process.respond(&request);
                assert_eq!(format!("{:?}", reply.body), format!("{expected:?}"));
                last = Some((seq, reply_bytes));
            }
        }
    }
});
