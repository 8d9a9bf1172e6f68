//! The driver against the register-level model: records round-trip, the controller is
//! locked between operations, and every error the silicon reports comes back as an error.

extern crate std;
use std::boxed::Box;

use super::model::F4Model;
use super::*;
use crate::storage::{load, save, AbRegion};

/// Sectors 1 and 2, as `memory.x` reserves them.
const START: u32 = 0x0800_4000;
const END: u32 = 0x0800_C000;
const REGION: AbRegion = AbRegion {
    magic: 0x5445_5354,
    slot_a: START,
    slot_b: 0x0800_8000,
    slot_len: 16 * 1024,
};

fn driver() -> F4Flash<Box<F4Model>> {
    F4Flash::new(Box::new(F4Model::new()), START, END)
}

impl FlashRegs for Box<F4Model> {
    fn read_reg(&mut self, offset: u32) -> u32 {
        (**self).read_reg(offset)
    }
    fn write_reg(&mut self, offset: u32, value: u32) {
        (**self).write_reg(offset, value)
    }
    fn read_mem(&mut self, addr: u32, buf: &mut [u8]) {
        (**self).read_mem(addr, buf)
    }
    fn write_mem_u8(&mut self, addr: u32, value: u8) {
        (**self).write_mem_u8(addr, value)
    }
    fn write_mem_u32(&mut self, addr: u32, value: u32) {
        (**self).write_mem_u32(addr, value)
    }
}

#[test]
fn the_sector_map_is_the_stm32f405s() {
    assert_eq!(sector_of(0x0800_0000), Some((0, 0x0800_0000, 16384)));
    assert_eq!(sector_of(0x0800_7fff), Some((1, 0x0800_4000, 16384)));
    assert_eq!(sector_of(0x0800_c000), Some((3, 0x0800_c000, 16384)));
    assert_eq!(sector_of(0x0801_0000), Some((4, 0x0801_0000, 65536)));
    assert_eq!(sector_of(0x0802_0000), Some((5, 0x0802_0000, 131072)));
    assert_eq!(sector_of(0x080f_ffff), Some((11, 0x080e_0000, 131072)));
    assert_eq!(sector_of(0x0810_0000), None);
    assert_eq!(sector_of(0x07ff_ffff), None);
}

#[test]
fn records_round_trip_through_the_controller_and_it_is_locked_after_each() {
    let mut f = driver();
    let mut scratch = [0u8; 256];
    let rec: (u32, heapless::Vec<u8, 64>) = (7, (0..41u8).collect());
    for gen in 1..=3u32 {
        let seq = save(&mut f, &REGION, &(gen, rec.1.clone()), &mut scratch).unwrap();
        assert_eq!(seq, gen);
        assert!(f.regs().locked(), "locked after the save");
        let back = load::<_, (u32, heapless::Vec<u8, 64>)>(&mut f, &REGION, &mut scratch)
            .unwrap()
            .unwrap();
        assert_eq!(back.value, (gen, rec.1.clone()));
    }
    // Three saves, each erasing its sector first: A, B, A.
    assert_eq!(f.regs().erases, 3);
    assert_eq!(f.regs().refused, 0);
    assert_eq!(f.regs().status() & sr::ERRORS, 0);
    // Sector 0 (vectors) and 3 (code) untouched.
    let m = &f.regs().mem;
    assert!(m[..0x4000].iter().all(|&b| b == 0xff));
    assert!(m[0xc000..].iter().all(|&b| b == 0xff));
}

#[test]
fn words_are_programmed_as_words_and_the_unaligned_rest_as_bytes() {
    let mut f = driver();
    f.erase_sector(START).unwrap();
    let data: std::vec::Vec<u8> = (0..23u8).collect();
    // 3 bytes to the next word, four words, then 4 bytes: but the model refuses any access
    // whose width differs from PSIZE or that is not aligned to it.
    f.write(START + 1, &data).unwrap();
    assert_eq!(f.regs().refused, 0);
    let mut back = [0u8; 23];
    f.read(START + 1, &mut back).unwrap();
    assert_eq!(&back[..], &data[..]);
    // 3 head bytes + 5 words (20 bytes) = 8 accesses.
    assert_eq!(f.regs().programs, 3 + 5);
}

