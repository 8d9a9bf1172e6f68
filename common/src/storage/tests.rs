//! Persistence tests, including a power cut at every operation of a save.

extern crate std;

use serde::{Deserialize, Serialize};

use super::stream::{load_board_into, save_board};
use super::*;
use crate::navigation::plan::{MissionItem, MissionStore};
use crate::param;
use crate::params::store::ParamExport;
use crate::params::{Group, ParamDef};

const SECTOR: u32 = 1024;
type Dev = RamFlash<4096>;

const REGION: AbRegion = AbRegion {
    magic: 0x5445_5354,
    slot_a: 0,
    slot_b: SECTOR,
    slot_len: SECTOR,
};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Rec {
    gen: u32,
    data: heapless::Vec<u8, 200>,
}

fn rec(gen: u32, len: usize) -> Rec {
    let mut data = heapless::Vec::new();
    for i in 0..len {
        data.push((i as u32 * 7 + gen * 13) as u8).unwrap();
    }
    Rec { gen, data }
}

#[test]
fn empty_flash_loads_nothing() {
    let mut f = Dev::new(SECTOR);
    let mut scratch = [0u8; 512];
    assert_eq!(load::<_, Rec>(&mut f, &REGION, &mut scratch).unwrap(), None);
}

#[test]
fn saves_alternate_slots_and_newest_wins() {
    let mut f = Dev::new(SECTOR);
    let mut scratch = [0u8; 512];
    for g in 1..=5 {
        assert_eq!(save(&mut f, &REGION, &rec(g, 50), &mut scratch).unwrap(), g);
        let l = load::<_, Rec>(&mut f, &REGION, &mut scratch)
            .unwrap()
            .unwrap();
        assert_eq!(l.value, rec(g, 50));
        assert_eq!(l.seq, g);
    }
    // Both slots hold a record (the two newest).
    assert_eq!(&f.bytes()[0..4], &REGION.magic.to_le_bytes());
    assert_eq!(
        &f.bytes()[SECTOR as usize..SECTOR as usize + 4],
        &REGION.magic.to_le_bytes()
    );
}

#[test]
fn power_cut_at_every_operation_keeps_old_or_new() {
    let mut scratch = [0u8; 512];
    // Two complete generations, then the third cut at every erase and byte.
    let mut base = Dev::new(SECTOR);
    save(&mut base, &REGION, &rec(1, 120), &mut scratch).unwrap();
    save(&mut base, &REGION, &rec(2, 80), &mut scratch).unwrap();
    let new = rec(3, 150);
    let mut probe = base.clone();
    let before = probe.ops();
    save(&mut probe, &REGION, &new, &mut scratch).unwrap();
    let total = probe.ops() - before;
    assert!(total > 150, "erase + payload + header");
    let (mut old_seen, mut new_seen) = (0, 0);
    // `cut` = k: k - 1 operations complete, the k-th is torn (k = 0: no power at all); k =
    // total + 1 lets the save finish.
    for cut in 0..=total + 1 {
        let mut f = base.clone();
        f.cut_after(Some(cut));
        let r = save(&mut f, &REGION, &new, &mut scratch);
        assert_eq!(r.is_ok(), cut > total, "cut {cut}");
        // Power back: load must give a complete record, the old one unless the save finished.
        f.cut_after(None);
        let got = load::<_, Rec>(&mut f, &REGION, &mut scratch)
            .unwrap()
            .unwrap();
        if cut > total {
            assert_eq!(got.value, new, "cut {cut}");
            new_seen += 1;
        } else {
            assert_eq!(got.value, rec(2, 80), "cut {cut}");
            old_seen += 1;
        }
        // A later save recovers.
        save(&mut f, &REGION, &rec(4, 10), &mut scratch).unwrap();
        assert_eq!(
            load::<_, Rec>(&mut f, &REGION, &mut scratch)
                .unwrap()
                .unwrap()
                .value,
            rec(4, 10)
        );
    }
    assert_eq!((old_seen, new_seen), (total + 1, 1));
}

#[test]
fn power_cut_on_first_save_loads_nothing_or_new() {
    let mut scratch = [0u8; 512];
    let new = rec(1, 30);
    for cut in 0..=60 {
        let mut f = Dev::new(SECTOR);
        f.cut_after(Some(cut));
        let done = save(&mut f, &REGION, &new, &mut scratch).is_ok();
        f.cut_after(None);
        let got = load::<_, Rec>(&mut f, &REGION, &mut scratch).unwrap();
        assert_eq!(
            got.map(|l| l.value),
            if done { Some(new.clone()) } else { None }
        );
    }
}

