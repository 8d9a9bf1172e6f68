//! Records read back from flash (`common::storage`): a flash image with any bytes, in which
//! the fuzzer may place records with a good or bad magic, sequence number, length and CRC,
//! and a payload that is any bytes or a well-formed parameter or mission record; then loads,
//! saves (some cut by a power loss at any operation) and loads again, on the SITL's layout.
//!
//! Asserted: loading never panics and gives the same answer twice; loaded parameters pass
//! every definition and stage rule, and each record is counted once (loaded, unknown or
//! rejected); whatever the flash held, a save followed by a load returns what was saved, and a
//! save cut at any operation leaves what was there before or the new record, never anything
//! else.

use arbitrary::{Arbitrary, Unstructured};
use common::navigation::plan::{MissionItem, MissionStore};
use common::params::store::{ParamImage, ParamRecord};
use common::params::ParamStore;
use common::storage::{
    load, load_missions, load_params, save_missions, save_params, AbRegion, RamFlash, StorageError,
    MISSION_MAGIC, PARAMS_MAGIC,
};
use common::vehicle::params::REGISTRY;

use crate::gcs::ParamValue;

/// The SITL's layout (`firmware::sitl::FileStorage`): four 16 KiB sectors.
const SECTOR: u32 = 16 * 1024;
const BYTES: usize = 4 * SECTOR as usize;
type Dev = RamFlash<BYTES>;
const PARAMS: AbRegion = AbRegion {
    magic: PARAMS_MAGIC,
    slot_a: 0,
    slot_b: SECTOR,
    slot_len: SECTOR,
};
const MISSIONS: AbRegion = AbRegion {
    magic: MISSION_MAGIC,
    slot_a: 2 * SECTOR,
    slot_b: 3 * SECTOR,
    slot_len: SECTOR,
};

/// A slot's contents as the fuzzer writes them.
#[derive(Arbitrary, Debug)]
pub struct Slot {
    magic: bool,
    seq: u32,
    /// The length field: the payload's own, or any.
    len: Option<u32>,
    /// The CRC field: the right one, or any.
    crc: Option<u32>,
    payload: Payload,
}

#[derive(Arbitrary, Debug)]
pub enum Payload {
    Bytes(Vec<u8>),
    Params(Vec<(u16, Option<[u8; 16]>, ParamValue)>),
    Missions(Vec<(u8, MissionItemIn)>),
}

#[derive(Arbitrary, Debug, Clone, Copy)]
pub struct MissionItemIn {
    params: [u32; 4],
    x: i32,
    y: i32,
    z: u32,
    command: u16,
    frame: u8,
    autocontinue: bool,
}

/// What happens after the first load.
#[derive(Arbitrary, Debug)]
pub enum Then {
    SaveParams {
        set: Vec<(u16, ParamValue)>,
        cut: Option<u16>,
    },
    SaveMissions {
        items: Vec<(u8, MissionItemIn)>,
        cut: Option<u16>,
    },
    Flip {
        at: u16,
        xor: u8,
    },
}

#[derive(Arbitrary, Debug)]
pub struct Input {
    image: Vec<u8>,
    slots: [Option<Slot>; 4],
    then: Vec<Then>,
}

fn missions(items: &[(u8, MissionItemIn)]) -> MissionStore {
    let mut m = MissionStore::default();
    for (list, it) in items {
        let item = MissionItem {
            params: it.params,
            x: it.x,
            y: it.y,
            z: it.z,
            command: it.command,
            frame: it.frame,
            autocontinue: it.autocontinue,
        };
        let _ = match list % 3 {
            0 => m.mission.push(item),
            1 => m.fence.push(item),
            _ => m.rally.push(item),
        };
    }
    m
}

fn payload(p: &Payload, store: &ParamStore) -> Vec<u8> {
    let mut buf = vec![0u8; SECTOR as usize];
    match p {
        Payload::Bytes(b) => b.clone(),
        Payload::Params(recs) => {
            let mut image = ParamImage::new();
            for (i, raw, v) in recs {
                let index = usize::from(*i) % store.len();
                let name = match raw {
                    Some(bytes) => String::from_utf8_lossy(bytes).into_owned(),
                    None => store.def(index).map_or("", |d| d.name).to_string(),
                };
                let Ok(name) =
                    heapless::String::try_from(name.get(..name.len().min(16)).unwrap_or(""))
                else {
                    continue;
                };
                let _ = image.push(ParamRecord {
                    name,
                    value: v.get(store, index),
                });
            }
            postcard::to_slice(&image, &mut buf).map_or_else(|_| Vec::new(), |s| s.to_vec())
        }
        Payload::Missions(items) => postcard::to_slice(&missions(items), &mut buf)
            .map_or_else(|_| Vec::new(), |s| s.to_vec()),
    }
}

/// The CRC-32 of a slot, as `common::storage` computes it.
fn crc(seq: u32, len: u32, payload: &[u8]) -> u32 {
    let mut c = crc_any::CRCu32::crc32();
    c.digest(&seq.to_le_bytes());
    c.digest(&len.to_le_bytes());
    c.digest(payload);
    c.get_crc()
}