#[test]
fn nothing_outside_the_reserved_sectors_is_erased_or_programmed() {
    let mut f = driver();
    assert_eq!(f.erase_sector(0x0800_0000), Err(F4Error::Address));
    assert_eq!(f.erase_sector(0x0800_c000), Err(F4Error::Address));
    assert_eq!(f.erase_sector(START + 4), Err(F4Error::Address));
    assert_eq!(f.write(END - 2, &[0; 4]), Err(F4Error::Address));
    assert_eq!(f.write(0x0800_3ffc, &[0; 8]), Err(F4Error::Address));
    assert_eq!(f.write(u32::MAX - 1, &[0; 8]), Err(F4Error::Address));
    assert_eq!((f.regs().erases, f.regs().programs), (0, 0));
    assert!(f.regs().locked(), "never even unlocked");
}

#[test]
fn programming_over_data_that_was_not_erased_fails_its_read_back() {
    let mut f = driver();
    f.erase_sector(START).unwrap();
    f.write(START, &[0x0f; 8]).unwrap();
    // Programming clears bits only: 0x0f & 0xf0 = 0, not 0xf0.
    assert_eq!(f.write(START, &[0xf0; 8]), Err(F4Error::Verify));
    assert!(f.regs().locked());
}

#[test]
fn a_write_protected_sector_reports_wrperr_and_stays_as_it_was() {
    let mut f = driver();
    f.regs().write_protected = 1 << 2;
    assert_eq!(
        f.erase_sector(0x0800_8000),
        Err(F4Error::Status(sr::WRPERR))
    );
    assert_eq!(
        f.write(0x0800_8000, &[0; 4]),
        Err(F4Error::Status(sr::WRPERR))
    );
    assert!(f.regs().mem[0x8000..0xc000].iter().all(|&b| b == 0xff));
    assert!(f.regs().locked());
    // The flags were cleared: the next operation elsewhere succeeds.
    f.erase_sector(START).unwrap();
    f.write(START, &[1, 2, 3, 4]).unwrap();
}

#[test]
fn a_controller_locked_by_a_wrong_key_is_reported_not_written() {
    let mut f = driver();
    f.regs().write_reg(reg::KEYR, 0x1234_5678);
    assert!(f.regs().key_fault);
    assert_eq!(f.erase_sector(START), Err(F4Error::Locked));
    assert_eq!(f.write(START, &[0; 4]), Err(F4Error::Locked));
    assert_eq!((f.regs().erases, f.regs().programs), (0, 0));
}

#[test]
fn a_controller_that_stays_busy_times_out_instead_of_hanging() {
    let mut f = driver().with_poll_limit(10_000);
    f.regs().busy_polls = u32::MAX;
    // The erase starts (BSY from then on) and the driver gives up after its poll budget.
    assert_eq!(f.erase_sector(START), Err(F4Error::Timeout));
    assert!(f.regs().locked());
}

#[test]
fn the_model_refuses_what_the_silicon_refuses() {
    // Independent of the driver: the rules the driver is tested against.
    let mut m = F4Model::new();
    m.write_mem_u32(START, 0);
    assert_eq!(m.status(), sr::PGSERR, "locked: no programming");
    m.write_reg(reg::SR, sr::ERRORS);
    m.write_reg(reg::KEYR, KEY1);
    m.write_reg(reg::KEYR, KEY2);
    assert!(!m.locked());
    m.write_mem_u32(START, 0);
    assert_eq!(m.status(), sr::PGSERR, "PG clear");
    m.write_reg(reg::SR, sr::ERRORS);
    m.write_reg(reg::CR, cr::PG | cr::PSIZE_X8);
    m.write_mem_u32(START, 0);
    assert_eq!(m.status(), sr::PGPERR, "a word access with PSIZE x8");
    m.write_reg(reg::SR, sr::ERRORS);
    m.write_reg(reg::CR, cr::PG | cr::PSIZE_X32);
    m.write_mem_u32(START + 2, 0);
    assert_eq!(m.status(), sr::PGAERR, "an unaligned word");
    m.write_reg(reg::SR, sr::ERRORS);
    m.write_mem_u32(START, 0x1234_5678);
    assert_eq!(m.status(), 0);
    assert_eq!(&m.mem[0x4000..0x4004], &0x1234_5678u32.to_le_bytes());
    m.write_reg(reg::CR, cr::LOCK);
    assert!(m.locked());
    m.write_reg(reg::CR, cr::SER | (1 << cr::SNB_SHIFT) | cr::STRT);
    assert_eq!(m.erases, 0, "CR ignored while locked");
}
