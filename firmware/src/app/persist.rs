//! What the autopilot keeps across resets, on any [`Flash`]: the board record of
//! `common::storage` (parameters by name, the plan, the signing key) in one A/B region.
//!
//! Both boards use it: the MCU on its two reserved sectors (or, in QEMU, a host file over
//! semihosting), SITL in a file. It saves what changed, PX4-like, but only while disarmed:
//! erasing a sector of the STM32F405's single flash bank stalls every fetch from flash for up
//! to 0.8 s. `MAV_CMD_PREFLIGHT_STORAGE` is answered once its save is done.

use common::params::store::ImportReport;
use common::storage::stream::{load_board_into, save_board};
use common::storage::StorageError;
use common::storage::{AbRegion, BoardRecordRef, Flash, SigningRecord};

use super::App;

/// What a load found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Loaded {
    /// Parameters taken, unknown and refused; `None`: nothing saved.
    pub params: Option<ImportReport>,
    /// Mission items loaded.
    pub mission_items: usize,
    /// A signing key was loaded (unsigned writes are refused).
    pub signing_key: bool,
    /// The saved key was dropped on purpose ([`Persistence::forget_signing_key`]).
    pub key_forgotten: bool,
    /// Both copies were intact but unreadable by this firmware, or the flash failed.
    pub unreadable: bool,
}

/// What [`Persistence::service`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Serviced {
    /// A save was written.
    pub saved: bool,
    /// A save failed.
    pub failed: bool,
    /// The ground station asked for a reboot: the board resets once the answer is out.
    pub reboot: bool,
}

/// The board record on a flash device.
pub struct Persistence<F> {
    flash: F,
    region: AbRegion,
    missions_seen: Option<u32>,
    signing_seen: Option<u32>,
    forget_key: bool,
    /// The last automatic save failed: no retry every loop until something asks again.
    gave_up: bool,
}

impl<F: Flash> Persistence<F> {
    /// The record in `region` of `flash`.
    pub fn new(flash: F, region: AbRegion) -> Self {
        Self {
            flash,
            region,
            missions_seen: None,
            signing_seen: None,
            forget_key: false,
            gave_up: false,
        }
    }

    /// The device.
    pub fn flash(&self) -> &F {
        &self.flash
    }

    /// Boots without the saved MAVLink signing key, and saves that at the next change: the
    /// bench recovery of a lost key.
    pub fn forget_signing_key(&mut self) {
        self.forget_key = true;
    }

    /// Loads the saved record into the autopilot (at start-up), streamed from the flash
    /// straight into its stores: no copy of the record, encoded or decoded, is held.
    pub fn load_into(&mut self, app: &mut App) -> Loaded {
        let mut loaded = Loaded::default();
        let (params, plan, _) = app.vehicle_mut().stores();
        match load_board_into(&mut self.flash, &self.region, params, plan) {
            Ok(Some(r)) => {
                loaded.params = Some(r.params);
                loaded.mission_items = app.vehicle().plan().mission.len();
                let key = if self.forget_key {
                    loaded.key_forgotten = true;
                    None
                } else {
                    r.signing.key
                };
                loaded.signing_key = key.is_some();
                app.signing_mut().load(key, r.signing.timestamp);
            }
            Ok(None) => {}
            Err(_) => loaded.unreadable = true,
        }
        self.missions_seen = Some(app.vehicle().plan().change_count());
        self.signing_seen = (!self.forget_key).then(|| app.signing_mut().change_count());
        app.vehicle_mut().params_mut().mark_saved();
        loaded
    }

    /// Whether something changed since the last save.
    fn changed(&mut self, app: &mut App) -> bool {
        let missions = Some(app.vehicle().plan().change_count()) != self.missions_seen
            && !app.ground_link().missions().busy();
        let signing = Some(app.signing_mut().change_count()) != self.signing_seen;
        app.vehicle().params().is_dirty() || missions || signing
    }

    /// Saves the record now, encoded straight into the flash.
    pub fn save(&mut self, app: &mut App) -> Result<u32, StorageError<F::Error>> {
        let signing = app.signing_mut();
        let record_signing = SigningRecord {
            key: signing.key().copied(),
            timestamp: signing.timestamp(),
        };
        let signing_seen = signing.change_count();
        let missions_seen = app.vehicle().plan().change_count();
        let (params, plan, _) = app.vehicle_mut().stores();
        let record = BoardRecordRef {
            params: common::params::store::ParamExport(params),
            plan: &*plan,
            signing: record_signing,
        };
        let seq = save_board(&mut self.flash, &self.region, &record)?;
        params.mark_saved();
        self.signing_seen = Some(signing_seen);
        self.missions_seen = Some(missions_seen);
        Ok(seq)
    }

    /// Called by the board's loop: answers a `MAV_CMD_PREFLIGHT_STORAGE` once its save is
    /// done, saves other changes while disarmed, and passes on a reboot request.
    pub fn service(&mut self, app: &mut App) -> Serviced {
        let mut done = Serviced::default();
        let asked = app.ground_link_mut().take_storage_request();
        let auto = !app.armed() && !self.gave_up && self.changed(app);
        if asked.is_some() || auto {
            let ok = self.save(app).is_ok();
            self.gave_up = !ok;
            done.saved = ok;
            done.failed = !ok;
            if let Some(peer) = asked {
                app.ground_link_mut().storage_done(peer, ok);
                app.poll_ground();
            }
        }
        done.reboot = app.ground_link_mut().take_reboot_request();
        done
    }
}
