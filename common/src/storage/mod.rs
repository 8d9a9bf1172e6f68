//! Power-cut-safe persistence of parameters and missions in flash.
//!
//! Each record (the parameters, the mission lists) lives in an [`AbRegion`]: two slots of one
//! flash sector each. A save goes to the slot that does *not* hold the newest good copy, so the
//! newest good copy is never touched while it is the only one. A slot is
//!
//! ```text
//! offset 0   magic   u32 LE   which record this is (and the format version)
//!        4   seq     u32 LE   save counter; the higher (wrapping) valid one wins
//!        8   len     u32 LE   payload length
//!       12   crc     u32 LE   CRC-32 of seq, len and payload
//!       16   payload          postcard encoding of the record
//! ```
//!
//! and is written in this order: erase, payload, header. Until the last header byte is
//! written the slot fails its magic or CRC check, so a power cut at any point loses at most
//! the save in progress: loading yields the old record or the new one, never a mixture.
//!
//! Parameters are stored by name ([`ParamImage`]), so a firmware whose table is reordered or
//! extended still loads them; only values that differ from their default are stored.

// Counts, lengths and offsets here come from outside: every operation on them is checked.
#![cfg_attr(not(test), deny(clippy::arithmetic_side_effects))]

use serde::{de::DeserializeOwned, Serialize};

use crate::navigation::plan::{
    MissionItem, MissionStore, FENCE_CAPACITY, MISSION_CAPACITY, RALLY_CAPACITY,
};
use crate::params::store::{
    ImportReport, ParamExport, ParamImage, ParamRecord, ParamStore, MAX_PARAMS,
};

/// A flash device (or a model of one). Erased bytes read 0xFF; a write can only clear bits.
pub trait Flash {
    /// Error of the device.
    type Error: core::fmt::Debug;
    /// Erases the whole sector that starts at `addr`.
    fn erase_sector(&mut self, addr: u32) -> Result<(), Self::Error>;
    /// Programs `data` at `addr` (already erased).
    fn write(&mut self, addr: u32, data: &[u8]) -> Result<(), Self::Error>;
    /// Reads `buf.len()` bytes at `addr`.
    fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), Self::Error>;
}

/// Two slots holding one record. Each slot is one whole sector of `slot_len` bytes (on the
/// STM32F405, for example, two of its 16 KiB sectors 1..3 for the parameters and the 16 KiB
/// sector 3 with the 64 KiB sector 4, using its first 16 KiB, for the missions).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AbRegion {
    /// Tells the records apart (and their format version): a slot with another magic is
    /// never loaded.
    pub magic: u32,
    /// Start of slot A (a sector start).
    pub slot_a: u32,
    /// Start of slot B (a sector start).
    pub slot_b: u32,
    /// Usable bytes of each slot, header included.
    pub slot_len: u32,
}

/// Magic of the parameter record, format 1.
pub const PARAMS_MAGIC: u32 = 0x5052_4d31; // "PRM1"
/// Magic of the mission record, format 1.
pub const MISSION_MAGIC: u32 = 0x4d53_4e31; // "MSN1"
/// Magic of the signing record (MAVLink 2 signing key and timestamp), format 1.
pub const SIGNING_MAGIC: u32 = 0x5347_4e31; // "SGN1"

/// The MAVLink 2 signing key and the signing clock when it was saved: a new boot carries on
/// from that timestamp, so its frames are never older than the ones it signed before.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct SigningRecord {
    /// The secret key; `None`: signing off.
    #[serde(deserialize_with = "key::deserialize")]
    pub key: Option<[u8; 32]>,
    /// Signing clock, 10 us units since 2015-01-01.
    pub timestamp: u64,
}

/// The signing key read back as serde's `[u8; 32]` reads it (a tuple of 32 bytes: the same
/// record), by a loop: serde's own reading of an array is its 32 elements unrolled, 0.5 KB of
/// the MCU image's boot code.
mod key {
    use serde::de::{Deserialize, Deserializer, Error, SeqAccess, Visitor};

    /// The key's 32 bytes.
    struct Key([u8; 32]);

