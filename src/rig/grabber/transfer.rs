//! Operation 5 (transfer the frozen frame) over a line that loses and
//! damages bytes, without crawling.
//!
//! Each block is one `READ off len`; its `DATA` line is looked for in the
//! incoming bytes ([`find_reply`]), so whatever comes before it — the tail
//! of a block given up on, a line damaged on the way — is skipped without a
//! re-sync. Two timeouts apply: the reply timeout (profile) until the first
//! byte of the answer, and inside the answer an *inter-byte* timeout of a
//! few byte times at the baud rate (at least [`INTER_BYTE_FLOOR`]): a block
//! that stops short has lost bytes and is asked for again at once — just
//! that block, not a re-sync and a reply timeout as before (a lossy line
//! took 78 s a frame at drop = 1e-3). `DEPTH` READs are kept on their
//! way, so the grabber has the next request while it answers one: the line
//! does not go quiet between blocks, and a block that lost bytes runs into
//! the next DATA line — its CRC fails, the bytes after its first are looked
//! through again, and the next block is read without any wait at all. The
//! inter-byte timeout is only waited when the stream stops (both answers
//! lost, the frame's last block); should bytes arrive just after it (a slow
//! USB adapter, a busy machine), it doubles, up to a fifth of the reply
//! timeout, so it learns the line's real gaps.
//!
//! The block size follows the error rate: failures per byte are estimated
//! over the last 64 KiB asked for, and each READ takes the power of two
//! (from [`MIN_BLOCK`] to the profile's `block`) that costs the least time
//! per good byte — bytes and lines on the wire, a turnaround, and the
//! inter-byte wait of a failure, each weighed by how likely a block of that
//! size comes through whole.

use std::cell::Cell;
use std::collections::{BTreeMap, VecDeque};
use std::time::{Duration, Instant};

use super::{FrameGrabber, ReadFail, VsgClient};
use crate::llv::GreyImage;
use crate::rig::protocol::{Command, ErrCode, FrameInfo, Reply, crc32, find_reply};
use crate::rig::{Link, RigError};

/// The smallest READ a noisy line shrinks blocks to.
pub const MIN_BLOCK: u32 = 32;
/// The shortest inter-byte timeout: below this a pause that loses nothing
/// looks like a lost byte. USB-serial adapters hold the last bytes of a
/// burst until their latency timer runs out (FTDI's default is 16 ms), and
/// a loaded PC deschedules the reader for several ms; at 2 ms both made a
/// clean line re-request blocks and shrink them (1.5 wire bytes per
/// payload byte while the test suite ran beside it). The floor costs time
/// only when the stream stops, not per lost byte: a block that lost bytes
/// runs into the next DATA line.
pub const INTER_BYTE_FLOOR: Duration = Duration::from_millis(20);
/// The least a failed block is taken to cost when block sizes are chosen
/// ([`VsgClient::failure_cost`]).
const FAILURE_COST_FLOOR: Duration = Duration::from_millis(2);
/// Byte times of silence inside an answer that mean bytes were lost.
const INTER_BYTE_BYTES: u32 = 8;
/// Failed blocks in a row after which the frame is given up (at a byte
/// loss of 1e-2 a 64-byte block fails about half the time: 32 failures in
/// a row happen once in 10¹⁰ blocks).
const MAX_BAD_IN_A_ROW: u32 = 32;
/// Bytes asked for that the error estimate looks back over.
const WINDOW: f64 = 65536.0;
/// Bytes of a READ line and a DATA line together.
const LINE_BYTES: f64 = 48.0;
/// Time a request takes to turn round beyond its bytes.
const TURNAROUND: f64 = 0.001;
/// Good blocks in a row after which a raised inter-byte timeout halves.
const RELAX_AFTER: u32 = 256;
/// Junk bytes kept while looking for a reply line.
const MAX_SCAN: usize = 1 << 20;

/// The inter-byte timeout for a line at `baud`: `INTER_BYTE_BYTES` byte
/// times (10 bits each, 8N1), at least [`INTER_BYTE_FLOOR`].
pub fn inter_byte_for(baud: u32) -> Duration {
    let byte = 10.0 / f64::from(baud.max(1));
    Duration::from_secs_f64(byte * f64::from(INTER_BYTE_BYTES)).max(INTER_BYTE_FLOOR)
}

