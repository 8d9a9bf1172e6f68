//! The panic call sites left in the release MCU image, counted: every Thumb-2 `BL`, `B.W` and
//! conditional `B<c>.W` whose target is a panic entry point of `core` (`core::panicking::*`,
//! `unwrap_failed`, `expect_failed`, the slice-index failures, `RefCell`'s borrow failures, ...),
//! attributed to the function that contains it and grouped by that function's crate. With the
//! optimisation and inlining of the release build, a bounds check of a dependency inlined into
//! one of our functions counts as ours: it is in our function.
//!
//! The project's own crates (`common`, `firmware`) have none, and must keep none; the
//! dependencies' count may not grow beyond the figure recorded here and in
//! `docs/RELIABILITY.md`, which says why none of them can fire. Run with `--nocapture` to see
//! every site.

use std::collections::BTreeMap;

use object::{Object, ObjectSection, ObjectSymbol, SectionKind, SymbolKind};
use system_tests::build_mcu_firmware;

/// Sites allowed in everything else the image links (the `mavlink` crate, `libm`,
/// `heapless`'s rings, the runtime and the logger): the count at the time of writing.
/// Lower it as sites go; never raise it without saying in `docs/RELIABILITY.md` why the new
/// ones cannot fire.
const DEPENDENCY_SITES: usize = 9;

/// Whether a (demangled, hash-free) function name is one of core's panic entry points.
fn is_panic_entry(name: &str) -> bool {
    name.starts_with("core::panicking::")
        || name.starts_with("core::result::unwrap_failed")
        || name.starts_with("core::option::unwrap_failed")
        || name.starts_with("core::option::expect_failed")
        || name.starts_with("core::cell::panic_already")
        || name.starts_with("core::str::slice_error_fail")
        || (name.starts_with("core::slice::") && name.ends_with("_fail"))
        || name == "rust_begin_unwind"
}

/// The crate a function belongs to: the first path segment of its name (`<a::B as c::D>::f`
/// is `a`'s).
fn crate_of(name: &str) -> &str {
    let n = name.trim_start_matches(['<', '&', '*', '(']);
    let n = n.strip_prefix("mut ").unwrap_or(n);
    let n = n.strip_prefix("dyn ").unwrap_or(n);
    let end = n
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(n.len());
    match &n[..end] {
        "" => "?",
        c => c,
    }
}

/// Whose site it is: the crate of the function holding it, except `heapless`'s SPSC ring
/// arithmetic inlined into the USART driver. heapless 0.9's `Producer` and `Consumer` step
/// their indices `% capacity` with the capacity read from the queue at run time, so the
/// compiler keeps a division-by-zero check in every function that moves a byte; the rings'
/// capacity is a constant (512), never zero (docs/RELIABILITY.md). Only that check, in that
/// module, is counted as heapless's.
fn owner(s: &Site) -> &str {
    if s.function.starts_with("firmware::mcu::usart::") && s.callee.ends_with("rem_by_zero") {
        "heapless (spsc, inlined into firmware::mcu::usart)"
    } else {
        crate_of(&s.function)
    }
}

/// The target of the 32-bit Thumb-2 branch at `pc` made of halfwords `h1`, `h2`: `BL` (T1),
/// `B.W` (T4) or `B<c>.W` (T3) (ARMv7-M Architecture Reference Manual, A7.7.12 and A7.7.18);
/// `None` for any other instruction.
fn branch_target(pc: u64, h1: u16, h2: u16) -> Option<u64> {
    if h1 >> 11 != 0b11110 || h2 >> 15 != 1 {
        return None;
    }
    let bit = |h: u16, n: u32| u32::from((h >> n) & 1);
    let (s, j1, j2) = (bit(h1, 10), bit(h2, 13), bit(h2, 11));
    let imm11 = u32::from(h2 & 0x7FF);
    let offset = if bit(h2, 12) == 1 {
        // BL (bit 14 set) and B.W (clear): S:I1:I2:imm10:imm11:'0', 25 bits.
        let (i1, i2) = (!(j1 ^ s) & 1, !(j2 ^ s) & 1);
        let imm10 = u32::from(h1 & 0x3FF);
        let v = (s << 24) | (i1 << 23) | (i2 << 22) | (imm10 << 12) | (imm11 << 1);
        ((v << 7) as i32) >> 7
    } else if bit(h2, 14) == 0 && (h1 >> 6) & 0xF < 0b1110 {
        // B<c>.W: S:J2:J1:imm6:imm11:'0', 21 bits (a condition of 111x is another instruction).
        let imm6 = u32::from(h1 & 0x3F);
        let v = (s << 20) | (j2 << 19) | (j1 << 18) | (imm6 << 12) | (imm11 << 1);
        ((v << 11) as i32) >> 11
    } else {
        return None;
    };
    Some(pc.wrapping_add(4).wrapping_add_signed(i64::from(offset)))
}

/// One panic call site.
#[derive(Debug)]
struct Site {
    function: String,
    address: u64,
    callee: String,
}