    impl<'de> Deserialize<'de> for Key {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            d.deserialize_tuple(32, KeyVisitor)
        }
    }

    struct KeyVisitor;

    impl<'de> Visitor<'de> for KeyVisitor {
        type Value = Key;

        fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
            f.write_str("an array of length 32")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Key, A::Error> {
            let mut key = [0u8; 32];
            for (i, b) in key.iter_mut().enumerate() {
                *b = seq
                    .next_element()?
                    .ok_or_else(|| A::Error::invalid_length(i, &self))?;
            }
            Ok(Key(key))
        }
    }

    /// `Option<[u8; 32]>` as serde derives its reading, the array by [`Key`].
    pub(super) fn deserialize<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<Option<[u8; 32]>, D::Error> {
        Ok(Option::<Key>::deserialize(d)?.map(|k| k.0))
    }
}

const HEADER_LEN: u32 = 16;

/// Why a save or load failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StorageError<E> {
    /// The device failed.
    Flash(E),
    /// The record does not fit the scratch buffer or the slot.
    TooLarge,
    /// Both copies are intact but neither decodes as this record (format changed).
    Decode,
}

impl<E: core::fmt::Display> core::fmt::Display for StorageError<E> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            StorageError::Flash(e) => write!(f, "flash failed: {e}"),
            StorageError::TooLarge => f.write_str("record too large for its slot"),
            StorageError::Decode => f.write_str("record does not decode (format changed)"),
        }
    }
}

impl<E: core::error::Error + 'static> core::error::Error for StorageError<E> {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            StorageError::Flash(e) => Some(e),
            _ => None,
        }
    }
}

/// A record loaded from flash.
#[derive(Clone, Debug, PartialEq)]
pub struct Loaded<T> {
    /// The record.
    pub value: T,
    /// Its save counter.
    pub seq: u32,
}

#[derive(Clone, Copy, Debug)]
struct Header {
    seq: u32,
    len: u32,
}

fn crc_of<F: Flash>(
    flash: &mut F,
    addr: u32,
    seq: u32,
    len: u32,
) -> Result<u32, StorageError<F::Error>> {
    let mut crc = crate::crc::Crc32::ieee();
    crc.digest(&seq.to_le_bytes());
    crc.digest(&len.to_le_bytes());
    let mut chunk = [0u8; 64];
    let mut done = 0u32;
    while done < len {
        let n = len.saturating_sub(done).min(chunk.len() as u32) as usize;
        let buf = chunk.get_mut(..n).ok_or(StorageError::TooLarge)?;
        let at = addr.saturating_add(HEADER_LEN).saturating_add(done);
        flash.read(at, buf).map_err(StorageError::Flash)?;
        crc.digest(buf);
        done = done.saturating_add(n as u32);
    }
    Ok(crc.get())
}

/// The header of a slot if the slot holds a complete, intact record of this region.
fn check_slot<F: Flash>(
    flash: &mut F,
    region: &AbRegion,
    addr: u32,
) -> Result<Option<Header>, StorageError<F::Error>> {
    let mut h = [0u8; HEADER_LEN as usize];
    flash.read(addr, &mut h).map_err(StorageError::Flash)?;
    let mut words = h
        .chunks_exact(4)
        .filter_map(|w| <[u8; 4]>::try_from(w).ok())
        .map(u32::from_le_bytes);
    let mut word = || words.next().unwrap_or(0);
    let (magic, seq, len, crc) = (word(), word(), word(), word());
    if magic != region.magic || len > region.slot_len.saturating_sub(HEADER_LEN) {
        return Ok(None);
    }
    if crc_of(flash, addr, seq, len)? != crc {
        return Ok(None);
    }
    Ok(Some(Header { seq, len }))
}

/// Whether save counter `a` is newer than `b` (wrapping).
fn newer(a: u32, b: u32) -> bool {
    (a.wrapping_sub(b) as i32) > 0
}

/// The intact slots, newest first.
type Candidates = [Option<(u32, Header)>; 2];