/// The block-size choice from the failures seen.
pub(super) struct Sizer {
    full: u32,
    /// Per block size 2^k: blocks that came whole and blocks that failed,
    /// decayed over [`WINDOW`] bytes asked for.
    whole: [f64; 33],
    failed: [f64; 33],
    /// [`Sizer::rate`] since the last [`Sizer::record`] (it is asked for
    /// every READ).
    rate: Cell<Option<f64>>,
}

/// The size class of a block: ⌈log2(len)⌉.
fn class(len: u32) -> usize {
    (32 - len.max(1).saturating_sub(1).leading_zeros()) as usize
}

impl Sizer {
    pub fn new(full: u32) -> Sizer {
        Sizer {
            full: full.max(1),
            whole: [0.0; 33],
            failed: [0.0; 33],
            rate: Cell::new(None),
        }
    }

    pub fn record(&mut self, len: u32, ok: bool) {
        self.rate.set(None);
        let d = (-f64::from(len) / WINDOW).exp();
        for (w, f) in self.whole.iter_mut().zip(self.failed.iter_mut()) {
            *w *= d;
            *f *= d;
        }
        let k = class(len).min(32);
        if let (Some(w), Some(f)) = (self.whole.get_mut(k), self.failed.get_mut(k)) {
            if ok {
                *w += 1.0;
            } else {
                *f += 1.0;
            }
        }
    }

    /// Estimated chance that a byte spoils its block: the most likely p
    /// when a block of `b` bytes comes whole with probability e^(−p·b),
    /// given the blocks of each size that came whole and that failed (a
    /// search over p from 10⁻⁸ to 0.5, 4 steps a decade).
    pub fn rate(&self) -> f64 {
        if let Some(r) = self.rate.get() {
            return r;
        }
        let r = self.estimate();
        self.rate.set(Some(r));
        r
    }

    fn estimate(&self) -> f64 {
        if self.failed.iter().all(|&f| f <= 1e-9) {
            return 0.0;
        }
        // Only the sizes that were asked for add to the likelihood (an
        // untouched size adds exactly 0).
        let seen: Vec<(f64, f64, f64)> = (0..33)
            .filter_map(|k| {
                let b = f64::from(1u32 << k.min(31));
                let (w, f) = (*self.whole.get(k)?, *self.failed.get(k)?);
                (w != 0.0 || f != 0.0).then_some((b, w, f))
            })
            .collect();
        let loglik = |p: f64| {
            let mut l = 0.0;
            for &(b, w, f) in &seen {
                let mut term = -p * b * w;
                if f != 0.0 {
                    term += f * (1.0 - (-p * b).exp()).max(1e-300).ln();
                }
                l += term;
            }
            l
        };
        let mut best = (f64::NEG_INFINITY, 0.0);
        for i in 0..=30 {
            let p = 10f64.powf(-8.0 + f64::from(i) / 4.0).min(0.5);
            let l = loglik(p);
            if l > best.0 {
                best = (l, p);
            }
        }
        best.1
    }

    /// The block size with the least expected time per good byte, given a
    /// byte time and the time a failure costs (seconds).
    pub fn block(&self, byte_time: f64, failure: f64) -> u32 {
        let p = self.rate();
        if p <= 0.0 || self.full <= MIN_BLOCK {
            return self.full;
        }
        let cost = |b: u32| {
            let b = f64::from(b);
            let q = (-p * b).exp();
            ((b + LINE_BYTES) * byte_time + TURNAROUND + (1.0 - q) * failure) / (q * b)
        };
        let mut best = self.full;
        let mut b = self.full;
        while b >= MIN_BLOCK {
            if cost(b) < cost(best) {
                best = b;
            }
            if b == MIN_BLOCK {
                break;
            }
            b = (b / 2).max(MIN_BLOCK);
        }
        best
    }
}

/// READs kept on their way: while one block's answer comes in, the
/// grabber already has the next requests, so the line never goes quiet
/// between blocks and a block that lost bytes shows at once (its bytes run
/// into the next DATA line) instead of after a timeout. The stream only
/// stops when every answer on its way lost its DATA line: at a byte loss
/// of 1e-2 a quarter of them do, so four out make that rare (0.4 %). Four
/// short lines are little for a grabber to hold.
const DEPTH: usize = 4;

/// What the next reply line is.
enum Event {
    /// The DATA line of `pending[index]` (the answers before it were lost).
    Header { index: usize, crc: u32 },
    /// `ERR CHECKSUM`: the oldest request reached the grabber garbled.
    DeviceChecksum,
    /// Bytes came, then silence: every request out is lost.
    Quiet,
    /// Nothing at all within the reply timeout.
    Silent,
}

