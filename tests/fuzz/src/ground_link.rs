//! The ground link of the application (`App::on_gcs_bytes` and `App::on_gcs_datagram`) over
//! sequences of ground-station messages from several stations on several channels, as whole
//! datagrams, as a byte stream cut anywhere, with garbage and corrupt frames, while sensor
//! frames move the vehicle's clock.
//!
//! Asserted: every frame sent decodes and names the autopilot, on a channel the board has; the
//! heartbeat comes at least once a second of vehicle time; every `COMMAND_LONG` and
//! `COMMAND_INT` addressed to us gets exactly one `COMMAND_ACK`, for its command, addressed
//! to its sender and on its channel; every `PARAM_VALUE` is the value the store holds and
//! every stored value passes its checks; the simulator's answers stay in range. With a
//! signing key set (`SETUP_SIGNING` among the messages), a datagram unsigned, signed with
//! another key or replaying a timestamp is not obeyed (no `COMMAND_ACK`, no parameter or plan
//! changed) and every frame sent is signed with the key; every FTP reply carrying file data
//! carries a served file's bytes at its offset.

use std::collections::BTreeMap;

use arbitrary::Arbitrary;
use common::gcs::signing::MAX_TIMESTAMP;
use common::gcs::Dest;
use common::link::framing::Sender;
use firmware::app::App;
use mavlink::dialects::common::*;
use mavlink::Message;

use crate::frames::{calm_fix, calm_sensors, frame, raw_frame, Simulator, Wobble};
use crate::gcs::{Built, GcsMsg};
use crate::watch::{after_ground, check_controls, sim_answers, Heartbeat};

/// Who sends: one of a few stations (two share an address on different channels).
#[derive(Arbitrary, Clone, Copy, Debug)]
pub struct Station(u8);

const STATIONS: [(u8, u8, u8); 5] = [
    (255, 190, 1),
    (255, 190, 2),
    (254, 1, 3),
    (1, 1, 4),
    (0, 0, 5),
];

impl Station {
    fn get(self) -> (u8, u8, u8) {
        STATIONS[usize::from(self.0) % STATIONS.len()]
    }
}

/// What happens next on the ground side.
#[derive(Arbitrary, Clone, Debug)]
pub enum GroundAction {
    /// One datagram holding these messages from one station, signed or not.
    Datagram {
        from: Station,
        msgs: Vec<GcsMsg>,
        sig: Sig,
    },
    /// The messages as a byte stream on the single-link channel, in reads cut at `cuts`.
    Stream { msgs: Vec<GcsMsg>, cuts: Vec<u8> },
    /// A datagram of bytes that are no frame, or a frame with one byte changed.
    Garbage { channel: u8, bytes: Vec<u8> },
    Corrupt {
        from: Station,
        msg: GcsMsg,
        at: u16,
        xor: u8,
    },
    /// Sensor frames of an aircraft at rest: the clock moves on, the link polls.
    Time { frames: u8, wobble: Wobble },
}

/// How a datagram's frames are signed (MAVLink 2 signing, the link id being the channel).
#[derive(Arbitrary, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sig {
    Unsigned,
    /// With the vehicle's key and a fresh timestamp.
    Good,
    /// With another key.
    WrongKey,
    /// With the key and the last timestamp the vehicle accepted from this stream.
    Replay,
}

struct Harness {
    app: App,
    sim: Simulator,
    senders: BTreeMap<(u8, u8), Sender>,
    raw_us: u64,
    heartbeat: Heartbeat,
    /// The last timestamp signed with `Sig::Good`, per stream (system, component, link id);
    /// forgotten when the vehicle's key changes.
    signed: BTreeMap<(u8, u8, u8), u64>,
    key_changes: u32,
}

