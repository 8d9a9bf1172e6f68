//! What the autopilot sends back, decoded, and the invariants every target shares: the
//! actuator answers are finite and in range, the heartbeat keeps coming, and a parameter read
//! back is the value in use.

use common::gcs::Dest;
use common::link::framing::FrameParser;
use common::params::store::{encode_wire, param_id_str};
use common::params::ParamStore;
use firmware::app::App;
use mavlink::dialects::common::{
    MavMessage, MavParamType, FILE_TRANSFER_PROTOCOL_DATA, HIL_ACTUATOR_CONTROLS_DATA,
};
use mavlink::MavHeader;

/// One frame the autopilot sent to its ground stations.
#[derive(Clone, Debug)]
pub struct Sent {
    pub dest: Dest,
    pub header: MavHeader,
    pub message: MavMessage,
}

/// Everything waiting for the ground stations, decoded. Each piece handed out must be one
/// valid frame; it may not decode (an acknowledgement of a command the dialect has no name
/// for carries that command's number), and then only its header is checked.
pub fn drain(app: &mut App) -> Vec<Sent> {
    let mut out = Vec::new();
    let mut bad = 0usize;
    // With signing on, every frame sent is signed with the key.
    let key = app.ground_link().signing().key().copied();
    app.drain_gcs_to(&mut |dest, bytes| {
        let mut p = FrameParser::new();
        p.set_key(key);
        let n = core::cell::Cell::new(0);
        p.push_with(
            bytes,
            |f| {
                n.set(n.get() + 1);
                if key.is_some() {
                    assert!(
                        f.signed.is_some_and(|s| s.valid),
                        "with a key set, a frame sent unsigned or badly signed: {:?}",
                        f.message
                    );
                }
                out.push(Sent {
                    dest,
                    header: f.header,
                    message: f.message,
                })
            },
            |raw| {
                n.set(n.get() + 1);
                assert_eq!(
                    raw.id, 77,
                    "only a COMMAND_ACK may carry a number unknown to the dialect"
                );
                assert_eq!((raw.header.system_id, raw.header.component_id), (1, 1));
            },
        );
        if n.get() != 1 || p.stats().bytes_skipped != 0 {
            bad += 1;
        }
    });
    assert_eq!(
        bad, 0,
        "a frame to the ground station is not one valid frame"
    );
    for s in &out {
        assert_eq!(
            (s.header.system_id, s.header.component_id),
            (1, 1),
            "every frame names the autopilot"
        );
        if let MavMessage::FILE_TRANSFER_PROTOCOL(d) = &s.message {
            check_ftp_data(d);
        }
        if let Dest::Channel(c) = s.dest {
            assert!(
                usize::from(c) < firmware::app::ground::CHANNELS,
                "an answer for a channel the board does not have: {c}"
            );
        }
    }
    out
}

/// An FTP reply carrying file data (an `ACK` of `ReadFile` or `BurstReadFile`) carries the
/// bytes of a served file at its offset, at least one.
fn check_ftp_data(d: &FILE_TRANSFER_PROTOCOL_DATA) {
    let p = &d.payload;
    let (opcode, size, req) = (p[3], usize::from(p[4]), p[5]);
    if opcode != 128 || !(req == 5 || req == 15) {
        return;
    }
    let offset = u32::from_le_bytes([p[8], p[9], p[10], p[11]]) as usize;
    assert!(
        size > 0 && size <= 239,
        "an FTP read answered with {size} bytes"
    );
    let data = &p[12..12 + size];
    assert!(
        firmware::app::ground::FILES
            .iter()
            .any(|f| f.bytes.get(offset..offset + size) == Some(data)),
        "FTP data at {offset} that no served file holds there"
    );
}

/// The answers on the simulator link, decoded.
pub fn sim_answers(bytes: &[u8]) -> Vec<HIL_ACTUATOR_CONTROLS_DATA> {
    let mut p = FrameParser::new();
    let mut out = Vec::new();
    p.push(bytes, |f| match f.message {
        MavMessage::HIL_ACTUATOR_CONTROLS(d) => out.push(d),
        other => panic!("the simulator link carries only actuator answers, not {other:?}"),
    });
    assert_eq!(p.stats().bytes_skipped, 0, "stray bytes to the simulator");
    out
}