/// What a block's payload was.
enum Payload {
    Good(Vec<u8>),
    /// Damaged or short by lost bytes (the bytes that followed it are
    /// left to be looked through for the next DATA line).
    Bad,
    /// Stopped short, and nothing followed.
    Short,
}

/// The requests of a transfer: what is still owed (not asked for), what is
/// pending (asked for, in order), and the block size.
struct Pipeline {
    owed: VecDeque<(u32, u32)>,
    pending: VecDeque<(u32, u32)>,
    sizer: Sizer,
    byte_time: f64,
    /// When the pipeline last started from empty.
    since: Instant,
}

impl Pipeline {
    /// Blocks that failed are owed again, first, in frame order.
    fn fail(&mut self, failed: &[(u32, u32)]) {
        for &(off, len) in failed.iter().rev() {
            self.owed.push_front((off, len));
        }
        for &(_, len) in failed {
            self.sizer.record(len, false);
        }
    }
}

impl<P: Link> VsgClient<P> {
    /// Looks for the next reply to one of `pending`, skipping anything else
    /// (late answers, damaged lines, payload of blocks given up on).
    fn next_event(
        &mut self,
        pending: &VecDeque<(u32, u32)>,
        since: Instant,
    ) -> Result<Event, RigError> {
        // `rx[..seen]` holds no line end. A reply line ends at one and never
        // spans one (its text is printable), so what comes up to the last
        // line end when no reply is found is junk for good: it is dropped,
        // and after a read only the new bytes are looked at for a line end.
        // (Looking through all of `rx` again after each read made a stream
        // of junk cost the square of its length.)
        let mut seen = 0;
        loop {
            let line_end = self.rx.get(seen..).is_some_and(|b| b.contains(&b'\n'));
            if line_end {
                if let Some((_, end, reply)) = find_reply(&self.rx) {
                    self.rx.drain(..end);
                    seen = 0;
                    match reply {
                        Reply::Data { off, len, crc } => {
                            let Some(index) = pending.iter().position(|&p| p == (off, len)) else {
                                // A late answer: its payload is skipped as junk.
                                continue;
                            };
                            return Ok(Event::Header { index, crc });
                        }
                        Reply::Err {
                            code: ErrCode::Checksum,
                            ..
                        } => return Ok(Event::DeviceChecksum),
                        r @ Reply::Err { .. } => {
                            let (off, len) = pending.front().copied().unwrap_or_default();
                            return self.device_err(&Command::Read { off, len }, r);
                        }
                        // A late OK to an earlier command.
                        Reply::Ok(_) => continue,
                    }
                }
                if let Some(last) = self.rx.iter().rposition(|&b| b == b'\n') {
                    self.rx.drain(..=last);
                }
            }
            if self.rx.len() > MAX_SCAN {
                let cut = self.rx.len() - 256;
                self.rx.drain(..cut);
            }
            seen = self.rx.len();
            // Once anything came after the requests went out, silence
            // means loss; before, the reply timeout applies.
            let heard = self.last_rx.is_some_and(|t| t >= since);
            let wait = if heard {
                self.inter_byte
            } else {
                self.cfg.timeout.saturating_sub(since.elapsed())
            };
            match self.fill(wait) {
                Ok(()) => {}
                Err(ReadFail::Vanished(e)) => return Err(self.vanished(e)),
                Err(_) if heard => return Ok(Event::Quiet),
                Err(_) => return Ok(Event::Silent),
            }
        }
    }

    /// The `len` bytes after a DATA line, checked against `crc`.
    fn payload(&mut self, len: u32, crc: u32) -> Result<Payload, RigError> {
        let need = len as usize;
        while self.rx.len() < need {
            match self.fill(self.inter_byte) {
                Ok(()) => {}
                Err(ReadFail::Vanished(e)) => return Err(self.vanished(e)),
                Err(_) => return Ok(Payload::Short),
            }
        }
        if self.rx.get(..need).is_some_and(|b| crc32(b) == crc) {
            return Ok(Payload::Good(self.rx.drain(..need).collect()));
        }
        // Lost bytes made the block take the start of what followed: all
        // but its first byte is looked through again.
        self.rx.drain(..1);
        Ok(Payload::Bad)
    }