impl Harness {
    fn encode(&mut self, from: (u8, u8), m: &GcsMsg) -> Option<(Vec<u8>, Option<MavMessage>)> {
        let tx = self
            .senders
            .entry(from)
            .or_insert_with(|| Sender::new(from.0, from.1));
        match m.build(self.app.vehicle().params())? {
            Built::Typed(msg) => Some((frame(tx, &msg), Some(msg))),
            Built::Raw(id, p) => Some((raw_frame(tx, id, &p)?, None)),
        }
    }

    /// Signs `frame` of stream `stream` as `sig` says; a replay of a stream with no accepted
    /// timestamp, and any signature while signing is off, leave it unsigned.
    fn sign(&mut self, frame: Vec<u8>, stream: (u8, u8, u8), sig: Sig) -> Vec<u8> {
        let signing = self.app.ground_link().signing();
        if signing.change_count() != self.key_changes {
            self.key_changes = signing.change_count();
            self.signed.clear();
        }
        let Some(key) = signing.key().copied() else {
            return frame;
        };
        let fresh = signing.timestamp().saturating_add(1);
        let (key, t) = match sig {
            Sig::Unsigned => return frame,
            Sig::Good => {
                let t = self.signed.get(&stream).map_or(fresh, |t| fresh.max(t + 1));
                self.signed.insert(stream, t);
                (key, t)
            }
            Sig::WrongKey => (key.map(|b| !b), fresh),
            Sig::Replay => match self.signed.get(&stream) {
                Some(t) => (key, *t),
                None => return frame,
            },
        };
        common::link::signing::sign(&frame, &key, stream.2, t)
            .expect("a frame of the dialect signs")
            .to_vec()
    }

    /// After a call that ran the ground link.
    fn check(&mut self) -> Vec<crate::watch::Sent> {
        after_ground(&mut self.app, &mut self.heartbeat)
    }