#[test]
fn corrupted_newest_falls_back_and_other_magic_ignored() {
    let mut scratch = [0u8; 512];
    let mut f = Dev::new(SECTOR);
    save(&mut f, &REGION, &rec(1, 40), &mut scratch).unwrap();
    save(&mut f, &REGION, &rec(2, 40), &mut scratch).unwrap(); // in slot B
                                                               // Flip a payload bit of slot B (a write can clear bits).
    f.write(SECTOR + 20, &[0x00]).unwrap();
    assert_eq!(
        load::<_, Rec>(&mut f, &REGION, &mut scratch)
            .unwrap()
            .unwrap()
            .value,
        rec(1, 40)
    );
    let other = AbRegion { magic: 1, ..REGION };
    assert_eq!(load::<_, Rec>(&mut f, &other, &mut scratch).unwrap(), None);
    // Too large for the slot is refused before anything is erased.
    let mut big = [0u8; 4096];
    let huge: heapless::Vec<u8, 2048> = (0..2000).map(|i| i as u8).collect();
    assert_eq!(
        save(&mut f, &REGION, &huge, &mut big),
        Err(StorageError::TooLarge)
    );
    assert_eq!(
        load::<_, Rec>(&mut f, &REGION, &mut scratch)
            .unwrap()
            .unwrap()
            .value,
        rec(1, 40)
    );
}

#[derive(Clone, Copy, Default)]
struct Settings {
    rll_kp: f32,
    nav_mode: u8,
    gone: f32,
    narrowed: f32,
    added: f32,
}
const OLD_TABLE: Group<Settings> = Group {
    name: "old",
    params: &[
        param!(ParamDef::real("RLL_KP", 0.8, 0.0, 5.0, "", ""), Settings => rll_kp),
        param!(ParamDef::int("NAV_MODE", 2, 0, 5, "", ""), Settings => nav_mode, count),
        param!(ParamDef::real("GONE", 1.0, 0.0, 5.0, "", ""), Settings => gone),
        param!(ParamDef::real("NARROWED", 1.0, 0.0, 5.0, "", ""), Settings => narrowed),
    ],
    base: Settings::default,
    check: crate::params::independent,
};
// The next firmware: reordered, one removed, one added, one with tighter bounds.
const NEW_TABLE: Group<Settings> = Group {
    name: "new",
    params: &[
        param!(ParamDef::real("ADDED", 3.0, 0.0, 5.0, "", ""), Settings => added),
        param!(ParamDef::real("NARROWED", 1.0, 0.0, 2.0, "", ""), Settings => narrowed),
        param!(ParamDef::int("NAV_MODE", 2, 0, 5, "", ""), Settings => nav_mode, count),
        param!(ParamDef::real("RLL_KP", 0.8, 0.0, 5.0, "", ""), Settings => rll_kp),
    ],
    base: Settings::default,
    check: crate::params::independent,
};

#[test]
fn params_load_by_name_into_a_reordered_table() {
    let mut f = Dev::new(SECTOR);
    let mut scratch = [0u8; 1024];
    let mut old = ParamStore::new(&[&OLD_TABLE]);
    old.set("RLL_KP", 1.5).unwrap();
    old.set("NAV_MODE", 4.0).unwrap();
    old.set("GONE", 2.0).unwrap();
    old.set("NARROWED", 4.0).unwrap();
    assert!(old.is_dirty());
    save_params(&mut f, &REGION, &mut old, &mut scratch).unwrap();
    assert!(!old.is_dirty());
    // The streamed encoding is the one a ParamImage has.
    let mut direct = [0u8; 1024];
    let image = postcard::to_slice(&old.export(), &mut direct)
        .unwrap()
        .to_vec();
    let mut streamed = [0u8; 1024];
    let streamed = postcard::to_slice(&ParamExport(&old), &mut streamed).unwrap();
    assert_eq!(image, streamed);

    let mut new = ParamStore::new(&[&NEW_TABLE]);
    let report = load_params(&mut f, &REGION, &mut new, &mut scratch)
        .unwrap()
        .unwrap();
    assert_eq!(
        report,
        ImportReport {
            loaded: 2,
            unknown: 1,
            rejected: 1
        }
    );
    assert_eq!(new.get("RLL_KP"), Some(1.5));
    assert_eq!(new.get("NAV_MODE"), Some(4.0));
    assert_eq!(
        new.get("NARROWED"),
        Some(1.0),
        "out of new bounds: default kept"
    );
    assert_eq!(new.get("ADDED"), Some(3.0));
    assert!(!new.is_dirty(), "a load is not a change to persist");
}