fn panic_sites(elf: &[u8]) -> Vec<Site> {
    let file = object::File::parse(elf).expect("an ELF");
    let name =
        |s: &object::Symbol| format!("{:#}", rustc_demangle::demangle(s.name().unwrap_or("")));
    let functions: Vec<(u64, u64, String)> = file
        .symbols()
        .filter(|s| s.kind() == SymbolKind::Text && s.size() > 0)
        .map(|s| (s.address() & !1, s.size(), name(&s)))
        .collect();
    let entries: BTreeMap<u64, String> = functions
        .iter()
        .filter(|(_, _, n)| is_panic_entry(n))
        .map(|(a, _, n)| (*a, n.clone()))
        .collect();
    // ARM's mapping symbols: `$d` starts data inside code (literal pools, branch tables),
    // `$t` Thumb instructions again.
    let mut mapping: Vec<(u64, bool)> = file
        .symbols()
        .filter_map(|s| match s.name() {
            Ok(n) if n.starts_with("$d") => Some((s.address(), true)),
            Ok(n) if n.starts_with("$t") => Some((s.address(), false)),
            _ => None,
        })
        .collect();
    mapping.sort_unstable();
    let is_data = |pc: u64| {
        let i = mapping.partition_point(|(a, _)| *a <= pc);
        i > 0 && mapping[i - 1].1
    };
    let mut sites = Vec::new();
    for section in file.sections().filter(|s| s.kind() == SectionKind::Text) {
        let bytes = section.data().expect("section data");
        let base = section.address();
        for (start, size, function) in &functions {
            // Panic machinery calling itself is not a site.
            if is_panic_entry(function) || *start < base || start + size > base + bytes.len() as u64
            {
                continue;
            }
            let mut pc = *start;
            while pc + 4 <= start + size {
                if is_data(pc) {
                    pc += 2;
                    continue;
                }
                let at = (pc - base) as usize;
                let h1 = u16::from_le_bytes([bytes[at], bytes[at + 1]]);
                let wide = h1 >> 11 >= 0b11101;
                if wide {
                    let h2 = u16::from_le_bytes([bytes[at + 2], bytes[at + 3]]);
                    if let Some(callee) = branch_target(pc, h1, h2).and_then(|t| entries.get(&t)) {
                        sites.push(Site {
                            function: function.clone(),
                            address: pc,
                            callee: callee.clone(),
                        });
                    }
                }
                pc += if wide { 4 } else { 2 };
            }
        }
    }
    sites
}

#[test]
fn branch_targets_decode_as_the_architecture_manual_says() {
    // bl #+0x1000 at 0x100: S=0, imm10=1, J1=J2=1, imm11=0.
    assert_eq!(branch_target(0x100, 0xF001, 0xF800), Some(0x1104));
    // bl #-4 at 0x2000: S=1, imm10=0x3FF, J1=J2=1, imm11=0x7FE.
    assert_eq!(branch_target(0x2000, 0xF7FF, 0xFFFE), Some(0x2000));
    // b.w #+8 at 0: 10x1 form.
    assert_eq!(branch_target(0, 0xF000, 0xB804), Some(0x0C));
    // bne.w #+8 at 0: cond 1 (NE), 10x0 form.
    assert_eq!(branch_target(0, 0xF040, 0x8004), Some(0x0C));
    // A 16-bit instruction pair is not a branch.
    assert_eq!(branch_target(0, 0x4770, 0x4770), None);
}

#[test]
fn panic_call_sites_in_the_mcu_image_do_not_grow() {
    let elf = build_mcu_firmware();
    let bytes = std::fs::read(&elf).expect("firmware ELF exists");
    let sites = panic_sites(&bytes);
    let mut by_crate: BTreeMap<&str, Vec<&Site>> = BTreeMap::new();
    for s in &sites {
        by_crate.entry(owner(s)).or_default().push(s);
    }
    println!("panic call sites in the MCU image: {}", sites.len());
    for (krate, list) in &by_crate {
        println!("{krate}: {}", list.len());
        let mut per_fn: BTreeMap<&str, Vec<String>> = BTreeMap::new();
        for s in list {
            per_fn
                .entry(&s.function)
                .or_default()
                .push(format!("{:#x} -> {}", s.address, s.callee));
        }
        for (f, calls) in per_fn {
            println!("    {f}");
            for c in calls {
                println!("        {c}");
            }
        }
    }
    let own: usize = ["common", "firmware"]
        .iter()
        .map(|c| by_crate.get(c).map_or(0, Vec::len))
        .sum();
    let deps = sites.len() - own;
    assert!(
        sites.iter().any(|s| s.callee.starts_with("core::")),
        "the scan finds nothing: has the image's symbol table gone?"
    );
    assert_eq!(
        own, 0,
        "panic sites in common and firmware (listed above): our own code must have none"
    );
    assert!(
        deps <= DEPENDENCY_SITES,
        "{deps} panic sites in dependencies, {DEPENDENCY_SITES} allowed"
    );
}