    fn step(&mut self, a: &GroundAction) {
        match a {
            GroundAction::Datagram { from, msgs, sig } => {
                let (sys, comp, channel) = from.get();
                // With a key set, only frames signed with it and fresh are obeyed.
                let signing = self.app.ground_link().signing();
                let locked = signing.key().is_some();
                let obeyed = !locked || *sig == Sig::Good;
                // Near the end of the 48-bit signing time (a key set up for then), fresh
                // timestamps run out: whether a frame is obeyed is not told here.
                let mut predictable = !locked || signing.timestamp() < MAX_TIMESTAMP - 1000;
                let mut bytes = Vec::new();
                // Commands owed an answer: (command, count). Only typed ones: a raw payload
                // may or may not decode.
                let mut owed: BTreeMap<u32, usize> = BTreeMap::new();
                for m in msgs.iter().take(24) {
                    let Some((f, typed)) = self.encode((sys, comp), m) else {
                        continue;
                    };
                    let f = self.sign(f, (sys, comp, channel), *sig);
                    bytes.extend_from_slice(&f);
                    match typed {
                        // A new key changes what the frames behind it are.
                        Some(MavMessage::SETUP_SIGNING(_)) => predictable = false,
                        Some(msg) => {
                            if let Some(c) = command_for_us(&msg, (sys, comp)) {
                                if obeyed {
                                    *owed.entry(c).or_default() += 1;
                                }
                            }
                        }
                        None => predictable = false,
                    }
                }
                let dropped = self.app.ground_link().dropped();
                let (params, plan) = (
                    self.app.vehicle().params().change_count(),
                    self.app.vehicle().plan().change_count(),
                );
                self.app.on_gcs_datagram(channel, &bytes);
                if !obeyed {
                    assert_eq!(
                        self.app.vehicle().params().change_count(),
                        params,
                        "with a key set, a parameter changed by a frame not signed with it"
                    );
                    assert_eq!(
                        self.app.vehicle().plan().change_count(),
                        plan,
                        "with a key set, a plan changed by a frame not signed with it"
                    );
                }
                let sent = self.check();
                if predictable && self.app.ground_link().dropped() == dropped {
                    let mut acked: BTreeMap<u32, usize> = BTreeMap::new();
                    for s in &sent {
                        if let MavMessage::COMMAND_ACK(a) = &s.message {
                            assert_eq!(s.dest, Dest::Channel(channel), "an ACK on its channel");
                            assert_eq!(
                                (a.target_system, a.target_component),
                                (sys, comp),
                                "an ACK addressed to its sender"
                            );
                            *acked.entry(a.command as u32).or_default() += 1;
                        }
                    }
                    assert_eq!(acked, owed, "one COMMAND_ACK per command");
                }
            }
            GroundAction::Stream { msgs, cuts } => {
                let mut bytes = Vec::new();
                for m in msgs.iter().take(24) {
                    if let Some((f, _)) = self.encode((255, 190), m) {
                        bytes.extend_from_slice(&f);
                    }
                }
                let mut rest: &[u8] = &bytes;
                for c in cuts {
                    let (a, b) = rest.split_at(usize::from(*c).min(rest.len()));
                    self.app.on_gcs_bytes(a);
                    self.check();
                    rest = b;
                }
                self.app.on_gcs_bytes(rest);
                self.check();
            }
            GroundAction::Garbage { channel, bytes } => {
                self.app.on_gcs_datagram(*channel % 10, bytes);
                if usize::from(*channel % 10) < firmware::app::ground::CHANNELS {
                    self.check();
                }
            }
            GroundAction::Corrupt { from, msg, at, xor } => {
                let (sys, comp, channel) = from.get();
                if let Some((mut f, _)) = self.encode((sys, comp), msg) {
                    let i = usize::from(*at) % f.len();
                    f[i] ^= (*xor).max(1);
                    self.app.on_gcs_datagram(channel, &f);
                    self.check();
                }
            }
            GroundAction::Time { frames, wobble } => {
                for k in 0..u32::from(*frames).min(120) {
                    self.raw_us += 10_000;
                    let mut bytes = Vec::new();
                    if k % 10 == 0 {
                        bytes.extend(self.sim.gps(self.raw_us, &calm_fix((0, 0), 0)));
                    }
                    bytes.extend(self.sim.sensors(&calm_sensors(self.raw_us, wobble)));
                    let mut out = Vec::new();
                    self.app
                        .on_sim_bytes(&bytes, &mut |b| out.extend_from_slice(b));
                    let answers = sim_answers(&out);
                    assert_eq!(answers.len(), 1, "one answer per sensor frame");
                    for a in &answers {
                        check_controls(a, a.mode.contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED));
                    }
                    self.check();
                }
            }
        }
    }
}

/// The command of a `COMMAND_LONG` or `COMMAND_INT` this autopilot must answer: addressed to
/// it (or broadcast) and not an echo of its own. `SET_MODE` is answered as `DO_SET_MODE`, as
/// PX4 does.
fn command_for_us(m: &MavMessage, from: (u8, u8)) -> Option<u32> {
    let c = match m {
        MavMessage::COMMAND_LONG(d) => d.command,
        MavMessage::COMMAND_INT(d) => d.command,
        MavMessage::SET_MODE(_) => MavCmd::MAV_CMD_DO_SET_MODE,
        _ => return None,
    };
    let ours = |t: Option<u8>, id: u8| t.is_none_or(|t| t == 0 || t == id);
    let to_us = ours(m.target_system_id(), common::gcs::SYSTEM_ID)
        && ours(m.target_component_id(), common::gcs::COMPONENT_ID);
    let echo = from == (common::gcs::SYSTEM_ID, common::gcs::COMPONENT_ID);
    (to_us && !echo).then_some(c as u32)
}

/// Runs one input.
pub fn run(data: &[u8]) {
    let mut h = Harness {
        app: App::new(),
        sim: Simulator::default(),
        senders: BTreeMap::new(),
        raw_us: 0,
        heartbeat: Heartbeat::default(),
        signed: BTreeMap::new(),
        key_changes: 0,
    };
    crate::each_action(data, 200, |a: &GroundAction| h.step(a));
}
