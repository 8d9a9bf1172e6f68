//! The checksums the autopilot computes itself, each a reflected CRC driven by a table the
//! compiler builds (the `crc-any` crate's code was 14 KB of the MCU image, each digest in two
//! to four copies).
//!
//! - [`Crc32`]: CRC-32 (polynomial 0x04C11DB7, reflected), four bits a step (a 64-byte table;
//!   it runs at boot and on the ground's requests): the persisted flash records, the
//!   mission's `opaque_id` ([`Crc32::ieee`]) and MAVLink FTP's file checksum
//!   ([`Crc32::mavlink_ftp`]).
//! - [`crc16_mcrf4xx`]: MAVLink's frame checksum (CRC-16/MCRF4XX, polynomial 0x1021,
//!   reflected, from 0xFFFF, no final XOR), a byte a step (a 512-byte table: every frame in
//!   and out is checked).

/// The table of a reflected CRC with polynomial `poly` (bit-reversed) for `log2(N)` bits a
/// step. Evaluated by the compiler (an index out of range would fail the build, not the
/// autopilot).
#[allow(clippy::indexing_slicing)]
const fn reflected_table<const N: usize>(poly: u32) -> [u32; N] {
    let mut table = [0u32; N];
    let mut n = 0;
    while n < N {
        let mut c = n as u32;
        let mut bit = 0;
        while bit < N.trailing_zeros() {
            c = if c & 1 == 1 { (c >> 1) ^ poly } else { c >> 1 };
            bit += 1;
        }
        table[n] = c;
        n += 1;
    }
    table
}

/// One reflected CRC step over `bytes` from `state`, by nibbles (low nibble first). Not
/// inlined: CRC-32 serves the records, the mission's id and FTP's checksums, never the control
/// period, and inlined it was copied into each of its seven callers.
#[inline(never)]
fn digest_nibbles(table: &[u32; 16], mut state: u32, bytes: &[u8]) -> u32 {
    for &b in bytes {
        state ^= u32::from(b);
        for _ in 0..2 {
            let low = table.get((state & 0xF) as usize).copied().unwrap_or(0);
            state = (state >> 4) ^ low;
        }
    }
    state
}

/// CRC-32's table (polynomial 0x04C11DB7 bit-reversed).
const CRC32_TABLE: [u32; 16] = reflected_table(0xEDB8_8320);

/// CRC-16/MCRF4XX's table (polynomial 0x1021 bit-reversed), a byte a step, in 16 bits.
#[allow(clippy::indexing_slicing)]
const CRC16_TABLE: [u16; 256] = {
    let (wide, mut table, mut n) = (reflected_table::<256>(0x8408), [0u16; 256], 0);
    while n < 256 {
        table[n] = wide[n] as u16;
        n += 1;
    }
    table
};

/// A CRC-32 fed digest by digest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crc32 {
    state: u32,
    xor_out: u32,
}

impl Crc32 {
    /// CRC-32 as zlib and IEEE 802.3 have it: from 0xFFFFFFFF, the result inverted.
    pub const fn ieee() -> Self {
        Self {
            state: u32::MAX,
            xor_out: u32::MAX,
        }
    }

    /// MAVLink FTP's CRC-32 (component metadata's `file_crc`): from 0, no final XOR.
    pub const fn mavlink_ftp() -> Self {
        Self {
            state: 0,
            xor_out: 0,
        }
    }

    /// Feeds `bytes`.
    pub fn digest(&mut self, bytes: &[u8]) {
        self.state = digest_nibbles(&CRC32_TABLE, self.state, bytes);
    }

    /// The checksum of everything fed so far.
    pub fn get(&self) -> u32 {
        self.state ^ self.xor_out
    }
}

/// MAVLink's CRC-16/MCRF4XX of `bytes`, continuing from `state` (0xFFFF to start).
pub fn crc16_mcrf4xx(mut state: u16, bytes: &[u8]) -> u16 {
    for &b in bytes {
        let low = CRC16_TABLE
            .get(usize::from((state as u8) ^ b))
            .copied()
            .unwrap_or(0);
        state = (state >> 8) ^ low;
    }
    state
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The catalogue's check values (CRC of "123456789") and the `crc-any` crate's results
    /// over a spread of lengths and contents.
    #[test]
    fn each_checksum_gives_the_catalogue_check_value_and_the_crc_any_crates() {
        let mut ieee = Crc32::ieee();
        ieee.digest(b"123456789");
        assert_eq!(ieee.get(), 0xCBF4_3926);
        assert_eq!(crc16_mcrf4xx(0xFFFF, b"123456789"), 0x6F91);
        let data: [u8; 300] = core::array::from_fn(|i| (i * 37 % 251) as u8);
        for n in [0, 1, 2, 7, 64, 255, 300] {
            let bytes = &data[..n];
            let (mut ours, mut theirs) = (Crc32::ieee(), crc_any::CRCu32::crc32());
            ours.digest(bytes);
            theirs.digest(bytes);
            assert_eq!(ours.get(), theirs.get_crc(), "crc32 of {n} bytes");
            let (mut ours, mut theirs) = (
                Crc32::mavlink_ftp(),
                crc_any::CRCu32::create_crc(0xEDB8_8320, 32, 0, 0, true),
            );
            // In two digests: the state carries over.
            ours.digest(&bytes[..n / 2]);
            ours.digest(&bytes[n / 2..]);
            theirs.digest(bytes);
            assert_eq!(ours.get(), theirs.get_crc(), "ftp crc of {n} bytes");
            let mut theirs = crc_any::CRCu16::crc16mcrf4cc();
            theirs.digest(bytes);
            let ours = crc16_mcrf4xx(crc16_mcrf4xx(0xFFFF, &bytes[..n / 3]), &bytes[n / 3..]);
            assert_eq!(ours, theirs.get_crc(), "crc16 of {n} bytes");
        }
    }
}