fn candidates<F: Flash>(
    flash: &mut F,
    region: &AbRegion,
) -> Result<Candidates, StorageError<F::Error>> {
    let a = check_slot(flash, region, region.slot_a)?.map(|h| (region.slot_a, h));
    let b = check_slot(flash, region, region.slot_b)?.map(|h| (region.slot_b, h));
    Ok(match (a, b) {
        (Some(x), Some(y)) if newer(y.1.seq, x.1.seq) => [Some(y), Some(x)],
        (Some(x), Some(y)) => [Some(x), Some(y)],
        (Some(x), None) | (None, Some(x)) => [Some(x), None],
        (None, None) => [None, None],
    })
}

/// Saves `value` into the slot not holding the newest intact copy; `scratch` must hold the
/// encoded record. Returns the new save counter.
pub fn save<F: Flash, T: Serialize>(
    flash: &mut F,
    region: &AbRegion,
    value: &T,
    scratch: &mut [u8],
) -> Result<u32, StorageError<F::Error>> {
    save_keeping(flash, region, value, scratch, |_| true)
}

/// As [`save`], keeping the copy that loads: `decodes` says whether a payload loads as the
/// record. When the newest intact copy does not (a format the firmware no longer reads) and
/// the older one does, the save goes over the newest, so a power cut during it still leaves
/// the copy [`load`] returns.
fn save_keeping<F: Flash, T: Serialize>(
    flash: &mut F,
    region: &AbRegion,
    value: &T,
    scratch: &mut [u8],
    decodes: impl Fn(&[u8]) -> bool,
) -> Result<u32, StorageError<F::Error>> {
    let [newest, older] = candidates(flash, region)?;
    let mut keep = newest;
    if let (Some((addr, h)), Some(_)) = (newest, older) {
        let buf = scratch
            .get_mut(..h.len as usize)
            .ok_or(StorageError::TooLarge)?;
        flash
            .read(addr.saturating_add(HEADER_LEN), buf)
            .map_err(StorageError::Flash)?;
        if !decodes(buf) {
            keep = older;
        }
    }
    let payload = postcard::to_slice(value, scratch).map_err(|_| StorageError::TooLarge)?;
    let len = payload.len() as u32;
    if len > region.slot_len.saturating_sub(HEADER_LEN) {
        return Err(StorageError::TooLarge);
    }
    let seq = newest.map_or(1, |(_, h)| h.seq.wrapping_add(1));
    let target = match keep {
        Some((addr, _)) if addr == region.slot_a => region.slot_b,
        _ => region.slot_a,
    };
    let mut crc = crate::crc::Crc32::ieee();
    crc.digest(&seq.to_le_bytes());
    crc.digest(&len.to_le_bytes());
    crc.digest(payload);
    let mut header = [0u8; HEADER_LEN as usize];
    for (dst, w) in header
        .chunks_exact_mut(4)
        .zip([region.magic, seq, len, crc.get()])
    {
        dst.copy_from_slice(&w.to_le_bytes());
    }
    flash.erase_sector(target).map_err(StorageError::Flash)?;
    flash
        .write(target.saturating_add(HEADER_LEN), payload)
        .map_err(StorageError::Flash)?;
    // The header last: until it is complete the slot is not valid.
    flash.write(target, &header).map_err(StorageError::Flash)?;
    Ok(seq)
}

/// Loads the newest intact copy that decodes (falling back to the older one), `None` when
/// neither slot holds one.
pub fn load<F: Flash, T: DeserializeOwned>(
    flash: &mut F,
    region: &AbRegion,
    scratch: &mut [u8],
) -> Result<Option<Loaded<T>>, StorageError<F::Error>> {
    let mut any = false;
    for (addr, h) in candidates(flash, region)?.into_iter().flatten() {
        any = true;
        let Some(buf) = scratch.get_mut(..h.len as usize) else {
            continue;
        };
        flash
            .read(addr.saturating_add(HEADER_LEN), buf)
            .map_err(StorageError::Flash)?;
        if let Ok(value) = postcard::from_bytes::<T>(buf) {
            return Ok(Some(Loaded { value, seq: h.seq }));
        }
    }
    if any {
        Err(StorageError::Decode)
    } else {
        Ok(None)
    }
}

