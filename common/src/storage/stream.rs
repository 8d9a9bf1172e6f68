//! The board record streamed between flash and the stores it fills, with no copy of it in RAM.
//!
//! An encoded record can take most of its 16 KiB slot, and the decoded one (a parameter image
//! and a whole plan) as much again: more than a small board can keep aside for a boot-time
//! load. Here a save encodes straight into the flash through a 64-byte window (a first pass
//! only counts and checksums, so nothing is erased for a record that does not fit), and a load
//! decodes one element at a time (a parameter, a mission item) from a 64-byte window straight
//! into the vehicle's stores. A load first walks the whole copy, so a copy that does not decode
//! changes nothing, then walks it again to apply it.

use serde::{Deserialize, Serialize};

use super::{
    candidates, AbRegion, BoardRecordRef, Flash, Header, SigningRecord, StorageError, HEADER_LEN,
};
use crate::navigation::plan::{
    MissionItem, MissionStore, PlanKind, FENCE_CAPACITY, MISSION_CAPACITY, RALLY_CAPACITY,
};
use crate::params::declare::MAX_NAME_LEN;
use crate::params::store::{ImportReport, ParamStore, MAX_PARAMS};

/// Bytes read from or written to the flash at a time.
const WINDOW: usize = 64;

/// Reads a slot's payload in order through a small window.
struct Cursor<'f, F: Flash> {
    flash: &'f mut F,
    next: u32,
    end: u32,
    win: [u8; WINDOW],
    pos: usize,
    fill: usize,
    failed: Option<F::Error>,
}

impl<'f, F: Flash> Cursor<'f, F> {
    /// The `len` payload bytes of the slot at `slot`.
    fn new(flash: &'f mut F, slot: u32, len: u32) -> Self {
        let start = slot.saturating_add(HEADER_LEN);
        Self {
            flash,
            next: start,
            end: start.saturating_add(len),
            win: [0; WINDOW],
            pos: 0,
            fill: 0,
            failed: None,
        }
    }

    fn pop(&mut self) -> postcard::Result<u8> {
        if self.pos >= self.fill {
            let n = self.end.saturating_sub(self.next).min(WINDOW as u32) as usize;
            let buf = self
                .win
                .get_mut(..n)
                .filter(|b| !b.is_empty())
                .ok_or(postcard::Error::DeserializeUnexpectedEnd)?;
            if let Err(e) = self.flash.read(self.next, buf) {
                self.failed = Some(e);
                return Err(postcard::Error::DeserializeUnexpectedEnd);
            }
            self.next = self.next.saturating_add(n as u32);
            (self.pos, self.fill) = (0, n);
        }
        let b = self
            .win
            .get(self.pos)
            .copied()
            .ok_or(postcard::Error::DeserializeUnexpectedEnd)?;
        self.pos = self.pos.saturating_add(1);
        Ok(b)
    }

    /// One element of type `T`, with `arena` for the bytes it borrows (a parameter's name).
    fn element<'s, 'de, T: Deserialize<'de>>(
        &'s mut self,
        arena: &'de mut [u8],
    ) -> postcard::Result<T>
    where
        's: 'de,
        F: 'de,
    {
        let mut de = postcard::Deserializer::from_flavor(Piece { cur: self, arena });
        T::deserialize(&mut de)
    }

    /// A sequence's length.
    fn len(&mut self) -> postcard::Result<usize> {
        self.element::<u32>(&mut []).map(|n| n as usize)
    }
}

/// postcard's view of a [`Cursor`] for one element: bytes it lends out come from `arena`.
struct Piece<'c, 'f, 'de, F: Flash> {
    cur: &'c mut Cursor<'f, F>,
    arena: &'de mut [u8],
}

impl<'c: 'de, 'f: 'de, 'de, F: Flash + 'de> postcard::de_flavors::Flavor<'de>
    for Piece<'c, 'f, 'de, F>
{
    type Remainder = ();
    type Source = ();

    fn pop(&mut self) -> postcard::Result<u8> {
        self.cur.pop()
    }

    fn try_take_n(&mut self, ct: usize) -> postcard::Result<&'de [u8]> {
        if ct > self.arena.len() {
            return Err(postcard::Error::DeserializeUnexpectedEnd);
        }
        let (head, rest) = core::mem::take(&mut self.arena).split_at_mut(ct);
        for b in head.iter_mut() {
            *b = self.cur.pop()?;
        }
        self.arena = rest;
        Ok(head)
    }

    fn finalize(self) -> postcard::Result<()> {
        Ok(())
    }
}

/// Where a walk of a record puts what it reads.
trait Sink {
    fn param(&mut self, name: &str, value: f32);
    fn item(&mut self, kind: PlanKind, item: MissionItem);
    fn signing(&mut self, record: SigningRecord);
}

/// A walk that keeps nothing: whether a copy decodes.
struct Check;

