//! Lock-step exchange: one sensor frame out, one actuator frame back, then the plant moves.

use super::tlog::TlogWriter;
use super::transport::Transport;
use common::gcs::SYSTEM_ID;
use common::link::framing::{encode_v2, Frame, FrameParser, LinkStats, Sender};
use common::link::simlink::{self, ActuatorFrame};
use mavlink::dialects::common::MavMessage;
use std::io;
use std::time::{Duration, Instant};

/// Component id of the simulator (MAV_COMP_ID_USER27, unused by real vehicles' components).
/// The simulator speaks for the vehicle's sensors, so its system is the autopilot's own
/// ([`SYSTEM_ID`]: the autopilot takes simulator frames from its own system only).
pub const SIM_COMPONENT_ID: u8 = 51;

/// Why an exchange failed.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    /// The autopilot did not answer a sensor frame in time.
    #[error("the autopilot is silent: no HIL_ACTUATOR_CONTROLS for the frame at t = {time_s:.3} s within {waited:?} ({frames} frames answered before){}", why.as_ref().map(|w| format!("; {w}")).unwrap_or_default())]
    Silent {
        /// Simulation time of the unanswered frame, s.
        time_s: f64,
        /// How long we waited.
        waited: Duration,
        /// Frames answered before this one.
        frames: u64,
        /// What the transport knows of the autopilot's state (its process ended, ...).
        why: Option<String>,
    },
    /// The transport failed.
    #[error("simulator link: {0}")]
    Io(#[from] io::Error),
}

/// The simulator end of a lock-step link.
pub struct Lockstep<T: Transport> {
    transport: T,
    parser: FrameParser,
    sender: Sender,
    tlog: Option<TlogWriter>,
    timeout: Duration,
    answered: u64,
    heard: bool,
    buf: Vec<u8>,
    rx: Vec<u8>,
}

impl<T: Transport> Lockstep<T> {
    /// Wraps a transport; an exchange fails after `timeout` without an answer.
    pub fn new(transport: T, timeout: Duration) -> Self {
        Self {
            transport,
            parser: FrameParser::new(),
            sender: Sender::new(SYSTEM_ID, SIM_COMPONENT_ID),
            tlog: None,
            timeout,
            answered: 0,
            heard: false,
            buf: Vec::with_capacity(512),
            rx: vec![0; 4096],
        }
    }

    /// Records every frame, both ways, into `tlog`.
    pub fn with_tlog(mut self, tlog: TlogWriter) -> Self {
        self.tlog = Some(tlog);
        self
    }

    /// The transport.
    pub fn transport(&self) -> &T {
        &self.transport
    }

    /// The transport, mutably (e.g. to reach an in-process autopilot between exchanges).
    pub fn transport_mut(&mut self) -> &mut T {
        &mut self.transport
    }

    /// Framing counters of what the autopilot sent.
    pub fn stats(&self) -> LinkStats {
        self.parser.stats()
    }

    /// Frames answered so far.
    pub fn answered(&self) -> u64 {
        self.answered
    }

    /// Flushes and returns the log, if any.
    pub fn finish(mut self) -> io::Result<Option<TlogWriter>> {
        if let Some(t) = self.tlog.as_mut() {
            t.flush()?;
        }
        Ok(self.tlog)
    }

    /// Waits until the autopilot has spoken (its boot heartbeat): a UART drops what arrives
    /// before the autopilot has enabled it, and a UDP simulator learns its peer that way, so
    /// no sensor frame is sent before.
    ///
    /// Once the autopilot has spoken, this returns at once (a caller may wait in slices).
    pub fn wait_for_autopilot(&mut self, timeout: Duration) -> Result<(), LinkError> {
        if self.heard {
            return Ok(());
        }
        self.await_frame(0, timeout, |f| {
            (f.header.system_id == u32::from(SYSTEM_ID)).then_some(())
        })?;
        self.heard = true;
        Ok(())
    }

    /// Sends `messages` (stamped `time_us`) in one write and waits for the autopilot's
    /// `HIL_ACTUATOR_CONTROLS` for that time. Other frames from the autopilot are logged and
    /// passed over.
    pub fn exchange(
        &mut self,
        time_us: u64,
        messages: &[MavMessage],
    ) -> Result<ActuatorFrame, LinkError> {
        self.buf.clear();
        for m in messages {
            let raw = self.sender.encode(m);
            if let Some(t) = self.tlog.as_mut() {
                t.write(time_us, raw.raw_bytes())?;
            }
            self.buf.extend_from_slice(raw.raw_bytes());
        }
        self.transport.send(&self.buf)?;
        let answer = self.await_frame(time_us, self.timeout, |f| match &f.message {
            MavMessage::HIL_ACTUATOR_CONTROLS(d) if d.time_usec == time_us => {
                Some(simlink::decode_actuators(d))
            }
            _ => None,
        })?;
        self.answered += 1;
        Ok(answer)
    }

    /// Reads the autopilot's frames, logging each at `time_us`, until `pick` accepts one; a
    /// link quiet for longer than `timeout` is a silent autopilot.
    fn await_frame<R>(
        &mut self,
        time_us: u64,
        timeout: Duration,
        mut pick: impl FnMut(&Frame) -> Option<R>,
    ) -> Result<R, LinkError> {
        let start = Instant::now();
        loop {
            let n = match self.transport.recv(&mut self.rx, Duration::from_millis(50)) {
                Ok(n) => n,
                // A signal cut the wait short: nothing arrived, the wait goes on.
                Err(e) if e.kind() == io::ErrorKind::Interrupted => 0,
                Err(e) => return Err(e.into()),
            };
            let mut found = None;
            let tlog = &mut self.tlog;
            let mut log_err = Ok(());
            self.parser.push(&self.rx[..n], |f| {
                if let Some(t) = tlog.as_mut() {
                    // Re-encoding a parsed MAVLink 2 frame gives back its bytes (same header,
                    // same trimmed payload); the autopilot sends nothing else.
                    let raw = encode_v2(f.header, &f.message);
                    if let Err(e) = t.write(time_us, raw.raw_bytes()) {
                        log_err = Err(e);
                    }
                }
                if found.is_none() {
                    found = pick(&f);
                }
            });
            log_err?;
            if let Some(r) = found {
                return Ok(r);
            }
            if n == 0 && start.elapsed() > timeout {
                return Err(LinkError::Silent {
                    time_s: time_us as f64 * 1e-6,
                    waited: timeout,
                    frames: self.answered,
                    why: self.transport.diagnose(),
                });
            }
        }
    }
}