#[test]
fn missions_persist_bit_exact() {
    let mut f = Dev::new(SECTOR);
    let mut scratch = [0u8; 2048];
    let mut store = MissionStore::default();
    for i in 0..20u32 {
        store
            .mission
            .push(MissionItem {
                params: [0x7fc0_0001 + i, (-0.0f32).to_bits(), 0xffff_ffff, i],
                x: 449_000_000 + i as i32,
                y: -932_000_000,
                z: f32::NAN.to_bits(),
                command: 16,
                frame: 3,
                autocontinue: true,
            })
            .unwrap();
    }
    store
        .rally
        .push(MissionItem {
            command: 5100,
            ..Default::default()
        })
        .unwrap();
    save_missions(&mut f, &REGION, &store, &mut scratch).unwrap();
    let back = load_missions(&mut f, &REGION, &mut scratch)
        .unwrap()
        .unwrap();
    assert_eq!(back, store);
}

#[test]
fn full_records_fit_their_sectors() {
    // The largest parameter image and mission store encode within one 16 KiB sector.
    use crate::navigation::plan::{FENCE_CAPACITY, MISSION_CAPACITY, RALLY_CAPACITY};
    use crate::params::store::{ParamRecord, MAX_PARAMS};
    let worst = MissionItem {
        params: [u32::MAX; 4],
        x: i32::MIN,
        y: i32::MIN,
        z: u32::MAX,
        command: u16::MAX,
        frame: u8::MAX,
        autocontinue: true,
    };
    let mut m = MissionStore::default();
    for _ in 0..MISSION_CAPACITY {
        m.mission.push(worst).unwrap();
    }
    for _ in 0..FENCE_CAPACITY {
        m.fence.push(worst).unwrap();
    }
    for _ in 0..RALLY_CAPACITY {
        m.rally.push(worst).unwrap();
    }
    let mut buf = std::vec![0u8; 64 * 1024];
    let n = postcard::to_slice(&m, &mut buf).unwrap().len();
    assert!(n + 16 <= 16 * 1024, "missions: {n} bytes");
    let mut img = ParamImage::new();
    for _ in 0..MAX_PARAMS {
        img.push(ParamRecord {
            name: heapless::String::try_from("ABCDEFGHIJKLMNOP").unwrap(),
            value: f32::MAX,
        })
        .unwrap();
    }
    let n = postcard::to_slice(&img, &mut buf).unwrap().len();
    assert!(n + 16 <= 16 * 1024, "params: {n} bytes");
}

#[test]
fn the_board_record_keeps_parameters_plan_and_key_together() {
    use crate::vehicle::params::REGISTRY;
    let mut store = ParamStore::new(REGISTRY);
    store.set("RLL_KP", -0.5).unwrap();
    let mut plan = MissionStore::default();
    let item = MissionItem {
        command: 16,
        x: 449_000_000,
        ..Default::default()
    };
    plan.mission.push(item).unwrap();
    let signing = SigningRecord {
        key: Some([7; 32]),
        timestamp: 99,
    };
    let mut f = RamFlash::<{ 2 * 16384 }>::new(16384);
    let region = AbRegion {
        magic: BOARD_MAGIC,
        slot_a: 0,
        slot_b: 16384,
        slot_len: 16384,
    };
    let rec = BoardRecordRef {
        params: ParamExport(&store),
        plan: &plan,
        signing,
    };
    assert_eq!(save_board(&mut f, &region, &rec), Ok(1));
    let (mut fresh, mut back) = (ParamStore::new(REGISTRY), MissionStore::default());
    back.rally.push(item).unwrap();
    let loaded = load_board_into(&mut f, &region, &mut fresh, &mut back)
        .unwrap()
        .unwrap();
    assert_eq!(back, plan);
    assert_eq!(loaded.signing, signing);
    assert_eq!((loaded.seq, loaded.params.loaded), (1, 1));
    assert_eq!(fresh.get("RLL_KP"), Some(-0.5));
}

/// A board region of two 16 KiB slots.
const BOARD: AbRegion = AbRegion {
    magic: BOARD_MAGIC,
    slot_a: 0,
    slot_b: 16384,
    slot_len: 16384,
};

