//! The flight log of the application: started when the vehicle arms, fed after every sensor
//! frame, stopped when it disarms; the board drains its bytes into its storage.
//!
//! A board without log storage leaves it off ([`FlightLog::enable`]): nothing is encoded, so
//! a log nobody keeps costs no control period. A board with little room for logs caps the
//! topics' rates ([`FlightLog::set_rate_cap`]: the MCU's flash).

use common::link::framing::LinkStats;
use common::logger::params::LogParams;
use common::logger::topics::TelemetryStatus;
use common::logger::{LogStats, Logger, SystemInfo};
use common::sensors::SensorFrame;
use common::ulog::Level;
use common::vehicle::commander::Severity;
use common::vehicle::Vehicle;

/// What the log says of the software and the board.
const INFO: SystemInfo = SystemInfo {
    sys_name: "fixed-wing autopilot",
    ver_sw: env!("CARGO_PKG_VERSION"),
    ver_hw: if cfg!(target_os = "none") {
        "STM32F405"
    } else {
        "SITL"
    },
};

/// The application's flight log.
pub struct FlightLog {
    logger: Logger,
    enabled: bool,
    armed: bool,
    logs: u32,
    /// `SDLOG_MODE` and friends, as of the parameter store's change count.
    when: LogParams,
    params_seen: Option<u32>,
}

impl Default for FlightLog {
    fn default() -> Self {
        Self::new()
    }
}

impl FlightLog {
    /// A flight log that is off until the board enables it.
    pub fn new() -> Self {
        Self {
            logger: Logger::new(INFO),
            enabled: false,
            armed: false,
            logs: 0,
            when: (common::logger::params::PARAMS.base)(),
            params_seen: None,
        }
    }

    /// Switches logging on (a board with storage for logs) or off.
    pub fn enable(&mut self, on: bool) {
        self.enabled = on;
        if !on {
            self.logger.stop();
        }
    }

    /// Caps every topic's rate at `hz` (0: the topics' own rates, `docs/LOGGING.md`).
    pub fn set_rate_cap(&mut self, hz: u16) {
        self.logger.set_rate_cap(hz);
    }

    /// Logs started since boot: a board opens a new file (or flash log) when this changes.
    pub fn logs_started(&self) -> u32 {
        self.logs
    }

    /// Whether a log is being recorded.
    pub fn recording(&self) -> bool {
        self.logger.recording()
    }

    /// What the current (or last) log lost and took.
    pub fn stats(&self) -> LogStats {
        self.logger.stats()
    }

    /// The oldest bytes waiting for the storage.
    pub fn pending(&self) -> &[u8] {
        self.logger.pending()
    }

    /// Bytes waiting for the storage in all.
    pub fn pending_len(&self) -> usize {
        self.logger.pending_len()
    }

    /// The storage took the first `n` bytes of [`FlightLog::pending`].
    pub fn consume(&mut self, n: usize) {
        self.logger.consume(n);
    }

    /// After the vehicle took sensor frame `f`: starts a log when `SDLOG_MODE` says (on
    /// arming, or at boot), stops it on disarming, and writes what is due.
    pub(crate) fn after_frame(&mut self, v: &Vehicle, f: &SensorFrame, ground: &GroundFigures) {
        if !self.enabled {
            return;
        }
        let Some(now) = v.time_us() else { return };
        let armed = v.armed();
        // Looked up by name only when a parameter changed: a lookup a frame costs the MCU
        // several thousand instructions.
        let changes = v.params().change_count();
        if self.params_seen != Some(changes) {
            self.params_seen = Some(changes);
            self.when = v.params().load(&common::logger::params::PARAMS);
            let high_rate = self.when.profile & common::logger::params::PROFILE_HIGH_RATE != 0;
            self.logger.set_high_rate(high_rate);
        }
        let when = self.when;
        // A log starts once the last one is drained (the board empties the ring after each
        // frame), so the board never finds two logs' bytes in the ring at once.
        let idle = !self.logger.recording() && self.logger.pending_len() == 0;
        if idle && !self.armed && when.starts(armed, self.logs) {
            self.logger.start(now);
            self.logs = self.logs.wrapping_add(1);
            self.armed = armed;
            // The arming period is the heaviest of all: the log's first bytes wait for the
            // next one.
            return;
        } else if self.logger.recording() && (when.mode < 0 || (!armed && self.armed)) {
            self.logger.stop();
            self.armed = false;
        } else if armed && self.logger.recording() {
            // A log from boot goes on through the flight and ends at its disarming.
            self.armed = true;
        }
        if !self.logger.recording() {
            return;
        }
        self.logger.step(now, v.params());
        v.write_log(&mut self.logger, f);
        if self.logger.due::<TelemetryStatus>(now) {
            let s = ground.stats;
            self.logger.write(
                now,
                &TelemetryStatus {
                    rx_message_count: s.frames_ok,
                    rx_error_count: s
                        .crc_errors
                        .saturating_add(s.unknown_ids)
                        .saturating_add(s.parse_errors)
                        .saturating_add(s.unsupported),
                    tx_dropped_count: ground.tx_dropped,
                    heartbeat_age_ms: ground.heard_us.map_or(u32::MAX, |t| {
                        u32::try_from(now.saturating_sub(t) / 1000).unwrap_or(u32::MAX)
                    }),
                },
            );
        }
    }
}

impl FlightLog {
    /// Whether a text given now is written (a log is past its opening).
    pub(crate) fn takes_texts(&self) -> bool {
        self.enabled && self.logger.writes_samples()
    }

    /// A status text of the vehicle (a failsafe, a mode change, a refusal) sent at `now_us`
    /// into the log, as PX4 logs its `mavlink_log` messages.
    pub(crate) fn text(&mut self, now_us: u64, severity: Severity, text: &str) {
        if !self.enabled || !self.logger.recording() {
            return;
        }
        let level = match severity {
            Severity::Info => Level::Info,
            Severity::Warning => Level::Warning,
            Severity::Critical => Level::Critical,
        };
        self.logger.text(now_us, level, text);
    }
}

/// The ground link's figures the log records.
pub(crate) struct GroundFigures {
    pub(crate) stats: LinkStats,
    pub(crate) tx_dropped: u32,
    pub(crate) heard_us: Option<u64>,
}
