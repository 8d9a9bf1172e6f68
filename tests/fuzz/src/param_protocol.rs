//! The parameter protocol as a state machine, through the application (`App`): sets of every
//! parameter to values on, near and beyond its bounds and to any float, under every wire
//! type; reads by index and by name; list downloads; resets to defaults; gain-set switches;
//! sensor frames in between so the stages load what the store holds.
//!
//! Asserted:
//! - every `PARAM_VALUE` is the value the store holds (name, index, count, type, bits);
//! - every value in the store passes its definition and its stage's rule, and every stage's
//!   settings loaded from the store pass the stage's own validation (so no stage refuses what
//!   the store holds and flies something else);
//! - a `PARAM_SET` of a known name is answered with one `PARAM_VALUE` for it: the value asked
//!   for when the definition and the stage's rule accept it, the old value otherwise;
//! - after a sensor frame the navigator flies the settings the store holds.

use arbitrary::Arbitrary;
use common::control::{autopilot, lateral, longitudinal, GainSet};
use common::link::framing::Sender;
use common::navigation::{fence, navigator, path_manager, validate};
use common::params::store::param_id_str;
use common::params::{Group, ParamKind, ParamStore};
use common::{estimator, failsafe, guidance};
use firmware::app::App;
use mavlink::dialects::common::*;

use crate::frames::{calm_fix, calm_sensors, frame, Simulator, Wobble};
use crate::gcs::{GcsMsg, Name, ParamValue};
use crate::watch::{after_ground, sim_answers, Heartbeat};

/// What the ground station (or time) does next.
#[derive(Arbitrary, Clone, Debug)]
pub enum ParamAction {
    Set {
        name: Name,
        value: ParamValue,
        ty: u8,
    },
    Read {
        index: i16,
        name: Name,
    },
    List,
    /// `PREFLIGHT_STORAGE`: 1 save, 2 restore the defaults.
    Storage {
        restore: bool,
    },
    /// Sensor frames: the vehicle ticks and loads changed parameters.
    Frames {
        n: u8,
    },
    /// Any other ground-station message (arming, modes: a reset is refused while armed).
    Other(GcsMsg),
}

struct Harness {
    app: App,
    sim: Simulator,
    station: Sender,
    raw_us: u64,
    heartbeat: Heartbeat,
}

/// Each typed group's settings, loaded from the store, pass the group's validation.
fn check_stages(store: &ParamStore) {
    fn one<C>(store: &ParamStore, g: &Group<C>) {
        let c = store.load(g);
        assert_eq!(
            g.validate(&c),
            Ok(()),
            "group {} refuses what the store holds",
            g.name
        );
    }
    one(store, &lateral::PARAMS);
    one(store, &longitudinal::PARAMS);
    one(store, &longitudinal::tecs::gains::PARAMS);
    one(store, &autopilot::PARAMS);
    one(store, &estimator::config::PARAMS);
    one(store, &guidance::PARAMS);
    one(store, &path_manager::PARAMS);
    one(store, &navigator::params::PARAMS);
    one(store, &validate::PARAMS);
    one(store, &fence::PARAMS);
    one(store, &failsafe::PARAMS);
    one(store, &common::vehicle::params::PARAMS);
    assert_eq!(
        GainSet::from_store(store).validate(),
        Ok(()),
        "the autopilot would refuse the gains the store holds"
    );
}

impl Harness {
    fn ground(&mut self, msg: &MavMessage) -> Vec<crate::watch::Sent> {
        let bytes = frame(&mut self.station, msg);
        self.app.on_gcs_datagram(0, &bytes);
        self.check()
    }

    fn check(&mut self) -> Vec<crate::watch::Sent> {
        let sent = after_ground(&mut self.app, &mut self.heartbeat);
        check_stages(self.app.vehicle().params());
        sent
    }

    fn set(&mut self, name: &Name, value: ParamValue, ty: u8) {
        let store = self.app.vehicle().params();
        let Some(crate::gcs::Built::Typed(msg)) = (GcsMsg::ParamSet {
            name: name.clone(),
            value,
            ty,
        })
        .build(store) else {
            return;
        };
        let MavMessage::PARAM_SET(d) = &msg else {
            return;
        };
        let index = param_id_str(&d.param_id[..]).and_then(|n| store.index_of(n));
        let old = index.and_then(|i| store.value(i));
        let wanted = index.and_then(|i| candidate(store, i, d));
        // With a signing key set (a `SETUP_SIGNING` among the other messages), this unsigned
        // write is refused: no echo, nothing changed.
        let locked = self.app.ground_link().signing().key().is_some();
        let changes = store.change_count();
        let sent = self.ground(&msg);
        if locked {
            assert!(
                !sent
                    .iter()
                    .any(|s| matches!(s.message, MavMessage::PARAM_VALUE(_))
                        && s.dest == common::gcs::Dest::All),
                "an unsigned PARAM_SET answered while signing is on"
            );
            assert_eq!(
                self.app.vehicle().params().change_count(),
                changes,
                "an unsigned PARAM_SET changed a parameter while signing is on"
            );
            return;
        }
        let Some(i) = index else {
            return;
        };
        let store = self.app.vehicle().params();
        let echoes: Vec<_> = sent
            .iter()
            .filter_map(|s| match &s.message {
                // The echo goes to every station; a list download streams to one channel.
                MavMessage::PARAM_VALUE(v)
                    if usize::from(v.param_index) == i && s.dest == common::gcs::Dest::All =>
                {
                    Some(v)
                }
                _ => None,
            })
            .collect();
        assert_eq!(echoes.len(), 1, "one PARAM_VALUE answers a PARAM_SET");
        let now = store.value(i).expect("a value");
        match wanted {
            Some(v) => assert_eq!(now.to_bits(), v.to_bits(), "an acceptable value refused"),
            None => assert_eq!(
                now.to_bits(),
                old.expect("a value").to_bits(),
                "a refused value changed the store"
            ),
        }
    }