/// Saves the parameters that differ from their defaults, by name, and marks the store saved.
/// Streams from the store: no [`ParamImage`] is built.
pub fn save_params<F: Flash>(
    flash: &mut F,
    region: &AbRegion,
    store: &mut ParamStore,
    scratch: &mut [u8],
) -> Result<u32, StorageError<F::Error>> {
    let decodes = |b: &[u8]| postcard::from_bytes::<Walk<ParamRecord, MAX_PARAMS>>(b).is_ok();
    let seq = save_keeping(flash, region, &ParamExport(store), scratch, decodes)?;
    store.mark_saved();
    Ok(seq)
}

/// Loads saved parameters into `store` by name; `None` when nothing is saved. Decodes into
/// a [`ParamImage`] first (8 KiB of stack: meant for start-up), so a copy that does not
/// decode changes nothing.
pub fn load_params<F: Flash>(
    flash: &mut F,
    region: &AbRegion,
    store: &mut ParamStore,
    scratch: &mut [u8],
) -> Result<Option<ImportReport>, StorageError<F::Error>> {
    Ok(load::<F, ParamImage>(flash, region, scratch)?.map(|l| store.import(&l.value)))
}

/// Saves the mission, fence and rally lists.
pub fn save_missions<F: Flash>(
    flash: &mut F,
    region: &AbRegion,
    store: &MissionStore,
    scratch: &mut [u8],
) -> Result<u32, StorageError<F::Error>> {
    let decodes = |b: &[u8]| postcard::from_bytes::<PlanWalk>(b).is_ok();
    save_keeping(flash, region, store, scratch, decodes)
}

/// Decodes a sequence of at most `N` `E`s without keeping them: whether a record loads, in
/// the stack of one element.
struct Walk<E, const N: usize>(core::marker::PhantomData<E>);

impl<'de, E: serde::Deserialize<'de>, const N: usize> serde::Deserialize<'de> for Walk<E, N> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_seq(Walk(core::marker::PhantomData))
    }
}

impl<'de, E: serde::Deserialize<'de>, const N: usize> serde::de::Visitor<'de> for Walk<E, N> {
    type Value = Self;
    fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
        write!(f, "at most {N} elements")
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut s: A) -> Result<Self, A::Error> {
        for _ in 0..N {
            if s.next_element::<E>()?.is_none() {
                return Ok(self);
            }
        }
        match s.next_element::<E>()? {
            None => Ok(self),
            Some(_) => Err(serde::de::Error::invalid_length(N.saturating_add(1), &self)),
        }
    }
}

/// [`MissionStore`]'s encoding, walked.
#[derive(serde::Deserialize)]
struct PlanWalk {
    _mission: Walk<MissionItem, MISSION_CAPACITY>,
    _fence: Walk<MissionItem, FENCE_CAPACITY>,
    _rally: Walk<MissionItem, RALLY_CAPACITY>,
}

/// Loads the mission, fence and rally lists; `None` when nothing is saved.
pub fn load_missions<F: Flash>(
    flash: &mut F,
    region: &AbRegion,
    scratch: &mut [u8],
) -> Result<Option<MissionStore>, StorageError<F::Error>> {
    Ok(load::<F, MissionStore>(flash, region, scratch)?.map(|l| l.value))
}

/// Magic of the board record (parameters, plan and signing key in one record), format 1.
pub const BOARD_MAGIC: u32 = 0x424f_5231; // "BOR1"

/// Everything a board keeps across resets, in one record of one [`AbRegion`]: the
/// parameters that differ from their defaults (by name), the mission, fence and rally lists,
/// and the signing key with its clock. One record in two sectors is what a small flash can
/// spare (the STM32F405's 16 KiB sectors 1 and 2).
#[derive(Serialize)]
pub struct BoardRecordRef<'a> {
    /// The parameters, streamed from the store.
    pub params: ParamExport<'a>,
    /// The plan.
    pub plan: &'a MissionStore,
    /// The signing key.
    pub signing: SigningRecord,
}

/// Error of [`RamFlash`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RamFlashError {
    /// Address outside the device or not a sector start.
    Address,
    /// The simulated power is off.
    PowerLost,
}

impl core::fmt::Display for RamFlashError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            RamFlashError::Address => "address outside the device or not a sector start",
            RamFlashError::PowerLost => "power lost",
        })
    }
}

impl core::error::Error for RamFlashError {}

