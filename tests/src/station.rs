//! A ground station of the tests' own: a UDP socket, frames encoded and parsed by the
//! `mavlink` crate alone (none of the autopilot's framing code), speaking to an autopilot's
//! ground link as an operator with QGroundControl would: the mission protocol both ways,
//! commands answered by COMMAND_ACK, heartbeats at 1 Hz of the autopilot's clock (until it
//! falls silent, as a lost link does), and a log of what it heard (heartbeats,
//! MISSION_CURRENT, MISSION_ITEM_REACHED, STATUSTEXT, the landed state).

use common::gcs::client::{command_long, gcs_heartbeat};
use mavlink::dialects::common::*;
use mavlink::{MavHeader, MavlinkReader, MavlinkVersion};
use std::collections::VecDeque;
use std::net::{SocketAddr, UdpSocket};
use std::time::{Duration, Instant};

/// The autopilot's identity (DESIGN.md: system 1, component 1).
pub const TARGET: (u8, u8) = (1, 1);
/// This station's identity: QGroundControl's.
pub const ME: (u8, u8) = (255, 190);

/// A free UDP port on the loopback (bound, read back and released for the flight to take).
pub fn free_port() -> u16 {
    UdpSocket::bind("127.0.0.1:0")
        .and_then(|s| s.local_addr())
        .expect("free port")
        .port()
}
/// Everything the station has heard that a test asserts on, whatever it was waiting for.
#[derive(Default)]
pub struct Log {
    /// Heartbeats of the autopilot: (armed, custom_mode), in arrival order.
    pub heartbeats: Vec<(bool, u32)>,
    /// MISSION_CURRENT: (seq, total, mission_state, mission_id).
    pub current: Vec<(u16, u16, MissionState, u32)>,
    /// MISSION_ITEM_REACHED, in arrival order.
    pub reached: Vec<u16>,
    /// STATUSTEXTs.
    pub texts: Vec<String>,
    /// Frames that were not from the autopilot.
    pub foreign: usize,
    /// Frames the `mavlink` crate could not parse.
    pub unparsed: usize,
    /// HOME_POSITION while the last heartbeat said armed: (latitude, longitude, altitude in
    /// mm), in arrival order.
    pub armed_homes: Vec<(i32, i32, i32)>,
    /// GLOBAL_POSITION_INT while armed: altitude above sea level less height above home, mm
    /// (home's altitude in the aircraft's datum).
    pub armed_datums: Vec<i32>,
    /// EXTENDED_SYS_STATE's landed state, each time it changed.
    pub landed_states: Vec<MavLandedState>,
}

/// The ground station.
pub struct Station {
    socket: UdpSocket,
    to: SocketAddr,
    sequence: u8,
    /// Messages heard and not yet passed over by [`Station::wait`].
    pub inbox: VecDeque<MavMessage>,
    /// What the tests assert on.
    pub log: Log,
    /// The autopilot's clock, from its time-stamped telemetry, ms.
    pub autopilot_ms: Option<u32>,
    /// Its clock when this station last sent a heartbeat, ms.
    heartbeat_ms: Option<u32>,
    heartbeat_wall: Instant,
    /// The link is lost the autopilot's way: this station keeps listening and sends nothing
    /// more, heartbeats included.
    pub silent: bool,
}

impl Station {
    /// A station on `socket` speaking to the autopilot's port `to`.
    pub fn new(socket: UdpSocket, to: SocketAddr) -> Self {
        socket.set_nonblocking(true).expect("non-blocking");
        let mut s = Self {
            socket,
            to,
            sequence: 0,
            inbox: VecDeque::new(),
            log: Log::default(),
            autopilot_ms: None,
            heartbeat_ms: None,
            heartbeat_wall: Instant::now(),
            silent: false,
        };
        s.heartbeat();
        s
    }