fn place(image: &mut [u8], at: usize, slot: &Slot, magic: u32, store: &ParamStore) {
    let body = payload(&slot.payload, store);
    let body = &body[..body.len().min(SECTOR as usize - 16)];
    let len = slot.len.unwrap_or(body.len() as u32);
    let m = if slot.magic { magic } else { magic ^ 1 };
    let c = slot.crc.unwrap_or_else(|| crc(slot.seq, len, body));
    let mut h = Vec::new();
    for w in [m, slot.seq, len, c] {
        h.extend_from_slice(&w.to_le_bytes());
    }
    image[at..at + 16].copy_from_slice(&h);
    image[at + 16..at + 16 + body.len()].copy_from_slice(body);
}

type Params = Result<Option<Vec<u32>>, StorageError<common::storage::RamFlashError>>;

/// The parameter store after loading `flash` into a fresh one, as bit patterns.
fn load_params_bits(flash: &mut Dev) -> Params {
    let mut store = ParamStore::new(REGISTRY);
    let mut scratch = vec![0u8; SECTOR as usize];
    let report = load_params(flash, &PARAMS, &mut store, &mut scratch)?;
    crate::watch::check_store(&store);
    if let Some(r) = report {
        let image = load::<_, ParamImage>(flash, &PARAMS, &mut scratch)?.expect("loaded twice");
        let counted = usize::from(r.loaded) + usize::from(r.unknown) + usize::from(r.rejected);
        assert_eq!(
            counted,
            image.value.len(),
            "each record counted once: {r:?}"
        );
    }
    Ok(report.map(|_| {
        (0..store.len())
            .filter_map(|i| store.value(i))
            .map(f32::to_bits)
            .collect()
    }))
}

type Missions = Result<Option<MissionStore>, StorageError<common::storage::RamFlashError>>;

fn load_missions_now(flash: &mut Dev) -> Missions {
    let mut scratch = vec![0u8; SECTOR as usize];
    load_missions(flash, &MISSIONS, &mut scratch)
}

/// Runs one input.
pub fn run(data: &[u8]) {
    let Ok(input) = Input::arbitrary_take_rest(Unstructured::new(data)) else {
        return;
    };
    if crate::trace() {
        eprintln!("{input:?}");
    }
    let store = ParamStore::new(REGISTRY);
    let mut image = vec![0xFFu8; BYTES];
    let n = input.image.len().min(BYTES);
    image[..n].copy_from_slice(&input.image[..n]);
    let regions = [
        (PARAMS.slot_a, PARAMS_MAGIC),
        (PARAMS.slot_b, PARAMS_MAGIC),
        (MISSIONS.slot_a, MISSION_MAGIC),
        (MISSIONS.slot_b, MISSION_MAGIC),
    ];
    for (slot, (at, magic)) in input.slots.iter().zip(regions) {
        if let Some(s) = slot {
            place(&mut image, at as usize, s, magic, &store);
        }
    }
    let mut flash = Dev::from_image(&image, SECTOR);

    let mut params = load_params_bits(&mut flash);
    assert_eq!(
        load_params_bits(&mut flash),
        params,
        "the same flash loads the same"
    );
    let mut plan = load_missions_now(&mut flash);
    assert_eq!(
        load_missions_now(&mut flash),
        plan,
        "the same flash loads the same"
    );

    for t in input.then.iter().take(8) {
        match t {
            Then::SaveParams { set, cut } => {
                let mut s = ParamStore::new(REGISTRY);
                for (i, v) in set {
                    let i = usize::from(*i) % s.len();
                    let value = v.get(&s, i);
                    let _ = s.set_index(i, value);
                }
                let new: Vec<u32> = (0..s.len())
                    .filter_map(|i| s.value(i))
                    .map(f32::to_bits)
                    .collect();
                let mut scratch = vec![0u8; SECTOR as usize];
                let mut torn = flash.clone();
                torn.cut_after(cut.map(usize::from));
                let saved = save_params(&mut torn, &PARAMS, &mut s, &mut scratch);
                torn.cut_after(None);
                let after = load_params_bits(&mut torn);
                match saved {
                    Ok(_) => assert_eq!(after, Ok(Some(new)), "a save then a load returns it"),
                    Err(_) => assert!(
                        after == params || after == Ok(Some(new)),
                        "a torn save left something else: {after:?}"
                    ),
                }
                params = after;
                flash = torn;
            }
            Then::SaveMissions { items, cut } => {
                let m = missions(items);
                let mut scratch = vec![0u8; SECTOR as usize];
                let mut torn = flash.clone();
                torn.cut_after(cut.map(usize::from));
                let saved = save_missions(&mut torn, &MISSIONS, &m, &mut scratch);
                torn.cut_after(None);
                let after = load_missions_now(&mut torn);
                match saved {
                    Ok(_) => assert_eq!(after, Ok(Some(m)), "a save then a load returns it"),
                    Err(_) => assert!(
                        after == plan || after == Ok(Some(m)),
                        "a torn save left something else: {after:?}"
                    ),
                }
                plan = after;
                flash = torn;
            }
            Then::Flip { at, xor } => {
                // Flash wears: a bit flips anywhere. Loading still never panics.
                let mut bytes = flash.bytes().to_vec();
                let i = usize::from(*at) * 4 % BYTES;
                bytes[i] ^= xor;
                flash = Dev::from_image(&bytes, SECTOR);
                params = load_params_bits(&mut flash);
                plan = load_missions_now(&mut flash);
            }
        }
    }
}