    /// The frozen frame, got back when the grabber loses it on the way.
    ///
    /// A grabber that is reset (a power dip, its watchdog) forgets its
    /// frame and its camera, and answers the READs still to come `NOFRAME`.
    /// The operator asked for a frame of one camera, under the lights the
    /// cell set: the transfer freezes again by itself ([`Self::recover_frame`])
    /// when that is what it gets back, and only then:
    /// - this client froze the frame itself, from a camera it had selected
    ///   (not a LOADed image, which FREEZE cannot make again, nor a frame
    ///   someone else froze, whose camera is unknown);
    /// - STATUS says the grabber holds no frame: it lost it. A frame with
    ///   another CRC there was frozen by someone else (a second console, the
    ///   front panel) and is not replaced. The same CRC there means the
    ///   NOFRAME answered a READ of an earlier transfer: the frame is read
    ///   again as it is;
    /// - that camera is selected again before FREEZE (a reset grabber is
    ///   back on camera 1), and the new frame must have the old one's size.
    ///
    /// The lights are not the grabber's: a reset leaves the relay board as
    /// the cell switched it, so the new frame is taken under the same
    /// lighting. The new frame is a new exposure (its CRC is the new
    /// FREEZE's, in [`FrameGrabber::frame`]), just as a retake by hand would
    /// be. At most [`super::FRAME_RECOVERIES`] times per transfer; then, or
    /// when a condition fails, the operator is told to freeze again.
    pub(super) fn read_frame_recovering(
        &mut self,
        mut frame: FrameInfo,
        progress: &mut dyn FnMut(usize, usize) -> bool,
    ) -> Result<GreyImage, RigError> {
        let mut recovered = 0;
        let mut crc_miss: Option<RigError> = None;
        loop {
            match self.read_frame(frame, progress) {
                Err(e @ RigError::NoFrame { .. }) if recovered < super::FRAME_RECOVERIES => {
                    recovered += 1;
                    match self.recover_frame(frame)? {
                        Some(f) => frame = f,
                        None => return Err(e),
                    }
                }
                // Every block passed its own CRC, the frame did not pass
                // FREEZE's: a block came from another frame. A READ given
                // up on in an earlier transfer (the line was slow: a loaded
                // machine) can be answered after the re-sync's quiet time,
                // and its DATA names the same offset and length as a READ
                // of this frame. The grabber still holds this frame: it is
                // read once more, after the re-sync that read_frame did.
                Err(e @ RigError::FrameCrc { .. }) if crc_miss.is_none() => {
                    crc_miss = Some(e);
                }
                // The second read failed too: the CRC mismatch is what went
                // wrong, unless the device went away or the operator stopped.
                Err(e) if !(e.is_vanished() || matches!(e, RigError::Cancelled { .. })) => {
                    return Err(crc_miss.unwrap_or(e));
                }
                r => return r,
            }
        }
    }

    /// After `NOFRAME` in a transfer of `lost`: the frame to read now, or
    /// `None` when the conditions of [`Self::read_frame_recovering`] fail.
    fn recover_frame(&mut self, lost: FrameInfo) -> Result<Option<FrameInfo>, RigError> {
        let Some(camera) = self.frozen_from.filter(|_| self.frame == Some(lost)) else {
            return Ok(None);
        };
        match self.status()?.frame {
            Some(crc) if crc == lost.crc => Ok(Some(lost)),
            Some(_) => Ok(None),
            None => {
                self.select_camera(camera)?;
                let f = self.freeze()?;
                self.stats.refreezes += 1;
                Ok(((f.width, f.height) == (lost.width, lost.height)).then_some(f))
            }
        }
    }

    /// The whole frozen frame, block by block, [`DEPTH`] READs at a time.
    pub(super) fn read_frame(
        &mut self,
        frame: FrameInfo,
        progress: &mut dyn FnMut(usize, usize) -> bool,
    ) -> Result<GreyImage, RigError> {
        let r = self.read_frame_inner(frame, progress);
        if r.is_err() || self.untracked {
            // Answers to requests given up on may still come: let them
            // pass before the next command (a late ERR would answer it).
            self.untracked = false;
            self.resync()?;
        }
        r
    }

