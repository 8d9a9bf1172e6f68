//! The file storage: the SITL's flash, a file holding the board record.

use crate::app::persist::Persistence;
use crate::app::App;
use common::storage::{AbRegion, RamFlash, BOARD_MAGIC};
use std::io;
use std::path::PathBuf;

/// The SITL "flash": the board record of `common::storage` (parameters, plan, signing key)
/// in a file, through the same [`Persistence`] as the MCU.
///
/// The record is written A/B with a CRC exactly as on the MCU; the file is the flash image.
pub struct FileStorage {
    path: Option<PathBuf>,
    store: Persistence<RamFlash<STORAGE_BYTES>>,
}

const SECTOR: u32 = 16 * 1024;
const STORAGE_BYTES: usize = 2 * SECTOR as usize;
const REGION: AbRegion = AbRegion {
    magic: BOARD_MAGIC,
    slot_a: 0,
    slot_b: SECTOR,
    slot_len: SECTOR,
};

impl FileStorage {
    /// Storage in `path` (created on the first save); `None` keeps it in memory only.
    pub fn open(path: Option<PathBuf>) -> Self {
        let image = path
            .as_ref()
            .and_then(|p| std::fs::read(p).ok())
            .unwrap_or_default();
        Self {
            path,
            store: Persistence::new(RamFlash::from_image(&image, SECTOR), REGION),
        }
    }

    /// Boots without the saved MAVLink signing key, and saves that at the next change: the
    /// bench recovery of a lost key (`firmware --signing-reset`).
    pub fn forget_signing_key(mut self) -> Self {
        self.store.forget_signing_key();
        self
    }

    /// Loads saved parameters and missions into the autopilot.
    pub fn load_into(&mut self, app: &mut App) -> Vec<String> {
        let l = self.store.load_into(app);
        let mut notes = Vec::new();
        if let Some(r) = l.params {
            notes.push(format!("parameters loaded ({r:?})"));
        }
        if l.mission_items > 0 {
            notes.push(format!("missions loaded ({} items)", l.mission_items));
        }
        if l.key_forgotten {
            notes.push("signing key forgotten (--signing-reset)".into());
        } else if l.signing_key {
            notes.push("signing key loaded: unsigned writes are refused".into());
        }
        if l.unreadable {
            notes.push("saved record unreadable: defaults kept".into());
        }
        notes
    }

    /// Saves what changed since the last save while disarmed, and answers a
    /// `MAV_CMD_PREFLIGHT_STORAGE` once saved (PX4 saves parameters as they change).
    pub fn save_changes(&mut self, app: &mut App) -> io::Result<()> {
        let done = self.store.service(app);
        if done.failed {
            return Err(io::Error::other("save of the board record failed"));
        }
        if done.saved {
            if let Some(p) = &self.path {
                // Write-then-rename: the file is never half written.
                let tmp = p.with_extension("tmp");
                std::fs::write(&tmp, self.store.flash().bytes())?;
                std::fs::rename(&tmp, p)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mavlink::dialects::common::SETUP_SIGNING_DATA;

    #[test]
    fn a_signing_key_survives_a_reboot_and_the_bench_reset_forgets_it() {
        let path = std::env::temp_dir().join(format!("sitl-signing-{}.bin", std::process::id()));
        let _ = std::fs::remove_file(&path);
        let mut app = App::new();
        let mut storage = FileStorage::open(Some(path.clone()));
        storage.load_into(&mut app);
        let setup = SETUP_SIGNING_DATA {
            initial_timestamp: 1_000_000,
            target_system: 1,
            target_component: 1,
            secret_key: [42; 32],
        };
        assert!(app.signing_mut().setup(&setup, false));
        storage.save_changes(&mut app).expect("saved");

        let mut rebooted = App::new();
        FileStorage::open(Some(path.clone())).load_into(&mut rebooted);
        assert_eq!(rebooted.signing_mut().key(), Some(&[42; 32]));
        // The signing clock carries on from where it was saved, never older.
        assert!(rebooted.signing_mut().timestamp() >= 1_000_000);

        let mut reset = App::new();
        FileStorage::open(Some(path.clone()))
            .forget_signing_key()
            .load_into(&mut reset);
        assert_eq!(reset.signing_mut().key(), None);
        let _ = std::fs::remove_file(&path);
    }
}