    /// Sends one frame.
    pub fn send(&mut self, m: &MavMessage) {
        assert!(!self.silent, "a silent station sends nothing");
        let header = MavHeader {
            system_id: u32::from(ME.0),
            component_id: ME.1,
            sequence: self.sequence,
        };
        self.sequence = self.sequence.wrapping_add(1);
        let mut buf = Vec::with_capacity(300);
        mavlink::write_v2_msg(&mut buf, header, m).expect("encode");
        self.socket.send_to(&buf, self.to).expect("send");
    }

    /// Sends a heartbeat now.
    pub fn heartbeat(&mut self) {
        self.send(&gcs_heartbeat());
        self.heartbeat_ms = self.autopilot_ms;
        self.heartbeat_wall = Instant::now();
    }

    /// Sends the heartbeat when due: 1 Hz of the autopilot's clock (what QGroundControl sends
    /// to a vehicle flying in real time; at 1 Hz of wall time this faster-than-real-time
    /// autopilot would hear it only every `SPEED` seconds and call the link lost), and at
    /// least 1 Hz of wall time while its clock is not known.
    fn heartbeat_if_due(&mut self) {
        if self.silent {
            return;
        }
        let due = match (self.autopilot_ms, self.heartbeat_ms) {
            (Some(now), Some(last)) => now.saturating_sub(last) >= 1000,
            (Some(_), None) => true,
            (None, _) => self.heartbeat_wall.elapsed() >= Duration::from_secs(1),
        };
        if due {
            self.heartbeat();
        }
    }

    /// Takes every waiting datagram, logs what the tests read, keeps the heartbeat going.
    pub fn pump(&mut self) {
        let mut buf = [0u8; 65536];
        loop {
            let n = match self.socket.recv_from(&mut buf) {
                Ok((n, _)) => n,
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => break,
                // The autopilot's port not open yet (ICMP from an earlier send).
                Err(e) if e.kind() == std::io::ErrorKind::ConnectionRefused => continue,
                Err(e) => panic!("receive: {e}"),
            };
            let mut reader = MavlinkReader::new(&buf[..n]);
            loop {
                match reader.read_message::<MavMessage>(MavlinkVersion::V2) {
                    Ok((h, m)) => self.take(h, m),
                    Err(mavlink::error::MessageReadError::Io(_)) => break,
                    // A frame the dialect does not parse: counted, skipped.
                    Err(mavlink::error::MessageReadError::Parse(_)) => {
                        self.log.unparsed += 1;
                        if self.log.unparsed > 10_000 {
                            panic!("the autopilot's frames do not parse");
                        }
                    }
                }
            }
        }
        self.heartbeat_if_due();
        std::thread::sleep(Duration::from_millis(1));
    }

    /// Whether the autopilot's last heartbeat said armed.
    fn armed(&self) -> bool {
        self.log.heartbeats.last().is_some_and(|h| h.0)
    }