    fn read_frame_inner(
        &mut self,
        frame: FrameInfo,
        progress: &mut dyn FnMut(usize, usize) -> bool,
    ) -> Result<GreyImage, RigError> {
        let total = frame.len();
        if total == 0 || total > super::MAX_FRAME {
            return Err(RigError::Garbled {
                port: self.name.clone(),
                command: "FREEZE".into(),
                detail: format!("frame size {} x {}", frame.width, frame.height),
                attempts: 1,
            });
        }
        let maxblock = self.info.as_ref().map_or(u32::MAX, |i| i.maxblock.max(1));
        let sizer = Sizer::new(self.cfg.block.min(maxblock).max(1));
        let byte_time = 10.0 / f64::from(self.cfg.baud.max(1));
        // Blocks as they come, put together at the end: memory follows the
        // bytes received, not the size a FREEZE reply claims.
        let mut blocks: BTreeMap<u32, Vec<u8>> = BTreeMap::new();
        let mut done = 0usize;
        let mut t = Pipeline {
            owed: VecDeque::from([(0, total as u32)]),
            pending: VecDeque::new(),
            sizer,
            byte_time,
            since: Instant::now(),
        };
        let (mut silent, mut bad_in_a_row, mut good_run) = (0u32, 0u32, 0u32);
        while done < total {
            self.top_up(&mut t)?;
            let mut failed: Vec<(u32, u32)> = Vec::new();
            match self.next_event(&t.pending, t.since)? {
                Event::Header { index, crc } => {
                    failed.extend(t.pending.drain(..index));
                    let Some((off, len)) = t.pending.pop_front() else {
                        continue;
                    };
                    // The next requests go out before this payload is read,
                    // so the grabber never waits for them.
                    t.fail(&failed);
                    self.top_up(&mut t)?;
                    self.count_failures(&failed, &mut bad_in_a_row)?;
                    failed.clear();
                    match self.payload(len, crc)? {
                        Payload::Good(bytes) => {
                            blocks.insert(off, bytes);
                            done += len as usize;
                            t.sizer.record(len, true);
                            (silent, bad_in_a_row) = (0, 0);
                            good_run += 1;
                            if good_run >= RELAX_AFTER {
                                // A long clean run: let the inter-byte
                                // timeout come back down.
                                good_run = 0;
                                self.inter_byte = (self.inter_byte / 2).max(self.base_inter_byte);
                            }
                            self.stats.payload += u64::from(len);
                            if !progress(done, total) {
                                return Err(RigError::Cancelled {
                                    port: self.name.clone(),
                                    done,
                                    total,
                                });
                            }
                        }
                        Payload::Bad => failed.push((off, len)),
                        Payload::Short => {
                            failed.push((off, len));
                            failed.extend(t.pending.drain(..));
                            self.given_up()?;
                        }
                    }
                }
                Event::DeviceChecksum => {
                    failed.extend(t.pending.pop_front());
                }
                Event::Quiet => {
                    failed.extend(t.pending.drain(..));
                    self.given_up()?;
                }
                Event::Silent => {
                    // A stalled grabber is no reason to keep a cancel (or
                    // a request to leave the session) waiting for retries.
                    if !progress(done, total) {
                        return Err(RigError::Cancelled {
                            port: self.name.clone(),
                            done,
                            total,
                        });
                    }
                    silent += 1;
                    if silent > self.cfg.retries {
                        let (off, len) = t.pending.front().copied().unwrap_or_default();
                        return Err(RigError::Timeout {
                            port: self.name.clone(),
                            command: Command::Read { off, len }.to_string(),
                            timeout_ms: self.cfg.timeout.as_millis() as u64,
                            attempts: silent,
                        });
                    }
                    self.stats.retries += t.pending.len() as u64;
                    while let Some(p) = t.pending.pop_back() {
                        t.owed.push_front(p);
                    }
                    self.untracked = true;
                    // Silence may be a grabber that lost a line's end: an
                    // empty line ends whatever it was receiving.
                    self.resync()?;
                }
            }
            if !failed.is_empty() {
                good_run = 0;
            }
            t.fail(&failed);
            self.count_failures(&failed, &mut bad_in_a_row)?;
        }
        let mut data = Vec::with_capacity(total);
        for b in blocks.into_values() {
            data.extend_from_slice(&b);
        }
        let got = crc32(&data);
        if got != frame.crc {
            return Err(RigError::FrameCrc {
                port: self.name.clone(),
                expected: frame.crc,
                got,
            });
        }
        GreyImage::new(frame.width as usize, frame.height as usize, data)
            .map_err(|e| RigError::Config(e.to_string()))
    }