    fn frames(&mut self, n: u8) {
        for k in 0..u32::from(n).min(60) {
            self.raw_us += 10_000;
            let mut bytes = Vec::new();
            if k % 10 == 0 {
                bytes.extend(self.sim.gps(self.raw_us, &calm_fix((0, 0), 0)));
            }
            bytes.extend(
                self.sim
                    .sensors(&calm_sensors(self.raw_us, &Wobble::default())),
            );
            let mut out = Vec::new();
            self.app
                .on_sim_bytes(&bytes, &mut |b| out.extend_from_slice(b));
            assert_eq!(sim_answers(&out).len(), 1);
            self.check();
            let v = self.app.vehicle();
            assert_eq!(
                *v.navigator().params(),
                v.params().load(&navigator::params::PARAMS),
                "the navigator flies other settings than the store holds"
            );
        }
    }

    fn step(&mut self, a: &ParamAction) {
        match a {
            ParamAction::Set { name, value, ty } => self.set(name, *value, *ty),
            ParamAction::Read { index, name } => {
                let store = self.app.vehicle().params();
                if let Some(crate::gcs::Built::Typed(m)) = (GcsMsg::ParamRead {
                    index: *index,
                    name: name.clone(),
                })
                .build(store)
                {
                    self.ground(&m);
                }
            }
            ParamAction::List => {
                self.ground(&MavMessage::PARAM_REQUEST_LIST(PARAM_REQUEST_LIST_DATA {
                    target_system: 1,
                    target_component: 1,
                }));
            }
            ParamAction::Storage { restore } => {
                self.ground(&MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
                    param1: if *restore { 2.0 } else { 1.0 },
                    command: MavCmd::MAV_CMD_PREFLIGHT_STORAGE,
                    target_system: 1,
                    target_component: 1,
                    ..COMMAND_LONG_DATA::DEFAULT
                }));
            }
            ParamAction::Frames { n } => self.frames(*n),
            ParamAction::Other(m) => {
                let store = self.app.vehicle().params();
                if let Some(crate::gcs::Built::Typed(msg)) = m.build(store) {
                    self.ground(&msg);
                }
            }
        }
    }
}

/// The value a `PARAM_SET` asks for, if the store must take it: the wire value read as the
/// parameter's kind and the message's type say, passing the definition and, with the stage's
/// other values, the stage's rule.
fn candidate(store: &ParamStore, index: usize, d: &PARAM_SET_DATA) -> Option<f32> {
    let def = store.def(index)?;
    let real = d.param_type == MavParamType::MAV_PARAM_TYPE_REAL32;
    let int_type = matches!(
        d.param_type,
        MavParamType::MAV_PARAM_TYPE_INT32
            | MavParamType::MAV_PARAM_TYPE_UINT8
            | MavParamType::MAV_PARAM_TYPE_INT8
            | MavParamType::MAV_PARAM_TYPE_UINT16
            | MavParamType::MAV_PARAM_TYPE_INT16
    );
    let v = match (def.kind, real) {
        (ParamKind::Real, true) => d.param_value,
        (k, false) if k.is_integer() && int_type => d.param_value.to_bits() as i32 as f32,
        (k, true) if k.is_integer() => d.param_value,
        _ => return None,
    };
    let v = def.check(v).ok()?;
    // The stage's rule over its values with this one in place.
    let mut start = 0;
    for stage in store.registry().iter() {
        if index < start + stage.len() {
            let mut values: Vec<f32> = (start..start + stage.len())
                .map(|i| store.value(i).unwrap_or(f32::NAN))
                .collect();
            values[index - start] = v;
            return stage.check(&values).ok().map(|_| v);
        }
        start += stage.len();
    }
    None
}

/// Runs one input.
pub fn run(data: &[u8]) {
    let mut h = Harness {
        app: App::new(),
        sim: Simulator::default(),
        station: Sender::new(255, 190),
        raw_us: 0,
        heartbeat: Heartbeat::default(),
    };
    // The first frame starts the clock, so the heartbeat check runs from a known time.
    h.frames(1);
    crate::each_action(data, 300, |a: &ParamAction| h.step(a));
}