    fn take(&mut self, h: MavHeader, m: MavMessage) {
        if (h.system_id, h.component_id) != (u32::from(TARGET.0), TARGET.1) {
            self.log.foreign += 1;
            return;
        }
        let stamp = match &m {
            MavMessage::ATTITUDE(a) => Some(a.time_boot_ms),
            MavMessage::GLOBAL_POSITION_INT(g) => Some(g.time_boot_ms),
            _ => None,
        };
        if let Some(t) = stamp {
            self.autopilot_ms = Some(self.autopilot_ms.map_or(t, |a| a.max(t)));
        }
        match &m {
            MavMessage::HEARTBEAT(hb) => self.log.heartbeats.push((
                hb.base_mode
                    .contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED),
                hb.custom_mode,
            )),
            MavMessage::MISSION_CURRENT(c) => {
                self.log
                    .current
                    .push((c.seq, c.total, c.mission_state, c.mission_id))
            }
            MavMessage::MISSION_ITEM_REACHED(r) => self.log.reached.push(r.seq),
            MavMessage::HOME_POSITION(p) if self.armed() => {
                self.log
                    .armed_homes
                    .push((p.latitude, p.longitude, p.altitude))
            }
            MavMessage::GLOBAL_POSITION_INT(g) if self.armed() => {
                self.log.armed_datums.push(g.alt - g.relative_alt)
            }
            MavMessage::EXTENDED_SYS_STATE(x)
                if self.log.landed_states.last() != Some(&x.landed_state) =>
            {
                self.log.landed_states.push(x.landed_state)
            }
            MavMessage::STATUSTEXT(t) => self
                .log
                .texts
                .push(t.text.to_str().unwrap_or("?").to_string()),
            _ => {}
        }
        self.inbox.push_back(m);
    }

    /// Waits up to `secs` of wall time for the first message `pick` accepts; what it passes
    /// over is dropped (the log has kept what matters).
    pub fn wait<T>(
        &mut self,
        secs: f64,
        mut pick: impl FnMut(&MavMessage) -> Option<T>,
    ) -> Option<T> {
        let end = Instant::now() + Duration::from_secs_f64(secs);
        loop {
            while let Some(m) = self.inbox.pop_front() {
                if let Some(t) = pick(&m) {
                    return Some(t);
                }
            }
            if Instant::now() >= end {
                return None;
            }
            self.pump();
        }
    }

    /// Sends a COMMAND_LONG and waits up to 2 s for its COMMAND_ACK.
    pub fn command(&mut self, cmd: MavCmd, p: [f32; 7]) -> Option<MavResult> {
        self.send(&command_long(cmd, p));
        self.wait(2.0, |m| match m {
            MavMessage::COMMAND_ACK(a) if a.command == cmd => Some(a.result),
            _ => None,
        })
    }

    /// The mission protocol's upload: MISSION_COUNT, then each item the autopilot asks for
    /// with MISSION_REQUEST_INT, until its MISSION_ACK. Returns the ACK and the requests in
    /// the order they came.
    pub fn upload(&mut self, items: &[MISSION_ITEM_INT_DATA]) -> (MISSION_ACK_DATA, Vec<u16>) {
        self.inbox.clear();
        self.send(&MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
            count: items.len() as u16,
            target_system: TARGET.0,
            target_component: TARGET.1,
            mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
            opaque_id: 0,
        }));
        let mut requests = Vec::new();
        let end = Instant::now() + Duration::from_secs(10);
        while Instant::now() < end {
            self.pump();
            while let Some(m) = self.inbox.pop_front() {
                match m {
                    MavMessage::MISSION_REQUEST_INT(r)
                        if r.mission_type == MavMissionType::MAV_MISSION_TYPE_MISSION
                            && (r.target_system, r.target_component) == ME =>
                    {
                        requests.push(r.seq);
                        let item = items
                            .get(usize::from(r.seq))
                            .unwrap_or_else(|| {
                                panic!("request for item {} of {}", r.seq, items.len())
                            })
                            .clone();
                        self.send(&MavMessage::MISSION_ITEM_INT(item));
                    }
                    MavMessage::MISSION_ACK(a)
                        if a.mission_type == MavMissionType::MAV_MISSION_TYPE_MISSION =>
                    {
                        assert_eq!(
                            (a.target_system, a.target_component),
                            ME,
                            "ACK addressed to the uploader"
                        );
                        return (a, requests);
                    }
                    _ => {}
                }
            }
        }
        panic!("no MISSION_ACK within 10 s (requests so far {requests:?})");
    }

    /// The mission protocol's download: MISSION_REQUEST_LIST, MISSION_COUNT, each item with
    /// MISSION_REQUEST_INT (asked again after 0.5 s without an answer), then MISSION_ACK.
    pub fn download(&mut self) -> Vec<MISSION_ITEM_INT_DATA> {
        self.inbox.clear();
        let list = MavMessage::MISSION_REQUEST_LIST(MISSION_REQUEST_LIST_DATA {
            target_system: TARGET.0,
            target_component: TARGET.1,
            mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        });
        let mut count = None;
        for _ in 0..5 {
            self.send(&list);
            count = self.wait(0.5, |m| match m {
                MavMessage::MISSION_COUNT(c)
                    if c.mission_type == MavMissionType::MAV_MISSION_TYPE_MISSION =>
                {
                    Some(c.count)
                }
                _ => None,
            });
            if count.is_some() {
                break;
            }
        }
        let count = count.expect("MISSION_COUNT");
        let mut items = Vec::new();
        for seq in 0..count {
            let request = MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
                seq,
                target_system: TARGET.0,
                target_component: TARGET.1,
                mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
            });
            let mut got = None;
            for _ in 0..5 {
                self.send(&request);
                got = self.wait(0.5, |m| match m {
                    MavMessage::MISSION_ITEM_INT(i) if i.seq == seq => Some(i.clone()),
                    _ => None,
                });
                if got.is_some() {
                    break;
                }
            }
            items.push(got.unwrap_or_else(|| panic!("item {seq} of {count}")));
        }
        self.send(&MavMessage::MISSION_ACK(MISSION_ACK_DATA {
            target_system: TARGET.0,
            target_component: TARGET.1,
            mavtype: MavMissionResult::MAV_MISSION_ACCEPTED,
            mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
            opaque_id: 0,
        }));
        items
    }

    /// Arms, retrying every `retry_s` of the autopilot's time while the pre-arm checks refuse
    /// (the estimator converges first), for at most `within` of wall time. Returns the
    /// autopilot's clock when it accepted (ms) and the refusals before.
    pub fn arm(&mut self, within: Duration, retry_s: f64, speed: f64) -> (Option<u32>, usize) {
        let mut refusals = 0;
        let end = Instant::now() + within;
        loop {
            assert!(
                Instant::now() < end,
                "not armed after {refusals} refusals: {:?}",
                self.log.texts
            );
            match self.command(
                MavCmd::MAV_CMD_COMPONENT_ARM_DISARM,
                [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            ) {
                Some(MavResult::MAV_RESULT_ACCEPTED) => return (self.autopilot_ms, refusals),
                Some(MavResult::MAV_RESULT_DENIED | MavResult::MAV_RESULT_TEMPORARILY_REJECTED) => {
                    refusals += 1;
                    std::thread::sleep(Duration::from_secs_f64(retry_s / speed));
                }
                other => panic!("arming answered {other:?}"),
            }
        }
    }

    /// Sets a parameter (PARAM_SET) and waits up to 2 s for the PARAM_VALUE that confirms it.
    pub fn set_param(&mut self, name: &str, value: f32) -> bool {
        self.send(&MavMessage::PARAM_SET(PARAM_SET_DATA {
            param_value: value,
            target_system: TARGET.0,
            target_component: TARGET.1,
            param_id: name.into(),
            param_type: MavParamType::MAV_PARAM_TYPE_REAL32,
        }));
        self.wait(2.0, |m| match m {
            MavMessage::PARAM_VALUE(v) if v.param_id.to_str().is_ok_and(|id| id == name) => {
                Some(v.param_value == value)
            }
            _ => None,
        })
        .unwrap_or(false)
    }

    /// Waits up to `secs` for the autopilot's heartbeat and checks that it describes a fixed
    /// wing with a generic autopilot (DESIGN.md's identity).
    pub fn fixed_wing_heartbeat(&mut self, secs: f64) -> HEARTBEAT_DATA {
        let hb = self
            .wait(secs, |m| match m {
                MavMessage::HEARTBEAT(h) => Some(h.clone()),
                _ => None,
            })
            .expect("the autopilot's heartbeat");
        assert_eq!(hb.mavtype, MavType::MAV_TYPE_FIXED_WING);
        assert_eq!(hb.autopilot, MavAutopilot::MAV_AUTOPILOT_GENERIC);
        hb
    }
}