/// Flash in RAM with NOR semantics (erase to 0xFF, writes clear bits), for SITL and tests.
/// It can lose power after a given number of operations (each erase and each byte written is
/// one): the operation hit by the cut is torn (half a sector erased, a byte half programmed)
/// and nothing after it happens.
#[derive(Clone, Debug)]
pub struct RamFlash<const N: usize> {
    mem: [u8; N],
    sector: u32,
    budget: Option<usize>,
    ops: usize,
}

impl<const N: usize> RamFlash<N> {
    /// Erased flash of `N` bytes in sectors of `sector` bytes.
    pub fn new(sector: u32) -> Self {
        Self {
            mem: [0xff; N],
            sector: sector.max(1),
            budget: None,
            ops: 0,
        }
    }

    /// A device holding `image` (a saved copy of [`RamFlash::bytes`]); missing bytes read as
    /// erased, extra ones are ignored. SITL keeps its "flash" in a file this way.
    pub fn from_image(image: &[u8], sector: u32) -> Self {
        let mut f = Self::new(sector);
        for (m, b) in f.mem.iter_mut().zip(image) {
            *m = *b;
        }
        f
    }

    /// Cuts the power during the `ops`-th operation from now: `ops - 1` complete, that one is
    /// torn, none after it happens (`Some(0)`: already off; `None`: power stays on).
    pub fn cut_after(&mut self, ops: Option<usize>) {
        self.budget = ops;
    }

    /// Operations done since creation.
    pub fn ops(&self) -> usize {
        self.ops
    }

    /// The raw contents.
    pub fn bytes(&self) -> &[u8] {
        &self.mem
    }

    /// Consumes one operation; `Ok(true)` if it completes, `Ok(false)` if the cut tears it.
    fn spend(&mut self) -> Result<bool, RamFlashError> {
        self_spend(&mut self.budget, &mut self.ops)
    }
}

impl<const N: usize> Flash for RamFlash<N> {
    type Error = RamFlashError;

    fn erase_sector(&mut self, addr: u32) -> Result<(), RamFlashError> {
        if !addr.is_multiple_of(self.sector) {
            return Err(RamFlashError::Address);
        }
        let (start, len) = (addr as usize, self.sector as usize);
        let range = self
            .mem
            .get_mut(start..start.saturating_add(len))
            .ok_or(RamFlashError::Address)?;
        let whole = self_spend(&mut self.budget, &mut self.ops)?;
        let end = if whole { len } else { len / 2 };
        range.iter_mut().take(end).for_each(|b| *b = 0xff);
        if whole {
            Ok(())
        } else {
            Err(RamFlashError::PowerLost)
        }
    }

    fn write(&mut self, addr: u32, data: &[u8]) -> Result<(), RamFlashError> {
        let start = addr as usize;
        if self
            .mem
            .get(start..start.saturating_add(data.len()))
            .is_none()
        {
            return Err(RamFlashError::Address);
        }
        for (i, d) in data.iter().enumerate() {
            let whole = self.spend()?;
            if let Some(b) = self.mem.get_mut(start.saturating_add(i)) {
                // A torn byte gets only its upper nibble programmed.
                *b &= if whole { *d } else { *d | 0x0f };
            }
            if !whole {
                return Err(RamFlashError::PowerLost);
            }
        }
        Ok(())
    }

    fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), RamFlashError> {
        let start = addr as usize;
        let src = self
            .mem
            .get(start..start.saturating_add(buf.len()))
            .ok_or(RamFlashError::Address)?;
        buf.copy_from_slice(src);
        Ok(())
    }
}

/// [`RamFlash::spend`] on split borrows (the erase holds a borrow of the memory).
fn self_spend(budget: &mut Option<usize>, ops: &mut usize) -> Result<bool, RamFlashError> {
    match *budget {
        Some(0) => Err(RamFlashError::PowerLost),
        Some(1) => {
            *budget = Some(0);
            *ops = ops.saturating_add(1);
            Ok(false)
        }
        Some(n) => {
            *budget = Some(n.saturating_sub(1));
            *ops = ops.saturating_add(1);
            Ok(true)
        }
        None => {
            *ops = ops.saturating_add(1);
            Ok(true)
        }
    }
}

pub mod f4;
pub mod flight_log;
pub mod stream;

#[cfg(test)]
mod tests;
