//! Retransmissions, the same on every device: a frame with the sequence
//! number of the previous one gets the previous reply's bytes again and
//! changes nothing. A device answers its frames through one [`Replay`].

use heapless::Vec;
use serde::Serialize;

use crate::endpoint::Endpoint;
use crate::fault::{Fault, FaultKind};
use crate::frame::{self, Frame, FrameError, MAX_FRAME};

/// The sequence number of replies to frames that could not be read (hosts
/// never send it).
pub const UNREAD: u32 = 0;

/// The last frame's sequence number and reply bytes (none yet while its
/// answer is deferred).
#[derive(Debug, Clone, Default)]
pub struct Replay {
    last: Option<(u32, Vec<u8, MAX_FRAME>)>,
}

/// The length of an encoded frame, 0 if it could not be encoded.
fn len(r: Result<&[u8], FrameError>) -> usize {
    r.map_or(0, <[u8]>::len)
}

impl Replay {
    /// No frame answered yet.
    pub const fn new() -> Self {
        Replay { last: None }
    }

    /// Answers one frame off the line (`raw` as
    /// [`frame::FrameReader::push`] gives it) to endpoint `E` with
    /// `respond`, and returns the reply frame's length in `out`. A frame
    /// that cannot be read gets a [`FaultKind::BadFrame`] reply numbered
    /// [`UNREAD`]; a repeated sequence number gets the previous reply
    /// again without `respond`. `respond` giving no reply defers it: no
    /// reply frame now (length 0, and the same to a retransmission), the
    /// answer comes from [`Replay::deferred`].
    pub fn serve<E: Endpoint>(
        &mut self,
        raw: Result<&[u8], FrameError>,
        out: &mut [u8; MAX_FRAME],
        respond: impl FnOnce(&E::Request) -> Option<E::Reply>,
    ) -> usize {
        let frame = match self.open::<E>(raw, out) {
            Ok(frame) => frame,
            Err(len) => return len,
        };
        let Some(reply) = respond(&frame.body) else {
            // Deferred: an empty last reply until it is given, so a
            // retransmission meanwhile gets nothing and changes nothing.
            self.last = Some((frame.seq, Vec::new()));
            return 0;
        };
        self.answer(frame.seq, &reply, out)
    }

    /// The first half of [`Replay::serve`], for a device that answers at
    /// once: the request of a frame to be answered (then
    /// [`Replay::answer`] it), or the length of the reply frame already
    /// written into `out` (a frame that cannot be read, a retransmission).
    pub fn open<E: Endpoint>(
        &mut self,
        raw: Result<&[u8], FrameError>,
        out: &mut [u8; MAX_FRAME],
    ) -> Result<Frame<E::Request>, usize> {
        let frame = match raw.and_then(frame::decode::<E::Request>) {
            Ok(frame) => frame,
            Err(e) => {
                let reply = E::Reply::from(Fault::new(FaultKind::BadFrame, e));
                return Err(len(frame::encode(UNREAD, &reply, out)));
            }
        };
        if let Some((seq, bytes)) = &self.last
            && *seq == frame.seq
            && let Some(dst) = out.get_mut(..bytes.len())
        {
            dst.copy_from_slice(bytes);
            return Err(bytes.len());
        }
        Ok(frame)
    }

    /// The second half of [`Replay::serve`]: encodes `reply` to frame
    /// `seq` into `out` and keeps it for a retransmission; returns its
    /// length.
    pub fn answer<R: Serialize + From<Fault>>(
        &mut self,
        seq: u32,
        reply: &R,
        out: &mut [u8; MAX_FRAME],
    ) -> usize {
        self.record(seq, reply, out)
    }

    /// The deferred answer `reply` to the last frame: its reply frame's
    /// length in `out`, kept for a retransmission; `None` (and nothing
    /// written) if the last frame's answer is not waiting.
    pub fn deferred<R: Serialize + From<Fault>>(
        &mut self,
        reply: &R,
        out: &mut [u8; MAX_FRAME],
    ) -> Option<usize> {
        let seq = match &self.last {
            Some((seq, bytes)) if bytes.is_empty() => *seq,
            _ => return None,
        };
        Some(self.record(seq, reply, out))
    }

    /// Encodes `reply` to frame `seq` into `out` and keeps it as the last
    /// reply; returns its length.
    fn record<R: Serialize + From<Fault>>(
        &mut self,
        seq: u32,
        reply: &R,
        out: &mut [u8; MAX_FRAME],
    ) -> usize {
        let n = match frame::encode(seq, reply, out) {
            Ok(bytes) => bytes.len(),
            // Every reply fits a frame (tested); should one not, say so.
            Err(e) => len(frame::encode(
                seq,
                &R::from(Fault::new(FaultKind::Capacity, e)),
                out,
            )),
        };
        self.last = out
            .get(..n)
            .and_then(|b| Vec::from_slice(b).ok())
            .map(|b| (seq, b));
        n
    }
}
