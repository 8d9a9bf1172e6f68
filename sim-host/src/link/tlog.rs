//! `.tlog` telemetry logs: each frame preceded by its time as a big-endian u64 of
//! microseconds since the Unix epoch (the format pymavlink's `mavlogfile` and QGroundControl
//! read).

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// The wall-clock epoch a simulated flight is stamped from (2026-01-01T00:00:00Z), so that a
/// log is a pure function of the flight and a seed, yet reads as a plausible date.
pub const SIM_EPOCH_US: u64 = 1_767_225_600_000_000;

/// Writes a `.tlog`.
pub struct TlogWriter {
    out: BufWriter<File>,
    frames: u64,
}

impl TlogWriter {
    /// Creates (truncates) the file.
    pub fn create(path: &Path) -> io::Result<Self> {
        Ok(Self {
            out: BufWriter::new(File::create(path)?),
            frames: 0,
        })
    }

    /// Appends one frame seen at simulation time `time_us`.
    pub fn write(&mut self, time_us: u64, frame: &[u8]) -> io::Result<()> {
        self.out
            .write_all(&(SIM_EPOCH_US + time_us).to_be_bytes())?;
        self.out.write_all(frame)?;
        self.frames += 1;
        Ok(())
    }

    /// Frames written so far.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Flushes to disk.
    pub fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

/// Length of the MAVLink frame at the start of `bytes` from its header (`None`: no frame
/// starts there, or its header is cut short).
pub fn frame_len(bytes: &[u8]) -> Option<usize> {
    let len = usize::from(*bytes.get(1)?);
    match bytes.first()? {
        0xFD => {
            let signed = bytes.get(2)? & 1 != 0;
            Some(12 + len + if signed { 13 } else { 0 })
        }
        0xFE => Some(8 + len),
        _ => None,
    }
}

/// The whole frames of a byte stream that holds whole frames back to back (what a ground
/// link's queue hands out); a torn tail is left out.
pub fn split_frames(mut bytes: &[u8]) -> impl Iterator<Item = &[u8]> {
    std::iter::from_fn(move || {
        let n = frame_len(bytes).filter(|&n| n <= bytes.len())?;
        let (frame, rest) = bytes.split_at(n);
        bytes = rest;
        Some(frame)
    })
}

/// Reads a `.tlog` back: (time since the simulation epoch in us, frame bytes) per record.
///
/// Frames are delimited with the MAVLink length byte, as pymavlink does.
pub fn read_tlog(bytes: &[u8]) -> Vec<(u64, Vec<u8>)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i + 8 + 3 <= bytes.len() {
        let mut t = [0u8; 8];
        t.copy_from_slice(&bytes[i..i + 8]);
        let time = u64::from_be_bytes(t).saturating_sub(SIM_EPOCH_US);
        let Some(total) = frame_len(&bytes[i + 8..]) else {
            break;
        };
        if i + 8 + total > bytes.len() {
            break;
        }
        out.push((time, bytes[i + 8..i + 8 + total].to_vec()));
        i += 8 + total;
    }
    out
}