    /// Keeps [`DEPTH`] READs out, the blocks owed first in frame order.
    fn top_up(&mut self, t: &mut Pipeline) -> Result<(), RigError> {
        while t.pending.len() < DEPTH {
            let Some((off, len)) = t.owed.pop_front() else {
                break;
            };
            let take = len.min(t.sizer.block(t.byte_time, self.failure_cost(t.byte_time)));
            if take < len {
                t.owed.push_front((off + take, len - take));
            }
            if t.pending.is_empty() {
                t.since = Instant::now();
            }
            self.send(&Command::Read { off, len: take })?;
            t.pending.push_back((off, take));
        }
        Ok(())
    }

    /// Counts failed blocks; too many in a row end the frame.
    fn count_failures(
        &mut self,
        failed: &[(u32, u32)],
        in_a_row: &mut u32,
    ) -> Result<(), RigError> {
        for &(off, _) in failed {
            self.stats.bad_blocks += 1;
            *in_a_row += 1;
            if *in_a_row >= MAX_BAD_IN_A_ROW {
                return Err(RigError::BlockCrc {
                    port: self.name.clone(),
                    offset: off as usize,
                    attempts: *in_a_row,
                });
            }
        }
        Ok(())
    }

    /// What a failed block costs beyond its bytes, for the block size:
    /// a block that lost bytes runs into the next DATA line, so it is not
    /// the inter-byte timeout but a few byte times and a scheduler tick
    /// ([`FAILURE_COST_FLOOR`]), plus what the line taught the timeout
    /// beyond its start (a slow adapter's longer gaps).
    fn failure_cost(&self, byte_time: f64) -> f64 {
        let learned = self.inter_byte.saturating_sub(self.base_inter_byte);
        (byte_time * f64::from(INTER_BYTE_BYTES)).max(FAILURE_COST_FLOOR.as_secs_f64())
            + learned.as_secs_f64()
    }

    /// Every request out was given up on after silence inside an answer:
    /// what came of them is junk, and their answers may still come. Bytes
    /// that arrive within an inter-byte timeout of giving up mean the
    /// line's gaps are longer than the timeout (a USB adapter that sends
    /// the last bytes of a burst after its latency timer): it doubles, up
    /// to a fifth of the reply timeout.
    fn given_up(&mut self) -> Result<(), RigError> {
        self.rx.clear();
        self.untracked = true;
        self.stats.stalls += 1;
        match self.fill(self.inter_byte) {
            Ok(()) => {
                self.inter_byte = (self.inter_byte * 2).min(self.gap);
                self.rx.clear();
                Ok(())
            }
            Err(ReadFail::Vanished(e)) => Err(self.vanished(e)),
            Err(_) => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_shrink_with_the_error_rate_and_grow_back() {
        let bt = 10.0 / 921_600.0;
        let fail = 0.002;
        let mut s = Sizer::new(16384);
        assert_eq!(s.block(bt, fail), 16384, "a clean line: full blocks");
        // About one byte in a thousand lost.
        for _ in 0..200 {
            s.record(1000, true);
            s.record(1000, false);
        }
        let b3 = s.block(bt, fail);
        assert!((128..=512).contains(&b3), "{b3}");
        // One in a hundred.
        let mut s = Sizer::new(16384);
        for _ in 0..200 {
            s.record(100, true);
            s.record(100, false);
        }
        let b2 = s.block(bt, fail);
        assert!((MIN_BLOCK..=128).contains(&b2), "{b2}");
        // Clean again: within a frame's worth of bytes blocks are large.
        let mut clean = 0;
        while clean < 256 << 10 {
            let b = s.block(bt, fail);
            s.record(b, true);
            clean += b;
        }
        assert!(s.block(bt, fail) >= 2048, "{}", s.block(bt, fail));
        // Every block failing: the smallest at once.
        let mut s = Sizer::new(1024);
        for _ in 0..4 {
            s.record(256, false);
        }
        assert!(s.block(bt, fail) <= 64, "{}", s.block(bt, fail));
    }

    #[test]
    fn the_inter_byte_timeout_follows_the_baud_rate() {
        assert_eq!(inter_byte_for(921_600), INTER_BYTE_FLOOR);
        assert_eq!(inter_byte_for(9600), INTER_BYTE_FLOOR);
        assert_eq!(inter_byte_for(1200), Duration::from_secs_f64(80.0 / 1200.0));
    }
}