impl Sink for Check {
    fn param(&mut self, _: &str, _: f32) {}
    fn item(&mut self, _: PlanKind, _: MissionItem) {}
    fn signing(&mut self, _: SigningRecord) {}
}

/// Arena of one element: a parameter's name and its value.
type Arena = [u8; 32];

/// Walks the parameters section (the record's first), handing each one to `put`.
fn walk_params<F: Flash>(
    cur: &mut Cursor<'_, F>,
    put: &mut dyn FnMut(&str, f32),
) -> postcard::Result<()> {
    let n = cur.len()?;
    if n > MAX_PARAMS {
        return Err(postcard::Error::DeserializeUnexpectedEnd);
    }
    for _ in 0..n {
        let mut arena: Arena = [0; 32];
        let (name, value) = cur.element::<(&str, f32)>(&mut arena)?;
        if name.len() > MAX_NAME_LEN {
            return Err(postcard::Error::DeserializeBadUtf8);
        }
        put(name, value);
    }
    Ok(())
}

/// Walks a whole record: the parameters, the three lists of the plan, the signing record.
fn walk<F: Flash>(cur: &mut Cursor<'_, F>, sink: &mut dyn Sink) -> postcard::Result<()> {
    walk_params(cur, &mut |name, value| sink.param(name, value))?;
    for (kind, cap) in [
        (PlanKind::Mission, MISSION_CAPACITY),
        (PlanKind::Fence, FENCE_CAPACITY),
        (PlanKind::Rally, RALLY_CAPACITY),
    ] {
        let n = cur.len()?;
        if n > cap {
            return Err(postcard::Error::DeserializeUnexpectedEnd);
        }
        for _ in 0..n {
            let item = cur.element::<MissionItem>(&mut [])?;
            sink.item(kind, item);
        }
    }
    let signing = cur.element::<SigningRecord>(&mut [])?;
    sink.signing(signing);
    Ok(())
}

/// Walks the copy in the slot at `addr`; `Ok(false)`: it does not decode.
fn walk_slot<F: Flash>(
    flash: &mut F,
    addr: u32,
    h: Header,
    sink: &mut dyn Sink,
) -> Result<bool, StorageError<F::Error>> {
    let mut cur = Cursor::new(flash, addr, h.len);
    match walk(&mut cur, sink) {
        Ok(()) => Ok(true),
        Err(_) => cur
            .failed
            .map_or(Ok(false), |e| Err(StorageError::Flash(e))),
    }
}

/// What [`load_board_into`] loaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoardLoaded {
    /// The parameters taken, unknown and refused.
    pub params: ImportReport,
    /// The signing key and clock.
    pub signing: SigningRecord,
    /// The copy's save counter.
    pub seq: u32,
}

/// Fills the plan's lists in place.
struct PlanInto<'a>(&'a mut MissionStore, Option<SigningRecord>);

impl Sink for PlanInto<'_> {
    fn param(&mut self, _: &str, _: f32) {}
    fn item(&mut self, kind: PlanKind, item: MissionItem) {
        // Cannot fail: the check walk counted each list against its capacity.
        let _ = match kind {
            PlanKind::Mission => self.0.mission.push(item),
            PlanKind::Fence => self.0.fence.push(item),
            PlanKind::Rally => self.0.rally.push(item),
        };
    }
    fn signing(&mut self, record: SigningRecord) {
        self.1 = Some(record);
    }
}

/// Loads the newest intact copy of the board record that decodes (falling back to the older
/// one) straight into `params` (by name, as [`ParamStore::import`] does) and `plan` (its three
/// lists replaced); `None` when neither slot holds one. Uses a few hundred bytes of stack
/// whatever the record's size.
pub fn load_board_into<F: Flash>(
    flash: &mut F,
    region: &AbRegion,
    params: &mut ParamStore,
    plan: &mut MissionStore,
) -> Result<Option<BoardLoaded>, StorageError<F::Error>> {
    let mut any = false;
    for (addr, h) in candidates(flash, region)?.into_iter().flatten() {
        any = true;
        if !walk_slot(flash, addr, h, &mut Check)? {
            continue;
        }
        let mut failed = None;
        let report = params.import_with(|put| {
            let mut cur = Cursor::new(flash, addr, h.len);
            if walk_params(&mut cur, put).is_err() {
                failed = failed.take().or(cur.failed);
            }
        });
        if let Some(e) = failed {
            return Err(StorageError::Flash(e));
        }
        for kind in [PlanKind::Mission, PlanKind::Fence, PlanKind::Rally] {
            plan.clear(kind);
        }
        let mut into = PlanInto(plan, None);
        if !walk_slot(flash, addr, h, &mut into)? {
            return Err(StorageError::Decode);
        }
        return Ok(Some(BoardLoaded {
            params: report,
            signing: into.1.unwrap_or_default(),
            seq: h.seq,
        }));
    }
    if any {
        Err(StorageError::Decode)
    } else {
        Ok(None)
    }
}