/// A plan of `n` mission items, each told apart by its latitude.
fn plan_of(n: usize) -> MissionStore {
    let mut plan = MissionStore::default();
    for k in 0..n {
        let item = MissionItem {
            command: 16,
            x: 449_000_000 + k as i32,
            params: [0, 0, f32::NAN.to_bits() | k as u32, 0],
            z: 100f32.to_bits(),
            ..Default::default()
        };
        plan.mission.push(item).unwrap();
    }
    plan
}

#[test]
fn a_streamed_board_record_is_the_postcard_encoding_of_the_record() {
    use crate::vehicle::params::REGISTRY;
    let mut store = ParamStore::new(REGISTRY);
    store.set("RLL_KP", -0.5).unwrap();
    let plan = plan_of(MISSION_CAPACITY);
    let rec = BoardRecordRef {
        params: ParamExport(&store),
        plan: &plan,
        signing: SigningRecord {
            key: Some([3; 32]),
            timestamp: 1 << 40,
        },
    };
    let mut f = RamFlash::<{ 2 * 16384 }>::new(16384);
    save_board(&mut f, &BOARD, &rec).unwrap();
    // The reference: postcard's own encoding in one buffer, and the slot layout of the
    // module's docs around it (magic, seq, len, CRC-32 of seq, len and payload).
    let mut buf = std::vec![0u8; 16384];
    let payload = postcard::to_slice(&rec, &mut buf).unwrap();
    let word = |k: usize| u32::from_le_bytes(f.bytes()[4 * k..4 * k + 4].try_into().unwrap());
    assert_eq!(
        (word(0), word(1), word(2)),
        (BOARD_MAGIC, 1, payload.len() as u32)
    );
    let mut crc = crate::crc::Crc32::ieee();
    crc.digest(&1u32.to_le_bytes());
    crc.digest(&(payload.len() as u32).to_le_bytes());
    crc.digest(payload);
    assert_eq!(word(3), crc.get());
    assert_eq!(&f.bytes()[16..16 + payload.len()], &*payload);
}

#[test]
fn a_full_plan_loads_back_bit_for_bit_over_the_one_flown_before() {
    use crate::vehicle::params::REGISTRY;
    let store = ParamStore::new(REGISTRY);
    let plan = plan_of(MISSION_CAPACITY);
    let rec = BoardRecordRef {
        params: ParamExport(&store),
        plan: &plan,
        signing: SigningRecord::default(),
    };
    let mut f = RamFlash::<{ 2 * 16384 }>::new(16384);
    save_board(&mut f, &BOARD, &rec).unwrap();
    let mut flown = plan_of(3);
    flown.fence.push(MissionItem::default()).unwrap();
    let changes = flown.change_count();
    let mut params = ParamStore::new(REGISTRY);
    load_board_into(&mut f, &BOARD, &mut params, &mut flown)
        .unwrap()
        .unwrap();
    assert_eq!(flown, plan);
    assert_ne!(
        flown.change_count(),
        changes,
        "the navigator must see a new plan"
    );
}