/// Every control finite and within its range: roll, pitch, yaw in [-1, 1], throttle in
/// [0, 1] and zero while disarmed, the unused channels zero.
pub fn check_controls(d: &HIL_ACTUATOR_CONTROLS_DATA, armed: bool) {
    for (i, c) in d.controls.iter().enumerate() {
        assert!(c.is_finite(), "control {i} is {c}: {d:?}");
        let ok = match i {
            0..=2 => (-1.0..=1.0).contains(c),
            3 => (0.0..=1.0).contains(c) && (armed || *c == 0.0),
            _ => *c == 0.0,
        };
        assert!(
            ok,
            "control {i} = {c} out of its range (armed {armed}): {d:?}"
        );
    }
}

/// A `PARAM_VALUE` is the value the store holds, under its name and index, in the wire
/// encoding of its kind.
pub fn check_param_value(m: &MavMessage, store: &ParamStore) {
    let MavMessage::PARAM_VALUE(v) = m else {
        return;
    };
    let name = param_id_str(&v.param_id[..]).expect("an ASCII name");
    let index = store
        .index_of(name)
        .unwrap_or_else(|| panic!("PARAM_VALUE of an unknown name {name}"));
    assert_eq!(usize::from(v.param_index), index, "{name}: index");
    assert_eq!(usize::from(v.param_count), store.len(), "{name}: count");
    let def = store.def(index).expect("a definition");
    let held = store.value(index).expect("a value");
    let wire = encode_wire(def.kind, held);
    assert_eq!(
        v.param_value.to_bits(),
        wire.to_bits(),
        "{name}: PARAM_VALUE {} but the store holds {held}",
        v.param_value
    );
    let int = v.param_type == MavParamType::MAV_PARAM_TYPE_INT32;
    assert_eq!(int, def.kind.is_integer(), "{name}: type");
}

/// Every value the store holds passes its definition and its stage's rule.
pub fn check_store(store: &ParamStore) {
    let mut start = 0;
    for stage in store.registry().iter() {
        let mut values = Vec::new();
        for i in 0..stage.len() {
            let def = stage.def(i).expect("a definition");
            let v = store.value(start + i).expect("a value");
            assert_eq!(def.check(v), Ok(v), "{} = {v}", def.name);
            values.push(v);
        }
        assert_eq!(stage.check(&values), Ok(()), "stage {}", stage.name());
        start += stage.len();
    }
}

/// `sent` holds a heartbeat to every station.
fn broadcasts_heartbeat(sent: &[Sent]) -> bool {
    sent.iter()
        .any(|s| matches!(s.message, MavMessage::HEARTBEAT(_)) && s.dest == Dest::All)
}

/// The heartbeat: whenever the ground link runs at a vehicle time a second or more after the
/// last heartbeat, it sends one.
#[derive(Default)]
pub struct Heartbeat {
    last_us: Option<u64>,
}

impl Heartbeat {
    /// After a call that may not have run the ground link (a datagram that asked nothing): a
    /// heartbeat it sent is recorded, none is asked of it.
    pub fn note(&mut self, now_us: u64, sent: &[Sent]) {
        if broadcasts_heartbeat(sent) {
            self.last_us = Some(now_us);
        }
    }

    /// After a call that ran the ground link at vehicle time `now_us` and sent `sent`.
    pub fn after_poll(&mut self, now_us: u64, sent: &[Sent]) {
        let beat = broadcasts_heartbeat(sent);
        // The first run of the link sends one at once.
        let due = match self.last_us {
            Some(last) => {
                assert!(
                    now_us >= last,
                    "the vehicle's clock went back: {last} -> {now_us}"
                );
                last.checked_add(common::gcs::HEARTBEAT_INTERVAL_US)
            }
            None => Some(0),
        };
        assert!(
            beat || due.is_none_or(|d| now_us < d),
            "no heartbeat at {now_us} us, the last at {:?} us",
            self.last_us
        );
        if beat {
            self.last_us = Some(now_us);
        }
    }
}

/// After a call into the ground port: what it sent, checked (every `PARAM_VALUE` against the
/// store, every stored value against its checks). A datagram that asks the vehicle nothing
/// costs its framing only and does not run the link, so a heartbeat is recorded here but
/// asked only after sensor frames (`sim_link`), which always run it.
pub fn after_ground(app: &mut App, heartbeat: &mut Heartbeat) -> Vec<Sent> {
    let sent = drain(app);
    let now = app.vehicle().time_us().unwrap_or(0);
    heartbeat.note(now, &sent);
    let store = app.vehicle().params();
    for s in &sent {
        check_param_value(&s.message, store);
    }
    check_store(store);
    sent
}
