//! The fuzz targets' logic, one module per target (`fuzz_targets/` holds the thin entry
//! points), and what they share: frames as a simulator and a ground station send them, and the
//! invariants checked on what the autopilot sends back. `docs/RELIABILITY.md` lists the targets
//! and what each asserts.

// Deprecated MAVLink messages (MISSION_ITEM, MISSION_REQUEST, SET_MODE) are still sent by
// ground stations: the targets send them on purpose.
#![allow(deprecated)]

pub mod frames;
pub mod gcs;
pub mod ground_link;
pub mod mission_file;
pub mod mission_protocol;
pub mod param_protocol;
pub mod sim_link;
pub mod storage;
pub mod watch;

/// Whether to print each input's actions (`FUZZ_TRACE=1` while reproducing a crash).
pub fn trace() -> bool {
    static ON: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *ON.get_or_init(|| std::env::var_os("FUZZ_TRACE").is_some())
}
pub mod navigator;

/// Reads actions from `data` until it runs out (or `max` of them) and hands each to `step`,
/// printing it first under `FUZZ_TRACE`.
pub fn each_action<A: for<'a> arbitrary::Arbitrary<'a> + std::fmt::Debug>(
    data: &[u8],
    max: usize,
    mut step: impl FnMut(&A),
) {
    let mut u = arbitrary::Unstructured::new(data);
    for _ in 0..max {
        let Ok(a) = A::arbitrary(&mut u) else {
            return;
        };
        if trace() {
            eprintln!("{a:?}");
        }
        step(&a);
        if u.is_empty() {
            return;
        }
    }
}