#[test]
fn a_board_copy_that_does_not_decode_changes_nothing_and_the_older_one_loads() {
    use crate::vehicle::params::REGISTRY;
    let mut store = ParamStore::new(REGISTRY);
    store.set("RLL_KP", -0.25).unwrap();
    let old_plan = plan_of(2);
    let mut f = RamFlash::<{ 2 * 16384 }>::new(16384);
    let rec = |store, plan| BoardRecordRef {
        params: ParamExport(store),
        plan,
        signing: SigningRecord::default(),
    };
    save_board(&mut f, &BOARD, &rec(&store, &old_plan)).unwrap();
    // A newer copy, intact (its CRC holds) but of another format: a mission count beyond the
    // capacity.
    let mut bytes = std::vec![0xffu8; 16384];
    let payload = [0u8, 0xff, 0x7f, 0, 0];
    let mut crc = crate::crc::Crc32::ieee();
    crc.digest(&2u32.to_le_bytes());
    crc.digest(&(payload.len() as u32).to_le_bytes());
    crc.digest(&payload);
    for (k, w) in [BOARD_MAGIC, 2, payload.len() as u32, crc.get()]
        .iter()
        .enumerate()
    {
        bytes[4 * k..4 * k + 4].copy_from_slice(&w.to_le_bytes());
    }
    bytes[16..16 + payload.len()].copy_from_slice(&payload);
    let mut image = f.bytes().to_vec();
    image[16384..].copy_from_slice(&bytes);
    let mut f = RamFlash::<{ 2 * 16384 }>::from_image(&image, 16384);
    let (mut params, mut plan) = (ParamStore::new(REGISTRY), plan_of(5));
    let loaded = load_board_into(&mut f, &BOARD, &mut params, &mut plan)
        .unwrap()
        .unwrap();
    assert_eq!((loaded.seq, plan.mission.len()), (1, 2));
    assert_eq!(params.get("RLL_KP"), Some(-0.25));
    // A save keeps the copy that loads: it goes over the newer one that does not.
    save_board(&mut f, &BOARD, &rec(&store, &plan_of(7))).unwrap();
    assert_eq!(&f.bytes()[..16384], &image[..16384]);
    // Only the undecodable copy left: an error, and nothing changed.
    let mut only_bad = RamFlash::<{ 2 * 16384 }>::from_image(&bytes, 16384);
    let (mut params, mut plan) = (ParamStore::new(REGISTRY), plan_of(5));
    assert_eq!(
        load_board_into(&mut only_bad, &BOARD, &mut params, &mut plan),
        Err(StorageError::Decode)
    );
    assert_eq!(plan, plan_of(5));
    assert_eq!(
        params.get("RLL_KP"),
        ParamStore::new(REGISTRY).get("RLL_KP")
    );
}

#[test]
fn a_power_cut_anywhere_in_a_streamed_board_save_loads_the_old_record_or_the_new() {
    use crate::vehicle::params::REGISTRY;
    let mut old_params = ParamStore::new(REGISTRY);
    old_params.set("RLL_KP", -0.25).unwrap();
    let mut new_params = old_params.clone();
    new_params.set("RLL_KP", -0.75).unwrap();
    let (old_plan, new_plan) = (plan_of(4), plan_of(9));
    let rec = |store, plan| BoardRecordRef {
        params: ParamExport(store),
        plan,
        signing: SigningRecord::default(),
    };
    let mut base = RamFlash::<{ 2 * 16384 }>::new(16384);
    save_board(&mut base, &BOARD, &rec(&old_params, &old_plan)).unwrap();
    let mut cuts = 0;
    for cut in 1.. {
        let mut f = base.clone();
        f.cut_after(Some(cut));
        let done = save_board(&mut f, &BOARD, &rec(&new_params, &new_plan)).is_ok();
        f.cut_after(None);
        let (mut params, mut plan) = (ParamStore::new(REGISTRY), MissionStore::default());
        load_board_into(&mut f, &BOARD, &mut params, &mut plan)
            .unwrap()
            .unwrap();
        let kp = params.get("RLL_KP");
        if plan == new_plan {
            assert_eq!(kp, Some(-0.75), "cut {cut}");
        } else {
            assert_eq!((&plan, kp), (&old_plan, Some(-0.25)), "cut {cut}");
            assert!(!done, "cut {cut}: a save that returned Ok must load");
        }
        if done {
            break;
        }
        cuts += 1;
    }
    // An erase and every payload and header byte.
    assert!(cuts > 9 * 20, "{cuts}");
}

#[test]
fn a_signing_key_reads_back_as_serde_reads_an_array() {
    /// The record as serde derives its reading, the array unrolled.
    #[derive(Debug, PartialEq, Deserialize)]
    struct Derived {
        key: Option<[u8; 32]>,
        timestamp: u64,
    }
    let key: [u8; 32] = core::array::from_fn(|i| (i * 37 + 200) as u8);
    for r in [
        SigningRecord {
            key: Some(key),
            timestamp: 1 << 40,
        },
        SigningRecord {
            key: None,
            timestamp: 7,
        },
    ] {
        let mut buf = [0u8; 64];
        let bytes = postcard::to_slice(&r, &mut buf).unwrap();
        assert_eq!(postcard::from_bytes::<SigningRecord>(bytes).unwrap(), r);
        let d = postcard::from_bytes::<Derived>(bytes).unwrap();
        assert_eq!((d.key, d.timestamp), (r.key, r.timestamp));
        // Cut short anywhere: refused by both.
        for n in 0..bytes.len() {
            assert!(
                postcard::from_bytes::<SigningRecord>(&bytes[..n]).is_err(),
                "{n}"
            );
            assert!(postcard::from_bytes::<Derived>(&bytes[..n]).is_err(), "{n}");
        }
    }
}
