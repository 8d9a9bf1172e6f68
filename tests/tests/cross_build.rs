//! The MCU image builds for the STM32F405 and fits its memory map.

use object::{Object, ObjectSection, ObjectSegment};
use system_tests::build_mcu_firmware;

const FLASH: (u64, u64) = (0x0800_0000, 1024 * 1024);
const RAM: (u64, u64) = (0x2000_0000, 128 * 1024);

#[test]
fn firmware_links_for_thumbv7em_and_fits_the_stm32f405() {
    let elf = build_mcu_firmware();
    let bytes = std::fs::read(&elf).expect("firmware ELF exists");
    let file = object::File::parse(&*bytes).expect("a valid ELF");
    assert_eq!(file.architecture(), object::Architecture::Arm);

    // The vector table sits at the start of flash: initial SP in RAM, reset vector in flash.
    let vt = file
        .section_by_name(".vector_table")
        .expect(".vector_table section");
    assert_eq!(vt.address(), FLASH.0);
    let data = vt.data().expect("vector table data");
    let sp = u32::from_le_bytes([data[0], data[1], data[2], data[3]]) as u64;
    let reset = u32::from_le_bytes([data[4], data[5], data[6], data[7]]) as u64 & !1;
    assert!(sp > RAM.0 && sp <= RAM.0 + RAM.1, "initial SP {sp:#x}");
    assert!(
        reset >= FLASH.0 && reset < FLASH.0 + FLASH.1,
        "reset {reset:#x}"
    );

    // Every loadable segment lies inside flash or RAM.
    for seg in file.segments() {
        let (a, s) = (seg.address(), seg.size());
        let in_flash = a >= FLASH.0 && a + s <= FLASH.0 + FLASH.1;
        let in_ram = a >= RAM.0 && a + s <= RAM.0 + RAM.1;
        assert!(
            in_flash || in_ram || s == 0,
            "segment {a:#x}+{s:#x} outside the map"
        );
    }
}