/// postcard's output into a slot's payload, a window at a time: written when `flash` is
/// given, checksummed when `crc` is, counted always.
struct Writer<'f, F: Flash> {
    flash: Option<&'f mut F>,
    crc: Option<crate::crc::Crc32>,
    at: u32,
    limit: u32,
    len: u32,
    buf: [u8; WINDOW],
    n: usize,
    failed: Option<F::Error>,
}

impl<'f, F: Flash> Writer<'f, F> {
    fn new(limit: u32) -> Self {
        Self {
            flash: None,
            crc: None,
            at: 0,
            limit,
            len: 0,
            buf: [0; WINDOW],
            n: 0,
            failed: None,
        }
    }

    fn flush(&mut self) -> postcard::Result<()> {
        let chunk = self
            .buf
            .get(..self.n)
            .ok_or(postcard::Error::SerializeBufferFull)?;
        if let Some(crc) = self.crc.as_mut() {
            crc.digest(chunk);
        }
        if let Some(f) = self.flash.as_deref_mut() {
            if let Err(e) = f.write(self.at, chunk) {
                self.failed = Some(e);
                return Err(postcard::Error::SerializeBufferFull);
            }
        }
        self.at = self.at.saturating_add(self.n as u32);
        self.n = 0;
        Ok(())
    }

    /// Encodes `value` through the writer.
    fn encode<T: Serialize>(&mut self, value: &T) -> postcard::Result<()> {
        postcard::serialize_with_flavor(value, &mut *self)?;
        self.flush()
    }
}

impl<F: Flash> postcard::ser_flavors::Flavor for &mut Writer<'_, F> {
    type Output = ();

    fn try_push(&mut self, b: u8) -> postcard::Result<()> {
        if self.len >= self.limit {
            return Err(postcard::Error::SerializeBufferFull);
        }
        *self
            .buf
            .get_mut(self.n)
            .ok_or(postcard::Error::SerializeBufferFull)? = b;
        self.n = self.n.saturating_add(1);
        self.len = self.len.saturating_add(1);
        if self.n == WINDOW {
            self.flush()?;
        }
        Ok(())
    }

    fn finalize(self) -> postcard::Result<()> {
        Ok(())
    }
}

/// The length of `value` encoded and the slot's CRC-32 (over seq, len and payload), or `None`
/// when it takes more than `limit` bytes. Encodes twice: the CRC covers the length first.
fn measure<T: Serialize, F: Flash>(value: &T, limit: u32, seq: u32) -> Option<(u32, u32)> {
    let mut count = Writer::<F>::new(limit);
    count.encode(value).ok()?;
    let mut crc = crate::crc::Crc32::ieee();
    crc.digest(&seq.to_le_bytes());
    crc.digest(&count.len.to_le_bytes());
    let mut sum = Writer::<F> {
        crc: Some(crc),
        ..Writer::new(limit)
    };
    sum.encode(value).ok()?;
    Some((count.len, sum.crc?.get()))
}

/// Saves the board record into the slot not holding the newest intact copy (or over the
/// newest, when only the older one decodes: the copy a load returns is never the one
/// erased), encoding straight into the flash. Returns the new save counter.
pub fn save_board<F: Flash>(
    flash: &mut F,
    region: &AbRegion,
    record: &BoardRecordRef,
) -> Result<u32, StorageError<F::Error>> {
    let [newest, older] = candidates(flash, region)?;
    let mut keep = newest;
    if let (Some((addr, h)), Some(_)) = (newest, older) {
        if !walk_slot(flash, addr, h, &mut Check)? {
            keep = older;
        }
    }
    let seq = newest.map_or(1, |(_, h)| h.seq.wrapping_add(1));
    let limit = region.slot_len.saturating_sub(HEADER_LEN);
    let (len, crc) = measure::<_, F>(record, limit, seq).ok_or(StorageError::TooLarge)?;
    let target = match keep {
        Some((addr, _)) if addr == region.slot_a => region.slot_b,
        _ => region.slot_a,
    };
    flash.erase_sector(target).map_err(StorageError::Flash)?;
    let mut w = Writer {
        flash: Some(&mut *flash),
        at: target.saturating_add(HEADER_LEN),
        ..Writer::new(limit)
    };
    if w.encode(record).is_err() || w.len != len {
        return Err(w.failed.map_or(StorageError::TooLarge, StorageError::Flash));
    }
    let mut header = [0u8; HEADER_LEN as usize];
    for (dst, word) in header
        .chunks_exact_mut(4)
        .zip([region.magic, seq, len, crc])
    {
        dst.copy_from_slice(&word.to_le_bytes());
    }
    // The header last: until it is complete the slot is not valid.
    flash.write(target, &header).map_err(StorageError::Flash)?;
    Ok(seq)
}
