//! Protocol tests: the link driven with MavMessage values, outputs inspected. Expected values
//! come from the MAVLink specification and PX4's published encodings, not from this code.

extern crate std;

use std::string::ToString;
use std::vec::Vec;

use mavlink::dialects::common::*;
use mavlink::MavHeader;

use super::mission::{UPLOAD_MAX_RETRIES, UPLOAD_RETRY_US};
use super::*;
use crate::navigation::plan::{MissionStore, PlanKind, MISSION_CAPACITY};
use crate::navigation::validate::PlanRules;
use crate::param;
use crate::params::store::{ParamStore, Registry};
use crate::params::{Group, ParamDef};
use crate::tuning::autotune::Status;
use crate::vehicle::modes::{FlightMode, ModeSet};
use crate::vehicle::requests::ArmRequest;
use crate::vehicle::snapshot::*;

#[derive(Clone, Copy, Default)]
struct A {
    rll_kp: f32,
    rll_ki: f32,
    nav_mode: u8,
}
#[derive(Clone, Copy, Default)]
struct B {
    aspd: f32,
    count: i32,
    alt_kp: f32,
}
const STAGE_A: Group<A> = Group {
    name: "a",
    params: &[
        param!(ParamDef::real("RLL_KP", 0.8, 0.0, 5.0, "", "roll gain"), A => rll_kp),
        param!(ParamDef::real("RLL_KI", 0.1, 0.0, 1.0, "", "roll integral gain"), A => rll_ki),
        param!(ParamDef::int("NAV_MODE", 2, 0, 5, "", "an enumeration"), A => nav_mode, count),
    ],
    base: A::default,
    check: crate::params::independent,
};
const STAGE_B: Group<B> = Group {
    name: "b",
    params: &[
        param!(ParamDef::real("ASPD_TRIM", 17.0, 10.0, 30.0, "m/s", "trim airspeed"), B => aspd),
        param!(
            ParamDef::int("SYS_COUNT", 100000, -5, 1_000_000, "", "a large integer"),
            B => count,
            count
        ),
        param!(ParamDef::real("ALT_KP", 0.05, 0.0, 1.0, "", "altitude gain"), B => alt_kp),
    ],
    base: B::default,
    check: crate::params::independent,
};
const REGISTRY: Registry = &[&STAGE_A, &STAGE_B];

/// The link with the stores a vehicle would lend it.
struct Bench {
    link: GroundLink,
    params: ParamStore,
    plan: MissionStore,
    rules: PlanRules,
}

impl core::ops::Deref for Bench {
    type Target = GroundLink;
    fn deref(&self) -> &GroundLink {
        &self.link
    }
}

impl core::ops::DerefMut for Bench {
    fn deref_mut(&mut self) -> &mut GroundLink {
        &mut self.link
    }
}

impl Bench {
    fn handle(&mut self, h: &MavHeader, msg: &MavMessage, now: u64, v: &VehicleSnapshot) {
        self.handle_on(0, h, msg, now, v);
    }

    fn handle_on(
        &mut self,
        channel: u8,
        h: &MavHeader,
        msg: &MavMessage,
        now: u64,
        v: &VehicleSnapshot,
    ) {
        let mut stores = Stores {
            params: &mut self.params,
            plan: &mut self.plan,
            rules: self.rules,
        };
        let origin = Origin {
            channel,
            signed: None,
        };
        self.link.handle(h, msg, now, v, &mut stores, origin);
    }

    fn poll(&mut self, now: u64, v: &VehicleSnapshot, mut out: impl FnMut(MavMessage)) {
        self.poll_to(now, v, |_, m| out(m));
    }

    /// The dialect's messages, with where they go; raw acknowledgements are dropped here.
    fn poll_to(&mut self, now: u64, v: &VehicleSnapshot, mut out: impl FnMut(Dest, MavMessage)) {
        self.poll_raw(now, v, |d, o| {
            if let Outgoing::Message(m) = o {
                out(d, m)
            }
        });
    }

    fn poll_raw(&mut self, now: u64, v: &VehicleSnapshot, out: impl FnMut(Dest, Outgoing)) {
        let stores = Stores {
            params: &mut self.params,
            plan: &mut self.plan,
            rules: self.rules,
        };
        self.link.poll(now, v, &stores, out);
    }
}

const GCS: (u8, u8) = (255, 190);

fn hdr() -> MavHeader {
    MavHeader {
        system_id: GCS.0 as u32,
        component_id: GCS.1,
        sequence: 0,
    }
}

fn link() -> Bench {
    Bench {
        link: GroundLink::default(),
        params: ParamStore::new(REGISTRY),
        plan: MissionStore::default(),
        rules: PlanRules::default(),
    }
}

/// A vehicle on the ground, booted, every sensor healthy, 3D fix, home set.
fn healthy() -> VehicleSnapshot {
    VehicleSnapshot {
        boot_complete: true,
        airspeed_range_m_s: (13.0, 25.0),
        modes_available: ModeSet::ALL,
        landed: LandedState::OnGround,
        health: SensorHealthReport {
            gyro_ok: true,
            accel_ok: true,
            mag_ok: true,
            baro_ok: true,
            airspeed_ok: true,
            gps_ok: true,
            attitude_converged: true,
            position_valid: true,
        },
        gps: GpsRaw {
            fix_type: 3,
            satellites: 10,
            ..Default::default()
        },
        home: HomeReport {
            valid: true,
            lat_e7: 449_000_000,
            lon_e7: -932_000_000,
            alt_amsl_m: 290.0,
        },
        ..Default::default()
    }
}

/// Handles `msg` at `now` and returns what the next poll emits.
fn exchange(l: &mut Bench, v: &VehicleSnapshot, now: u64, msg: MavMessage) -> Vec<MavMessage> {
    l.handle(&hdr(), &msg, now, v);
    poll(l, v, now)
}

fn poll(l: &mut Bench, v: &VehicleSnapshot, now: u64) -> Vec<MavMessage> {
    let mut out = Vec::new();
    l.poll(now, v, |m| out.push(m));
    out
}

use super::client::command_long as cmd_long;

fn acks(out: &[MavMessage]) -> Vec<(MavCmd, MavResult)> {
    out.iter()
        .filter_map(|m| match m {
            MavMessage::COMMAND_ACK(a) => Some((a.command, a.result)),
            _ => None,
        })
        .collect()
}

fn texts(out: &[MavMessage]) -> Vec<std::string::String> {
    out.iter()
        .filter_map(|m| match m {
            MavMessage::STATUSTEXT(t) => Some(t.text.to_str().unwrap().to_string()),
            _ => None,
        })
        .collect()
}

fn param_values(out: &[MavMessage]) -> Vec<PARAM_VALUE_DATA> {
    out.iter()
        .filter_map(|m| match m {
            MavMessage::PARAM_VALUE(p) => Some(p.clone()),
            _ => None,
        })
        .collect()
}

fn heartbeat_of(out: &[MavMessage]) -> Option<HEARTBEAT_DATA> {
    out.iter().find_map(|m| match m {
        MavMessage::HEARTBEAT(h) => Some(h.clone()),
        _ => None,
    })
}

// ---------------------------------------------------------------- parameters

#[test]
fn full_parameter_download_every_index_once() {
    let mut l = link();
    let v = healthy();
    let mut got = Vec::new();
    let mut now = 0;
    got.extend(param_values(&exchange(
        &mut l,
        &v,
        now,
        MavMessage::PARAM_REQUEST_LIST(PARAM_REQUEST_LIST_DATA {
            target_system: 1,
            target_component: 1,
        }),
    )));
    for _ in 0..20 {
        now += 20_000;
        got.extend(param_values(&poll(&mut l, &v, now)));
    }
    assert_eq!(got.len(), 6, "six parameters, each sent once");
    let mut seen = [false; 6];
    for (k, p) in got.iter().enumerate() {
        assert_eq!(p.param_count, 6);
        assert_eq!(usize::from(p.param_index), k, "index order is stable");
        assert!(!seen[usize::from(p.param_index)]);
        seen[usize::from(p.param_index)] = true;
    }
    let names: Vec<_> = got
        .iter()
        .map(|p| p.param_id.to_str().unwrap().to_string())
        .collect();
    assert_eq!(
        names,
        [
            "RLL_KP",
            "RLL_KI",
            "NAV_MODE",
            "ASPD_TRIM",
            "SYS_COUNT",
            "ALT_KP"
        ]
    );
    // INT32 values travel bytewise: 100000's bytes, not the float 100000.0.
    assert_eq!(got[4].param_type, MavParamType::MAV_PARAM_TYPE_INT32);
    assert_eq!(got[4].param_value.to_bits(), 100_000);
    assert_eq!(got[0].param_type, MavParamType::MAV_PARAM_TYPE_REAL32);
    assert_eq!(got[0].param_value, 0.8);
    // Paced: 4 per poll by default.
    let mut l2 = link();
    let first = param_values(&exchange(
        &mut l2,
        &v,
        0,
        MavMessage::PARAM_REQUEST_LIST(PARAM_REQUEST_LIST_DATA::default()),
    ));
    assert_eq!(first.len(), 4);
}

fn param_set(name: &str, value: f32, t: MavParamType) -> MavMessage {
    MavMessage::PARAM_SET(PARAM_SET_DATA {
        param_value: value,
        target_system: 1,
        target_component: 1,
        param_id: name.into(),
        param_type: t,
    })
}

#[test]
fn set_and_read_back() {
    let mut l = link();
    let v = healthy();
    let out = exchange(
        &mut l,
        &v,
        0,
        param_set("RLL_KP", 1.25, MavParamType::MAV_PARAM_TYPE_REAL32),
    );
    let pv = param_values(&out);
    assert_eq!(pv.len(), 1);
    assert_eq!(pv[0].param_value, 1.25);
    assert_eq!(pv[0].param_index, 0);
    assert!(texts(&out).is_empty());
    assert_eq!(l.params.get("RLL_KP"), Some(1.25));
    assert!(l.params.is_dirty());

    // Integer set bytewise.
    let out = exchange(
        &mut l,
        &v,
        1,
        param_set(
            "SYS_COUNT",
            f32::from_bits(-3i32 as u32),
            MavParamType::MAV_PARAM_TYPE_INT32,
        ),
    );
    assert_eq!(param_values(&out)[0].param_value.to_bits(), -3i32 as u32);
    assert_eq!(l.params.get("SYS_COUNT"), Some(-3.0));

    // Read by name (index -1) and by index.
    let out = exchange(
        &mut l,
        &v,
        2,
        MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
            param_index: -1,
            target_system: 1,
            target_component: 1,
            param_id: "RLL_KP".into(),
        }),
    );
    assert_eq!(param_values(&out)[0].param_value, 1.25);
    let out = exchange(
        &mut l,
        &v,
        3,
        MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
            param_index: 4,
            target_system: 1,
            target_component: 1,
            param_id: "".into(),
        }),
    );
    let pv = param_values(&out);
    assert_eq!(pv[0].param_id.to_str().unwrap(), "SYS_COUNT");
    assert_eq!(pv[0].param_value.to_bits(), -3i32 as u32);
    // An index past the end gets no answer.
    let out = exchange(
        &mut l,
        &v,
        4,
        MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
            param_index: 6,
            target_system: 1,
            target_component: 1,
            param_id: "".into(),
        }),
    );
    assert!(param_values(&out).is_empty());
}

#[test]
fn bad_values_refused_with_echo_and_reason() {
    let mut l = link();
    let v = healthy();
    let cases: [(&str, f32, MavParamType, &str); 5] = [
        (
            "RLL_KP",
            f32::NAN,
            MavParamType::MAV_PARAM_TYPE_REAL32,
            "not a finite number",
        ),
        (
            "RLL_KP",
            7.0,
            MavParamType::MAV_PARAM_TYPE_REAL32,
            "out of bounds",
        ),
        (
            "NAV_MODE",
            1.5,
            MavParamType::MAV_PARAM_TYPE_REAL32,
            "not an integer",
        ),
        (
            "NAV_MODE",
            f32::from_bits(9),
            MavParamType::MAV_PARAM_TYPE_INT32,
            "out of bounds",
        ),
        (
            "RLL_KI",
            f32::from_bits(1),
            MavParamType::MAV_PARAM_TYPE_INT32,
            "wrong type",
        ),
    ];
    for (k, (name, value, t, why)) in cases.into_iter().enumerate() {
        let before = l.params.get(name).unwrap();
        let changes = l.params.change_count();
        let out = exchange(&mut l, &v, k as u64, param_set(name, value, t));
        let pv = param_values(&out);
        assert_eq!(pv.len(), 1, "{name}: one echo");
        let echoed = if pv[0].param_type == MavParamType::MAV_PARAM_TYPE_INT32 {
            pv[0].param_value.to_bits() as i32 as f32
        } else {
            pv[0].param_value
        };
        assert_eq!(echoed, before, "{name}: echo carries the unchanged value");
        assert_eq!(l.params.get(name), Some(before));
        assert_eq!(l.params.change_count(), changes);
        let t = texts(&out);
        assert_eq!(t.len(), 1, "{name}: one STATUSTEXT");
        assert!(t[0].contains(name) && t[0].contains(why), "{:?}", t[0]);
    }
    // A whole number sent as REAL32 to an integer parameter is accepted (pymavlink default).
    let out = exchange(
        &mut l,
        &v,
        10,
        param_set("NAV_MODE", 4.0, MavParamType::MAV_PARAM_TYPE_REAL32),
    );
    assert_eq!(param_values(&out)[0].param_value.to_bits(), 4);
    // Unknown name: no echo, a reason.
    let out = exchange(
        &mut l,
        &v,
        11,
        param_set("NOPE", 1.0, MavParamType::MAV_PARAM_TYPE_REAL32),
    );
    assert!(param_values(&out).is_empty());
    assert!(texts(&out)[0].contains("unknown"));
}

// ---------------------------------------------------------------- identity, commands

#[test]
fn heartbeat_one_hertz_identity_and_status() {
    let mut l = link();
    let mut v = VehicleSnapshot::default();
    let mut beats = Vec::new();
    for k in 0..5000u64 {
        // 5 s polled at 1 kHz.
        for m in poll(&mut l, &v, k * 1000) {
            if let MavMessage::HEARTBEAT(h) = m {
                beats.push(h);
            }
        }
    }
    assert_eq!(beats.len(), 5);
    let h = &beats[0];
    assert_eq!(h.mavtype, MavType::MAV_TYPE_FIXED_WING);
    assert_eq!(h.autopilot, MavAutopilot::MAV_AUTOPILOT_GENERIC);
    assert_eq!(h.system_status, MavState::MAV_STATE_BOOT);
    assert_eq!(h.mavlink_version, 3);
    assert!(h
        .base_mode
        .contains(MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED));

    v = healthy();
    let st = |l: &mut Bench, v: &VehicleSnapshot, t: u64| heartbeat_of(&poll(l, v, t)).unwrap();
    assert_eq!(
        st(&mut l, &v, 6_000_000).system_status,
        MavState::MAV_STATE_STANDBY
    );
    v.armed = true;
    let h = st(&mut l, &v, 7_000_000);
    assert_eq!(h.system_status, MavState::MAV_STATE_ACTIVE);
    assert!(h
        .base_mode
        .contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED));
    assert!(h
        .base_mode
        .contains(MavModeFlag::MAV_MODE_FLAG_MANUAL_INPUT_ENABLED));
    v.failsafe = true;
    assert_eq!(
        st(&mut l, &v, 8_000_000).system_status,
        MavState::MAV_STATE_CRITICAL
    );
    v.failsafe = false;
    v.mode = FlightMode::Mission;
    let h = st(&mut l, &v, 9_000_000);
    assert!(h
        .base_mode
        .contains(MavModeFlag::MAV_MODE_FLAG_AUTO_ENABLED));
    assert!(!h
        .base_mode
        .contains(MavModeFlag::MAV_MODE_FLAG_MANUAL_INPUT_ENABLED));
}

#[allow(deprecated)]
#[test]
fn autopilot_version_on_request_and_legacy_command() {
    let v = healthy();
    for (k, msg) in [
        cmd_long(
            MavCmd::MAV_CMD_REQUEST_MESSAGE,
            [148.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
        cmd_long(
            MavCmd::MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES,
            [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let mut l = link();
        let out = exchange(&mut l, &v, k as u64, msg);
        assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_ACCEPTED);
        let av = out
            .iter()
            .find_map(|m| match m {
                MavMessage::AUTOPILOT_VERSION(a) => Some(a.clone()),
                _ => None,
            })
            .expect("AUTOPILOT_VERSION sent");
        // Bits from the MAVLink MAV_PROTOCOL_CAPABILITY enum.
        let bits = av.capabilities.bits();
        for b in [8192u64, 4, 8, 2, 16] {
            assert_ne!(bits & b, 0, "capability {b}");
        }
        assert_eq!(bits & 64, 0, "SET_ATTITUDE_TARGET not claimed");
        assert_eq!(bits & 32, 0, "FTP not claimed");
        assert_eq!(av.flight_sw_version & 0xff, 255);
    }
}

#[test]
fn unknown_command_unsupported_and_ack_addressed_to_sender() {
    let mut l = link();
    let v = healthy();
    let out = exchange(
        &mut l,
        &v,
        0,
        cmd_long(MavCmd::MAV_CMD_DO_DIGICAM_CONTROL, [0.0; 7]),
    );
    let ack = out
        .iter()
        .find_map(|m| match m {
            MavMessage::COMMAND_ACK(a) => Some(a.clone()),
            _ => None,
        })
        .unwrap();
    assert_eq!(ack.result, MavResult::MAV_RESULT_UNSUPPORTED);
    assert_eq!(ack.command, MavCmd::MAV_CMD_DO_DIGICAM_CONTROL);
    assert_eq!((ack.target_system, ack.target_component), GCS);
    // REQUEST_MESSAGE for a message we do not produce.
    let out = exchange(
        &mut l,
        &v,
        1,
        cmd_long(
            MavCmd::MAV_CMD_REQUEST_MESSAGE,
            [397.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    );
    assert_eq!(
        acks(&out),
        [(
            MavCmd::MAV_CMD_REQUEST_MESSAGE,
            MavResult::MAV_RESULT_UNSUPPORTED
        )]
    );
}

#[test]
fn messages_for_other_systems_ignored() {
    let mut l = link();
    let v = healthy();
    // Drain the first heartbeat and streams so only answers remain.
    poll(&mut l, &v, 0);
    let other_sys = MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        command: MavCmd::MAV_CMD_COMPONENT_ARM_DISARM,
        param1: 1.0,
        target_system: 2,
        target_component: 1,
        ..Default::default()
    });
    assert!(acks(&exchange(&mut l, &v, 1, other_sys)).is_empty());
    let other_comp = MavMessage::PARAM_REQUEST_LIST(PARAM_REQUEST_LIST_DATA {
        target_system: 1,
        target_component: 154,
    });
    assert!(param_values(&exchange(&mut l, &v, 2, other_comp)).is_empty());
    assert_eq!(l.take_requests(), VehicleRequests::default());
    // Broadcast (0) is ours.
    let bcast = MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
        param_index: 0,
        target_system: 0,
        target_component: 0,
        param_id: "".into(),
    });
    assert_eq!(param_values(&exchange(&mut l, &v, 3, bcast)).len(), 1);
    // Our own echo (system 1, component 1) is ignored.
    let echo = MavHeader {
        system_id: 1,
        component_id: 1,
        sequence: 0,
    };
    l.handle(
        &echo,
        &cmd_long(MavCmd::MAV_CMD_DO_DIGICAM_CONTROL, [0.0; 7]),
        4,
        &v,
    );
    assert!(acks(&poll(&mut l, &v, 4)).is_empty());
}

// ---------------------------------------------------------------- arming and modes

fn arm_cmd(arm: bool, force: bool) -> MavMessage {
    let p2 = if force { 21196.0 } else { 0.0 };
    cmd_long(
        MavCmd::MAV_CMD_COMPONENT_ARM_DISARM,
        [if arm { 1.0 } else { 0.0 }, p2, 0.0, 0.0, 0.0, 0.0, 0.0],
    )
}

#[test]
fn arming_a_healthy_vehicle_on_the_ground_is_accepted_and_queued() {
    let v = healthy();
    let mut l = link();
    let out = exchange(&mut l, &v, 0, arm_cmd(true, false));
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_ACCEPTED);
    assert_eq!(
        l.take_requests().arm,
        Some(ArmRequest {
            arm: true,
            forced: false
        })
    );
    assert!(texts(&out).is_empty(), "{:?}", texts(&out));
}

/// Arms a vehicle `break_it` has spoiled: the result, the STATUSTEXTs, and that nothing was
/// queued; then checks that a forced arming is accepted all the same.
fn arm_refused(break_it: fn(&mut VehicleSnapshot)) -> (MavResult, Vec<std::string::String>) {
    let mut bad = healthy();
    break_it(&mut bad);
    let mut l = link();
    let out = exchange(&mut l, &bad, 0, arm_cmd(true, false));
    assert_eq!(l.take_requests().arm, None, "a refusal queues nothing");
    let refused = (acks(&out)[0].1, texts(&out));
    // Forced arming skips the checks.
    let out = exchange(&mut l, &bad, 100, arm_cmd(true, true));
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_ACCEPTED);
    assert!(l.take_requests().arm.is_some_and(|a| a.forced));
    refused
}

// MAVLink's MAV_RESULT: TEMPORARILY_REJECTED is "a problem that should be fixed just by
// waiting (... can't arm because have not got GPS lock ...)"; DENIED is "retrying the same
// command and parameters will not work". Each refusal says why in one STATUSTEXT.

#[test]
fn arming_while_the_attitude_estimate_converges_is_temporarily_rejected() {
    let (r, t) = arm_refused(|v| v.health.attitude_converged = false);
    assert_eq!(r, MavResult::MAV_RESULT_TEMPORARILY_REJECTED);
    assert_eq!(t, ["Arming denied: attitude estimate not converged"]);
}

#[test]
fn arming_before_a_3d_gps_fix_is_temporarily_rejected() {
    let (r, t) = arm_refused(|v| v.gps.fix_type = 2);
    assert_eq!(r, MavResult::MAV_RESULT_TEMPORARILY_REJECTED);
    assert_eq!(t, ["Arming denied: no 3D GPS fix"]);
}

#[test]
fn arming_while_the_gps_receiver_is_silent_is_temporarily_rejected() {
    let (r, t) = arm_refused(|v| v.health.gps_ok = false);
    assert_eq!(r, MavResult::MAV_RESULT_TEMPORARILY_REJECTED);
    assert_eq!(t, ["Arming denied: no 3D GPS fix"]);
}

#[test]
fn arming_before_the_position_estimate_is_valid_is_temporarily_rejected() {
    let (r, t) = arm_refused(|v| v.health.position_valid = false);
    assert_eq!(r, MavResult::MAV_RESULT_TEMPORARILY_REJECTED);
    assert_eq!(t, ["Arming denied: position estimate invalid"]);
}

#[test]
fn arming_with_an_unhealthy_gyro_is_denied() {
    let (r, t) = arm_refused(|v| v.health.gyro_ok = false);
    assert_eq!(r, MavResult::MAV_RESULT_DENIED);
    assert_eq!(t, ["Arming denied: gyro unhealthy"]);
}

#[test]
fn arming_with_an_unhealthy_accelerometer_is_denied() {
    let (r, t) = arm_refused(|v| v.health.accel_ok = false);
    assert_eq!(r, MavResult::MAV_RESULT_DENIED);
    assert_eq!(t, ["Arming denied: accelerometer unhealthy"]);
}

#[test]
fn arming_with_an_unhealthy_magnetometer_is_denied() {
    let (r, t) = arm_refused(|v| v.health.mag_ok = false);
    assert_eq!(r, MavResult::MAV_RESULT_DENIED);
    assert_eq!(t, ["Arming denied: magnetometer unhealthy"]);
}

#[test]
fn arming_with_an_unhealthy_barometer_is_denied() {
    let (r, t) = arm_refused(|v| v.health.baro_ok = false);
    assert_eq!(r, MavResult::MAV_RESULT_DENIED);
    assert_eq!(t, ["Arming denied: barometer unhealthy"]);
}

#[test]
fn arming_with_an_unhealthy_airspeed_sensor_is_denied() {
    let (r, t) = arm_refused(|v| v.health.airspeed_ok = false);
    assert_eq!(r, MavResult::MAV_RESULT_DENIED);
    assert_eq!(t, ["Arming denied: airspeed sensor unhealthy"]);
}

#[test]
fn arming_on_a_critical_battery_is_denied() {
    let (r, t) = arm_refused(|v| {
        v.battery.present = true;
        v.battery.warning = crate::battery::Warning::Critical;
    });
    assert_eq!(r, MavResult::MAV_RESULT_DENIED);
    assert_eq!(t, ["Arming denied: battery critical"]);
}

/// A station that retries while it is told to wait must not wait for what will not pass: with
/// a failed sensor and an estimator still converging, the answer is the sensor's DENIED.
#[test]
fn arming_with_a_failed_sensor_while_the_estimator_converges_is_denied_for_the_sensor() {
    let (r, t) = arm_refused(|v| {
        v.health.attitude_converged = false;
        v.health.position_valid = false;
        v.health.baro_ok = false;
    });
    assert_eq!(r, MavResult::MAV_RESULT_DENIED);
    assert_eq!(t, ["Arming denied: barometer unhealthy"]);
}

#[test]
fn arming_before_the_boot_is_complete_is_temporarily_rejected() {
    let (r, t) = arm_refused(|v| v.boot_complete = false);
    assert_eq!(r, MavResult::MAV_RESULT_TEMPORARILY_REJECTED);
    assert_eq!(t, ["Arming denied: system still starting"]);
}

#[test]
fn disarming_in_the_air_is_denied_unless_forced() {
    let mut flying = healthy();
    flying.armed = true;
    flying.landed = LandedState::InAir;
    let mut l = link();
    let out = exchange(&mut l, &flying, 0, arm_cmd(false, false));
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_DENIED);
    assert!(texts(&out)[0].contains("not landed"));
    let out = exchange(&mut l, &flying, 1, arm_cmd(false, true));
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_ACCEPTED);
    assert_eq!(
        l.take_requests().arm,
        Some(ArmRequest {
            arm: false,
            forced: true
        })
    );
}

/// A disarm asked of a vehicle flying 3 m over home (the land detector's verdict, through the
/// snapshot the link checks commands against) is refused unless forced; EXTENDED_SYS_STATE
/// says it is in the air.
#[test]
fn a_disarm_asked_in_flight_below_5_m_is_refused_unless_forced() {
    use crate::estimator::{Estimator, Home as EstHome};
    use crate::math::geodetic::GeoPoint;
    use crate::vehicle::commander::Commander;
    use crate::vehicle::land_detector::LandParams;
    use crate::vehicle::report::{snapshot, Extras};
    use crate::vehicle::requests::VehicleRequests;
    let mut e = Estimator::default().state();
    e.home = Some(EstHome {
        point: GeoPoint {
            lat_e7: 449_000_000,
            lon_e7: -932_000_000,
        },
        alt_amsl_m: 300.0,
    });
    e.alt_amsl_m = 303.0;
    e.pos_ned = nalgebra::Vector3::new(0.0, 0.0, -3.0);
    e.airspeed = 15.0;
    e.ground_speed = 15.0;
    e.vel_ned = nalgebra::Vector3::new(15.0, 0.0, 0.5);
    let mut c = Commander::new();
    c.apply(
        &VehicleRequests {
            arm: Some(ArmRequest {
                arm: true,
                forced: false,
            }),
            ..Default::default()
        },
        &e,
        &mut crate::navigation::navigator::Navigator::default(),
    );
    for _ in 0..100 {
        c.detect_landing(&LandParams::default(), &e, Some(9.81), 0.02);
    }
    let v = snapshot(
        &e,
        &c,
        &Extras {
            time_us: Some(1_000_000),
            ..Default::default()
        },
    );
    assert!(v.armed);
    assert_eq!(v.landed, LandedState::InAir);
    let MavMessage::EXTENDED_SYS_STATE(x) = telemetry::extended_sys_state(&v) else {
        panic!("EXTENDED_SYS_STATE expected")
    };
    assert_eq!(x.landed_state, MavLandedState::MAV_LANDED_STATE_IN_AIR);
    let mut l = link();
    let out = exchange(&mut l, &v, 0, arm_cmd(false, false));
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_DENIED);
    assert_eq!(l.take_requests().arm, None);
    let out = exchange(&mut l, &v, 1, arm_cmd(false, true));
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_ACCEPTED);
    assert_eq!(
        l.take_requests().arm,
        Some(ArmRequest {
            arm: false,
            forced: true
        })
    );
}

/// PX4's custom_mode numbers, written out independently of `FlightMode`.
fn px4(main: u32, sub: u32) -> u32 {
    (main << 16) | (sub << 24)
}

#[allow(deprecated)]
#[test]
fn mode_changes_by_every_path_reach_the_heartbeat() {
    let mut v = healthy();
    let mut l = link();
    // A one-item mission so Mission mode can be entered.
    assert_eq!(
        upload(
            &mut l,
            &v,
            0,
            MavMissionType::MAV_MISSION_TYPE_MISSION,
            &waypoints(1, 0)
        ),
        MavMissionResult::MAV_MISSION_ACCEPTED
    );
    let cases: Vec<(MavMessage, MavCmd, u32)> = std::vec![
        (
            cmd_long(
                MavCmd::MAV_CMD_DO_SET_MODE,
                [1.0, 7.0, 0.0, 0.0, 0.0, 0.0, 0.0]
            ),
            MavCmd::MAV_CMD_DO_SET_MODE,
            px4(7, 0)
        ),
        (
            MavMessage::COMMAND_INT(COMMAND_INT_DATA {
                param1: 129.0,
                param2: 2.0,
                command: MavCmd::MAV_CMD_DO_SET_MODE,
                target_system: 1,
                target_component: 1,
                ..Default::default()
            }),
            MavCmd::MAV_CMD_DO_SET_MODE,
            px4(2, 0)
        ),
        (
            MavMessage::SET_MODE(SET_MODE_DATA {
                custom_mode: px4(3, 0),
                target_system: 1,
                base_mode: MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED,
            }),
            MavCmd::MAV_CMD_DO_SET_MODE,
            px4(3, 0)
        ),
        (
            cmd_long(
                MavCmd::MAV_CMD_DO_SET_MODE,
                [1.0, 4.0, 3.0, 0.0, 0.0, 0.0, 0.0]
            ),
            MavCmd::MAV_CMD_DO_SET_MODE,
            px4(4, 3)
        ),
        (
            cmd_long(
                MavCmd::MAV_CMD_DO_SET_STANDARD_MODE,
                [8.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
            ),
            MavCmd::MAV_CMD_DO_SET_STANDARD_MODE,
            px4(4, 2)
        ),
        (
            cmd_long(
                MavCmd::MAV_CMD_DO_SET_STANDARD_MODE,
                [7.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
            ),
            MavCmd::MAV_CMD_DO_SET_STANDARD_MODE,
            px4(4, 6)
        ),
        (
            cmd_long(MavCmd::MAV_CMD_MISSION_START, [0.0; 7]),
            MavCmd::MAV_CMD_MISSION_START,
            px4(4, 4)
        ),
        (
            cmd_long(MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH, [0.0; 7]),
            MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH,
            px4(4, 5)
        ),
        (
            cmd_long(
                MavCmd::MAV_CMD_DO_SET_MODE,
                [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
            ),
            MavCmd::MAV_CMD_DO_SET_MODE,
            px4(1, 0)
        ),
    ];
    let mut now = 1_000_000;
    for (msg, cmd, expect) in cases {
        now += 1_000_000;
        let out = exchange(&mut l, &v, now, msg);
        assert_eq!(
            acks(&out),
            [(cmd, MavResult::MAV_RESULT_ACCEPTED)],
            "{expect:#x}"
        );
        // The vehicle applies the request; the next heartbeat tells the truth.
        let mode = l.take_requests().mode.expect("mode requested");
        v.mode = mode;
        now += 1_000_000;
        let hb = heartbeat_of(&poll(&mut l, &v, now)).unwrap();
        assert_eq!(hb.custom_mode, expect);
    }
}

#[test]
fn modes_refused_with_reasons() {
    let mut v = healthy();
    v.health.position_valid = false;
    v.modes_available = ModeSet::WITHOUT_POSITION;
    let mut l = link();
    assert_eq!(
        upload(
            &mut l,
            &v,
            0,
            MavMissionType::MAV_MISSION_TYPE_MISSION,
            &waypoints(2, 0)
        ),
        MavMissionResult::MAV_MISSION_ACCEPTED
    );
    let out = exchange(
        &mut l,
        &v,
        10,
        cmd_long(
            MavCmd::MAV_CMD_DO_SET_MODE,
            [1.0, 4.0, 3.0, 0.0, 0.0, 0.0, 0.0],
        ),
    );
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_TEMPORARILY_REJECTED);
    assert!(texts(&out)[0].contains("Loiter refused: no position estimate"));
    assert_eq!(l.take_requests().mode, None);
    // Altitude mode needs no position.
    let out = exchange(
        &mut l,
        &v,
        11,
        cmd_long(
            MavCmd::MAV_CMD_DO_SET_MODE,
            [1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    );
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_ACCEPTED);
    // Modes this autopilot does not fly.
    let out = exchange(
        &mut l,
        &v,
        12,
        cmd_long(
            MavCmd::MAV_CMD_DO_SET_MODE,
            [1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    );
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_FAILED);
    let out = exchange(
        &mut l,
        &v,
        13,
        cmd_long(
            MavCmd::MAV_CMD_DO_SET_STANDARD_MODE,
            [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    );
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_FAILED);
    // Mission with nothing uploaded, Return without home.
    let mut l = link();
    let v = healthy();
    let out = exchange(
        &mut l,
        &v,
        0,
        cmd_long(MavCmd::MAV_CMD_MISSION_START, [0.0; 7]),
    );
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_DENIED);
    assert!(texts(&out)[0].contains("no mission"));
    let mut nohome = healthy();
    nohome.home.valid = false;
    let out = exchange(
        &mut l,
        &nohome,
        1,
        cmd_long(MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH, [0.0; 7]),
    );
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_TEMPORARILY_REJECTED);
    assert!(texts(&out)[0].contains("no home"));
}

#[test]
fn available_and_current_modes() {
    let mut l = link();
    let mut v = healthy();
    let out = exchange(
        &mut l,
        &v,
        0,
        cmd_long(
            MavCmd::MAV_CMD_REQUEST_MESSAGE,
            [435.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    );
    assert!(matches!(out[0], MavMessage::COMMAND_ACK(_)), "ACK first");
    let modes: Vec<_> = out
        .iter()
        .filter_map(|m| match m {
            MavMessage::AVAILABLE_MODES(a) => Some(a.clone()),
            _ => None,
        })
        .collect();
    assert_eq!(modes.len(), 9);
    let mut idx: Vec<u8> = modes.iter().map(|m| m.mode_index).collect();
    idx.sort();
    assert_eq!(idx, (1..=9).collect::<Vec<u8>>());
    assert!(modes.iter().all(|m| m.number_modes == 9));
    let mission = modes
        .iter()
        .find(|m| m.mode_name.to_str().unwrap() == "Mission")
        .unwrap();
    assert_eq!(mission.custom_mode, px4(4, 4));
    assert_eq!(
        mission.standard_mode,
        MavStandardMode::MAV_STANDARD_MODE_MISSION
    );
    // One by index.
    let out = exchange(
        &mut l,
        &v,
        1,
        cmd_long(
            MavCmd::MAV_CMD_REQUEST_MESSAGE,
            [435.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    );
    let one: Vec<_> = out
        .iter()
        .filter(|m| matches!(m, MavMessage::AVAILABLE_MODES(_)))
        .collect();
    assert_eq!(one.len(), 1);
    // CURRENT_MODE on request and on change.
    v.mode = FlightMode::Loiter;
    let out = exchange(
        &mut l,
        &v,
        2,
        cmd_long(
            MavCmd::MAV_CMD_REQUEST_MESSAGE,
            [436.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    );
    let cm = out
        .iter()
        .find_map(|m| match m {
            MavMessage::CURRENT_MODE(c) => Some(c.clone()),
            _ => None,
        })
        .unwrap();
    assert_eq!(cm.custom_mode, px4(4, 3));
    // Loiter is no standard ORBIT (a manual orbit the standard defines), as on PX4.
    assert_eq!(
        cm.standard_mode,
        MavStandardMode::MAV_STANDARD_MODE_NON_STANDARD
    );
}

// ---------------------------------------------------------------- telemetry scheduler

fn count_over(l: &mut Bench, v: &VehicleSnapshot, from_us: u64, secs: u64, id: u32) -> usize {
    let mut n = 0;
    // Polled at 1 kHz, like a fast SITL loop.
    for k in 0..secs * 1000 {
        for m in poll(l, v, from_us + k * 1000) {
            if mavlink::Message::message_id(&m) == id {
                n += 1;
            }
        }
    }
    n
}

#[test]
fn default_stream_rates() {
    let mut l = link();
    let v = healthy();
    // 10 s: PX4-like defaults.
    let mut counts = std::collections::BTreeMap::new();
    for k in 0..10_000u64 {
        for m in poll(&mut l, &v, k * 1000) {
            *counts
                .entry(mavlink::Message::message_id(&m))
                .or_insert(0usize) += 1;
        }
    }
    let expect = [
        (0u32, 10usize), // HEARTBEAT 1 Hz
        (1, 10),         // SYS_STATUS 1 Hz
        (24, 10),        // GPS_RAW_INT 1 Hz
        (30, 150),       // ATTITUDE 15 Hz
        (33, 50),        // GLOBAL_POSITION_INT 5 Hz
        (42, 10),        // MISSION_CURRENT 1 Hz
        (62, 10),        // NAV_CONTROLLER_OUTPUT 1 Hz
        (74, 40),        // VFR_HUD 4 Hz
        (147, 5),        // BATTERY_STATUS 0.5 Hz
        (242, 5),        // HOME_POSITION 0.5 Hz
        (245, 10),       // EXTENDED_SYS_STATE 1 Hz
    ];
    for (id, n) in expect {
        let got = counts.get(&id).copied().unwrap_or(0);
        assert!(
            got.abs_diff(n) <= 1,
            "message {id}: {got} in 10 s, expected {n}"
        );
    }
}

#[test]
fn set_message_interval_changes_a_stream() {
    let mut l = link();
    let v = healthy();
    let set = |iv: f32| {
        cmd_long(
            MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
            [30.0, iv, 0.0, 0.0, 0.0, 0.0, 0.0],
        )
    };
    assert_eq!(
        acks(&exchange(&mut l, &v, 0, set(20_000.0)))[0].1,
        MavResult::MAV_RESULT_ACCEPTED
    );
    let n = count_over(&mut l, &v, 1_000, 10, 30);
    assert!(n.abs_diff(500) <= 1, "50 Hz for 10 s gave {n}");
    // GET_MESSAGE_INTERVAL reports it.
    #[allow(deprecated)]
    let out = exchange(
        &mut l,
        &v,
        11_000_000,
        cmd_long(
            MavCmd::MAV_CMD_GET_MESSAGE_INTERVAL,
            [30.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    );
    let mi = out
        .iter()
        .find_map(|m| match m {
            MavMessage::MESSAGE_INTERVAL(i) => Some(i.clone()),
            _ => None,
        })
        .unwrap();
    assert_eq!((mi.message_id, mi.interval_us), (30, 20_000));
    // -1 stops it.
    exchange(&mut l, &v, 11_000_001, set(-1.0));
    assert_eq!(count_over(&mut l, &v, 11_001_000, 3, 30), 0);
    // 0 restores the default 15 Hz.
    exchange(&mut l, &v, 14_001_000, set(0.0));
    let n = count_over(&mut l, &v, 14_002_000, 10, 30);
    assert!(n.abs_diff(150) <= 1, "default gave {n}");
    // Unknown stream, heartbeat.
    let out = exchange(
        &mut l,
        &v,
        30_000_000,
        cmd_long(
            MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
            [9999.0, 1e5, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    );
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_UNSUPPORTED);
    let out = exchange(
        &mut l,
        &v,
        30_000_001,
        cmd_long(
            MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
            [0.0, 1e5, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    );
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_DENIED);
}

#[test]
fn statustext_queue_from_vehicle() {
    let mut l = link();
    let v = healthy();
    l.send_statustext(MavSeverity::MAV_SEVERITY_CRITICAL, "Failsafe: link lost");
    let out = poll(&mut l, &v, 0);
    assert_eq!(texts(&out), ["Failsafe: link lost"]);
    // More than fit: the rest counted as dropped, never a panic.
    for _ in 0..20 {
        l.send_statustext(MavSeverity::MAV_SEVERITY_INFO, "x");
    }
    assert_eq!(texts(&poll(&mut l, &v, 1)).len(), 8);
    assert_eq!(l.dropped(), 12);
}

// ---------------------------------------------------------------- missions

/// `n` waypoints; each carries awkward floats: NaN with a payload, -0.0, infinities.
fn waypoints(n: usize, salt: u32) -> Vec<MISSION_ITEM_INT_DATA> {
    (0..n)
        .map(|i| MISSION_ITEM_INT_DATA {
            param1: i as f32 * 0.5,
            param2: f32::from_bits(0x7fc0_0000 | (i as u32 + salt)), // NaN, payload i
            param3: -0.0,
            param4: if i % 2 == 0 { f32::NAN } else { f32::INFINITY },
            x: 449_000_000 + i as i32 * 1000,
            y: -932_000_000 - i as i32 * 1000,
            z: 100.0 + i as f32,
            seq: i as u16,
            command: if i == 0 {
                MavCmd::MAV_CMD_NAV_TAKEOFF
            } else {
                MavCmd::MAV_CMD_NAV_WAYPOINT
            },
            target_system: 1,
            target_component: 1,
            frame: MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
            current: 0,
            autocontinue: 1,
            mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        })
        .collect()
}

/// A ground station uploading `items`, answering each request; returns the final ACK.
fn upload(
    l: &mut Bench,
    v: &VehicleSnapshot,
    start_us: u64,
    t: MavMissionType,
    items: &[MISSION_ITEM_INT_DATA],
) -> MavMissionResult {
    upload_said(l, v, start_us, t, items).0
}

/// As [`upload`], with the STATUSTEXTs the vehicle sent on the way.
fn upload_said(
    l: &mut Bench,
    v: &VehicleSnapshot,
    start_us: u64,
    t: MavMissionType,
    items: &[MISSION_ITEM_INT_DATA],
) -> (MavMissionResult, Vec<std::string::String>) {
    let mut said = Vec::new();
    let mut now = start_us;
    let mut out = exchange(
        l,
        v,
        now,
        MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
            count: items.len() as u16,
            target_system: 1,
            target_component: 1,
            mission_type: t,
            opaque_id: 0,
        }),
    );
    for _ in 0..10_000 {
        let mut next = None;
        said.extend(texts(&out));
        for m in &out {
            match m {
                MavMessage::MISSION_ACK(a) => return (a.mavtype, said),
                MavMessage::MISSION_REQUEST_INT(r) => {
                    assert_eq!(r.mission_type, t);
                    assert_eq!((r.target_system, r.target_component), GCS);
                    next = Some(r.seq);
                }
                _ => {}
            }
        }
        now += 1000;
        out = match next {
            Some(seq) => {
                let mut it = items[usize::from(seq)].clone();
                it.mission_type = t;
                exchange(l, v, now, MavMessage::MISSION_ITEM_INT(it))
            }
            None => poll(l, v, now),
        };
    }
    panic!("upload never finished");
}

/// A ground station downloading a list.
fn download(
    l: &mut Bench,
    v: &VehicleSnapshot,
    start_us: u64,
    t: MavMissionType,
) -> Vec<MISSION_ITEM_INT_DATA> {
    let out = exchange(
        l,
        v,
        start_us,
        MavMessage::MISSION_REQUEST_LIST(MISSION_REQUEST_LIST_DATA {
            target_system: 1,
            target_component: 1,
            mission_type: t,
        }),
    );
    let count = out
        .iter()
        .find_map(|m| match m {
            MavMessage::MISSION_COUNT(c) => Some(c.clone()),
            _ => None,
        })
        .expect("MISSION_COUNT");
    assert_eq!(count.mission_type, t);
    let mut items = Vec::new();
    for seq in 0..count.count {
        let out = exchange(
            l,
            v,
            start_us + 1 + u64::from(seq),
            MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
                seq,
                target_system: 1,
                target_component: 1,
                mission_type: t,
            }),
        );
        let it = out
            .iter()
            .find_map(|m| match m {
                MavMessage::MISSION_ITEM_INT(i) => Some(i.clone()),
                _ => None,
            })
            .expect("MISSION_ITEM_INT");
        assert_eq!(it.seq, seq);
        items.push(it);
    }
    l.handle(
        &hdr(),
        &MavMessage::MISSION_ACK(MISSION_ACK_DATA {
            target_system: 1,
            target_component: 1,
            mavtype: MavMissionResult::MAV_MISSION_ACCEPTED,
            mission_type: t,
            opaque_id: 0,
        }),
        start_us + 100_000,
        v,
    );
    assert!(!l.missions().busy(), "download closed by the GCS ACK");
    items
}

fn same_bits(a: &MISSION_ITEM_INT_DATA, b: &MISSION_ITEM_INT_DATA) -> bool {
    a.param1.to_bits() == b.param1.to_bits()
        && a.param2.to_bits() == b.param2.to_bits()
        && a.param3.to_bits() == b.param3.to_bits()
        && a.param4.to_bits() == b.param4.to_bits()
        && a.x == b.x
        && a.y == b.y
        && a.z.to_bits() == b.z.to_bits()
        && a.seq == b.seq
        && a.command == b.command
        && a.frame == b.frame
        && a.autocontinue == b.autocontinue
        && a.mission_type == b.mission_type
}

#[test]
fn mission_round_trip_bit_exact_130_items() {
    let mut l = link();
    let v = healthy();
    let items = waypoints(130, 7);
    assert_eq!(
        upload(
            &mut l,
            &v,
            0,
            MavMissionType::MAV_MISSION_TYPE_MISSION,
            &items
        ),
        MavMissionResult::MAV_MISSION_ACCEPTED
    );
    assert_eq!(l.plan.mission.len(), 130);
    let back = download(
        &mut l,
        &v,
        10_000_000,
        MavMissionType::MAV_MISSION_TYPE_MISSION,
    );
    assert_eq!(back.len(), 130);
    for (a, b) in items.iter().zip(&back) {
        assert!(same_bits(a, b), "item {} differs:\n{a:?}\n{b:?}", a.seq);
        assert_eq!((b.target_system, b.target_component), GCS);
    }
    // Item 0 is the first to fly (take-off), not home.
    assert_eq!(back[0].command, MavCmd::MAV_CMD_NAV_TAKEOFF);
    // The full capacity fits; one more does not.
    let mut l = link();
    let full = waypoints(MISSION_CAPACITY, 0);
    assert_eq!(
        upload(
            &mut l,
            &v,
            0,
            MavMissionType::MAV_MISSION_TYPE_MISSION,
            &full
        ),
        MavMissionResult::MAV_MISSION_ACCEPTED
    );
    let over = waypoints(MISSION_CAPACITY + 1, 0);
    assert_eq!(
        upload(
            &mut l,
            &v,
            0,
            MavMissionType::MAV_MISSION_TYPE_MISSION,
            &over
        ),
        MavMissionResult::MAV_MISSION_NO_SPACE
    );
    assert_eq!(l.plan.mission.len(), MISSION_CAPACITY, "old mission kept");
}

#[test]
fn fence_and_rally_stored_beside_the_mission() {
    let mut l = link();
    let v = healthy();
    let mission = waypoints(3, 0);
    let fence: Vec<_> = (0..4)
        .map(|i| MISSION_ITEM_INT_DATA {
            param1: 4.0, // vertices in the polygon
            x: 449_000_000 + (i & 1) * 10_000,
            y: -932_000_000 + (i >> 1) * 10_000,
            seq: i as u16,
            command: MavCmd::MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION,
            frame: MavFrame::MAV_FRAME_GLOBAL,
            mission_type: MavMissionType::MAV_MISSION_TYPE_FENCE,
            ..Default::default()
        })
        .collect();
    let rally = [MISSION_ITEM_INT_DATA {
        x: 449_100_000,
        y: -932_100_000,
        z: 50.0,
        command: MavCmd::MAV_CMD_NAV_RALLY_POINT,
        frame: MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
        mission_type: MavMissionType::MAV_MISSION_TYPE_RALLY,
        ..Default::default()
    }];
    let m = MavMissionType::MAV_MISSION_TYPE_MISSION;
    let f = MavMissionType::MAV_MISSION_TYPE_FENCE;
    let r = MavMissionType::MAV_MISSION_TYPE_RALLY;
    assert_eq!(
        upload(&mut l, &v, 0, m, &mission),
        MavMissionResult::MAV_MISSION_ACCEPTED
    );
    assert_eq!(
        upload(&mut l, &v, 1_000_000, f, &fence),
        MavMissionResult::MAV_MISSION_ACCEPTED
    );
    assert_eq!(
        upload(&mut l, &v, 2_000_000, r, &rally),
        MavMissionResult::MAV_MISSION_ACCEPTED
    );
    assert_eq!(download(&mut l, &v, 3_000_000, m).len(), 3);
    let fb = download(&mut l, &v, 4_000_000, f);
    assert!(fence.iter().zip(&fb).all(|(a, b)| same_bits(a, b)));
    let rb = download(&mut l, &v, 5_000_000, r);
    assert!(same_bits(&rally[0], &rb[0]));
    // A waypoint is not a fence item.
    assert_eq!(
        upload(&mut l, &v, 6_000_000, f, &waypoints(1, 0)),
        MavMissionResult::MAV_MISSION_UNSUPPORTED
    );
    assert_eq!(l.plan.fence.len(), 4);
    // Clearing the fence leaves the others.
    let out = exchange(
        &mut l,
        &v,
        7_000_000,
        MavMessage::MISSION_CLEAR_ALL(MISSION_CLEAR_ALL_DATA {
            target_system: 1,
            target_component: 1,
            mission_type: f,
        }),
    );
    assert!(out.iter().any(|m| matches!(m, MavMessage::MISSION_ACK(a) if a.mavtype == MavMissionResult::MAV_MISSION_ACCEPTED && a.mission_type == f)));
    assert_eq!(l.plan.fence.len(), 0);
    assert_eq!(l.plan.mission.len(), 3);
    assert_eq!(l.plan.rally.len(), 1);
    // ALL clears everything.
    exchange(
        &mut l,
        &v,
        7_100_000,
        MavMessage::MISSION_CLEAR_ALL(MISSION_CLEAR_ALL_DATA {
            target_system: 1,
            target_component: 1,
            mission_type: MavMissionType::MAV_MISSION_TYPE_ALL,
        }),
    );
    assert!(l.plan.mission.is_empty() && l.plan.rally.is_empty());
}

fn mission_acks(out: &[MavMessage]) -> Vec<MavMissionResult> {
    out.iter()
        .filter_map(|m| match m {
            MavMessage::MISSION_ACK(a) => Some(a.mavtype),
            _ => None,
        })
        .collect()
}

fn requests(out: &[MavMessage]) -> Vec<u16> {
    out.iter()
        .filter_map(|m| match m {
            MavMessage::MISSION_REQUEST_INT(r) => Some(r.seq),
            _ => None,
        })
        .collect()
}

fn count_msg(n: u16) -> MavMessage {
    MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
        count: n,
        target_system: 1,
        target_component: 1,
        mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        opaque_id: 0,
    })
}

#[test]
fn erroneous_uploads_get_the_right_ack() {
    let v = healthy();
    let items = waypoints(5, 0);
    // Out of sequence: item 3 when 1 is expected.
    let mut l = link();
    assert_eq!(
        upload(
            &mut l,
            &v,
            0,
            MavMissionType::MAV_MISSION_TYPE_MISSION,
            &items[..2]
        ),
        MavMissionResult::MAV_MISSION_ACCEPTED
    );
    assert_eq!(requests(&exchange(&mut l, &v, 1, count_msg(5))), [0]);
    assert_eq!(
        requests(&exchange(
            &mut l,
            &v,
            2,
            MavMessage::MISSION_ITEM_INT(items[0].clone())
        )),
        [1]
    );
    let out = exchange(
        &mut l,
        &v,
        3,
        MavMessage::MISSION_ITEM_INT(items[3].clone()),
    );
    assert_eq!(
        mission_acks(&out),
        [MavMissionResult::MAV_MISSION_INVALID_SEQUENCE]
    );
    assert_eq!(l.plan.mission.len(), 2, "old mission kept");
    assert!(!l.missions().busy());
    // A repeated earlier item is answered by asking again for the expected one.
    exchange(&mut l, &v, 4, count_msg(5));
    exchange(
        &mut l,
        &v,
        5,
        MavMessage::MISSION_ITEM_INT(items[0].clone()),
    );
    assert_eq!(
        requests(&exchange(
            &mut l,
            &v,
            6,
            MavMessage::MISSION_ITEM_INT(items[0].clone())
        )),
        [1]
    );
    // Local frame, latitude out of range.
    let mut local = items[0].clone();
    local.frame = MavFrame::MAV_FRAME_LOCAL_NED;
    let mut badlat = items[0].clone();
    badlat.x = 950_000_000;
    for (it, want) in [
        (local, MavMissionResult::MAV_MISSION_UNSUPPORTED_FRAME),
        (badlat, MavMissionResult::MAV_MISSION_INVALID_PARAM5_X),
    ] {
        let mut l = link();
        exchange(&mut l, &v, 0, count_msg(1));
        assert_eq!(
            mission_acks(&exchange(&mut l, &v, 1, MavMessage::MISSION_ITEM_INT(it))),
            [want]
        );
    }
    // Busy: an upload while a download runs is denied; from another GCS while uploading too.
    let mut l = link();
    upload(
        &mut l,
        &v,
        0,
        MavMissionType::MAV_MISSION_TYPE_MISSION,
        &items,
    );
    exchange(
        &mut l,
        &v,
        1_000_000,
        MavMessage::MISSION_REQUEST_LIST(MISSION_REQUEST_LIST_DATA {
            target_system: 1,
            target_component: 1,
            mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        }),
    );
    assert_eq!(
        mission_acks(&exchange(&mut l, &v, 1_000_001, count_msg(2))),
        [MavMissionResult::MAV_MISSION_DENIED]
    );
    let mut l = link();
    exchange(&mut l, &v, 0, count_msg(3));
    let other = MavHeader {
        system_id: 254,
        component_id: 190,
        sequence: 0,
    };
    l.handle(&other, &count_msg(2), 1, &v);
    assert_eq!(
        mission_acks(&poll(&mut l, &v, 1)),
        [MavMissionResult::MAV_MISSION_DENIED]
    );
    // The GCS cancels its upload.
    l.handle(
        &hdr(),
        &MavMessage::MISSION_ACK(MISSION_ACK_DATA {
            target_system: 1,
            target_component: 1,
            mavtype: MavMissionResult::MAV_MISSION_OPERATION_CANCELLED,
            mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
            opaque_id: 0,
        }),
        2,
        &v,
    );
    assert!(!l.missions().busy());
    // Requesting an item that does not exist.
    let out = exchange(
        &mut l,
        &v,
        3,
        MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
            seq: 9,
            target_system: 1,
            target_component: 1,
            mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        }),
    );
    assert_eq!(
        mission_acks(&out),
        [MavMissionResult::MAV_MISSION_INVALID_SEQUENCE]
    );
    // mission_type ALL cannot be uploaded.
    let out = exchange(
        &mut l,
        &v,
        4,
        MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
            count: 1,
            target_system: 1,
            target_component: 1,
            mission_type: MavMissionType::MAV_MISSION_TYPE_ALL,
            opaque_id: 0,
        }),
    );
    assert_eq!(
        mission_acks(&out),
        [MavMissionResult::MAV_MISSION_UNSUPPORTED]
    );
}

#[test]
fn upload_timeouts_retries_and_restart() {
    let v = healthy();
    let items = waypoints(4, 0);
    let mut l = link();
    upload(
        &mut l,
        &v,
        0,
        MavMissionType::MAV_MISSION_TYPE_MISSION,
        &items[..1],
    );
    let t0 = 10_000_000;
    assert_eq!(requests(&exchange(&mut l, &v, t0, count_msg(4))), [0]);
    assert_eq!(
        requests(&exchange(
            &mut l,
            &v,
            t0 + 1000,
            MavMessage::MISSION_ITEM_INT(items[0].clone())
        )),
        [1]
    );
    // Silence: item 1 requested again every retry interval, then an error ACK.
    let mut rerequests = Vec::new();
    let mut final_ack = Vec::new();
    let mut now = t0 + 1000;
    while now < t0 + 1000 + UPLOAD_RETRY_US * (u64::from(UPLOAD_MAX_RETRIES) + 2) {
        now += 10_000;
        let out = poll(&mut l, &v, now);
        for s in requests(&out) {
            rerequests.push((s, now));
        }
        final_ack.extend(mission_acks(&out));
    }
    assert_eq!(rerequests.len(), usize::from(UPLOAD_MAX_RETRIES));
    assert!(rerequests.iter().all(|(s, _)| *s == 1));
    let gaps: Vec<u64> = rerequests.windows(2).map(|w| w[1].1 - w[0].1).collect();
    assert!(
        gaps.iter().all(|&g| g.abs_diff(UPLOAD_RETRY_US) <= 10_000),
        "{gaps:?}"
    );
    assert_eq!(final_ack, [MavMissionResult::MAV_MISSION_ERROR]);
    assert!(!l.missions().busy());
    assert_eq!(l.plan.mission.len(), 1, "old mission kept");

    // A retry answered resumes the upload.
    let mut l = link();
    exchange(&mut l, &v, 0, count_msg(2));
    exchange(
        &mut l,
        &v,
        1000,
        MavMessage::MISSION_ITEM_INT(items[0].clone()),
    );
    assert_eq!(requests(&poll(&mut l, &v, 1000 + UPLOAD_RETRY_US)), [1]);
    let out = exchange(
        &mut l,
        &v,
        2000 + UPLOAD_RETRY_US,
        MavMessage::MISSION_ITEM_INT(items[1].clone()),
    );
    assert_eq!(mission_acks(&out), [MavMissionResult::MAV_MISSION_ACCEPTED]);
    // The ACK was lost and the GCS repeats its last item: the same ACK again.
    let out = exchange(
        &mut l,
        &v,
        3000 + UPLOAD_RETRY_US,
        MavMessage::MISSION_ITEM_INT(items[1].clone()),
    );
    assert_eq!(mission_acks(&out), [MavMissionResult::MAV_MISSION_ACCEPTED]);

    // A new count mid-upload restarts it from item 0.
    let mut l = link();
    exchange(&mut l, &v, 0, count_msg(4));
    exchange(
        &mut l,
        &v,
        1,
        MavMessage::MISSION_ITEM_INT(items[0].clone()),
    );
    exchange(
        &mut l,
        &v,
        2,
        MavMessage::MISSION_ITEM_INT(items[1].clone()),
    );
    assert_eq!(requests(&exchange(&mut l, &v, 3, count_msg(3))), [0]);
    assert_eq!(
        upload(
            &mut l,
            &v,
            4,
            MavMissionType::MAV_MISSION_TYPE_MISSION,
            &items[..3]
        ),
        MavMissionResult::MAV_MISSION_ACCEPTED
    );
    assert_eq!(l.plan.mission.len(), 3);
}

#[allow(deprecated)]
#[test]
fn legacy_request_answered_with_item_int_and_set_current() {
    let v = healthy();
    let mut l = link();
    let items = waypoints(3, 0);
    upload(
        &mut l,
        &v,
        0,
        MavMissionType::MAV_MISSION_TYPE_MISSION,
        &items,
    );
    let out = exchange(
        &mut l,
        &v,
        1_000_000,
        MavMessage::MISSION_REQUEST(MISSION_REQUEST_DATA {
            seq: 2,
            target_system: 1,
            target_component: 1,
            mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        }),
    );
    let it = out
        .iter()
        .find_map(|m| match m {
            MavMessage::MISSION_ITEM_INT(i) => Some(i.clone()),
            _ => None,
        })
        .expect("MISSION_ITEM_INT");
    assert!(same_bits(&it, &items[2]));
    // Set current via the command and via the message: MISSION_CURRENT confirms.
    let out = exchange(
        &mut l,
        &v,
        1_000_001,
        cmd_long(
            MavCmd::MAV_CMD_DO_SET_MISSION_CURRENT,
            [2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    );
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_ACCEPTED);
    let mc = out
        .iter()
        .find_map(|m| match m {
            MavMessage::MISSION_CURRENT(c) => Some(c.clone()),
            _ => None,
        })
        .unwrap();
    assert_eq!((mc.seq, mc.total), (2, 3));
    assert_eq!(l.take_requests().mission_seq, Some(2));
    let out = exchange(
        &mut l,
        &v,
        1_000_002,
        MavMessage::MISSION_SET_CURRENT(MISSION_SET_CURRENT_DATA {
            seq: 7,
            target_system: 1,
            target_component: 1,
        }),
    );
    assert!(texts(&out)[0].contains("does not exist"));
    assert_eq!(l.take_requests().mission_seq, None);
}

#[test]
fn malformed_input_never_panics() {
    // Every message kind with extreme field values: the link must answer or ignore, not panic.
    let mut l = link();
    let mut v = healthy();
    v.yaw = f32::NAN;
    v.alt_amsl_m = f32::INFINITY;
    v.battery.present = true;
    v.battery.voltage_v = -1e30;
    let msgs = [
        cmd_long(
            MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
            [f32::NAN, f32::NAN, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
        cmd_long(
            MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
            [30.0, 1e30, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
        cmd_long(
            MavCmd::MAV_CMD_REQUEST_MESSAGE,
            [435.0, 1e9, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
        cmd_long(
            MavCmd::MAV_CMD_REQUEST_MESSAGE,
            [-5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
        cmd_long(
            MavCmd::MAV_CMD_DO_SET_MODE,
            [f32::NAN, 1e9, -1e9, 0.0, 0.0, 0.0, 0.0],
        ),
        cmd_long(
            MavCmd::MAV_CMD_DO_SET_MISSION_CURRENT,
            [1e12, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
        cmd_long(
            MavCmd::MAV_CMD_DO_SET_STANDARD_MODE,
            [f32::INFINITY, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
        MavMessage::PARAM_SET(PARAM_SET_DATA {
            param_value: 1.0,
            param_id: [0xffu8; 16].into(),
            ..Default::default()
        }),
        MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
            param_index: i16::MAX,
            ..Default::default()
        }),
        MavMessage::MISSION_ITEM_INT(MISSION_ITEM_INT_DATA {
            seq: u16::MAX,
            ..Default::default()
        }),
        MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
            seq: u16::MAX,
            ..Default::default()
        }),
        MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
            count: u16::MAX,
            ..Default::default()
        }),
    ];
    let big = MavHeader {
        system_id: 70_000,
        component_id: 1,
        sequence: 0,
    };
    for (k, m) in msgs.iter().enumerate() {
        l.handle(&hdr(), m, k as u64, &v);
        l.handle(&big, m, k as u64, &v);
        poll(&mut l, &v, k as u64 * 1_000_000);
    }
    for _ in 0..100 {
        l.handle(
            &hdr(),
            &cmd_long(
                MavCmd::MAV_CMD_REQUEST_MESSAGE,
                [435.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            ),
            0,
            &v,
        );
    }
    poll(&mut l, &v, 100_000_000);
    assert!(l.dropped() > 0, "overflow counted");
}

#[test]
fn ram_footprint_within_budget() {
    use core::mem::size_of;
    let sizes = [
        ("GroundLink", size_of::<GroundLink>()),
        ("ParamStore", size_of::<ParamStore>()),
        ("MissionManager", size_of::<mission::MissionManager>()),
        ("MissionStore", size_of::<MissionStore>()),
        ("VehicleSnapshot", size_of::<VehicleSnapshot>()),
        ("MavMessage", size_of::<MavMessage>()),
        ("ParamImage", size_of::<crate::params::store::ParamImage>()),
    ];
    for (n, s) in sizes {
        std::println!("{n}: {s} bytes");
    }
    // The MCU has 128 KiB of SRAM; the link (with 240 stored plan items and a staging list
    // for uploads) must leave most of it to the rest of the autopilot.
    assert!(
        size_of::<GroundLink>() <= 20 * 1024,
        "{}",
        size_of::<GroundLink>()
    );
}

#[test]
fn heartbeat_reports_truth_not_requests_and_tracks_gcs() {
    let mut l = link();
    let v = healthy();
    assert_eq!(l.gcs_last_seen_us(), None);
    l.handle(&hdr(), &super::client::gcs_heartbeat(), 42, &v);
    assert_eq!(l.gcs_last_seen_us(), Some(42));
    // Loiter accepted, but the vehicle has not switched: the heartbeat still says Manual and
    // CURRENT_MODE shows the intention.
    let out = exchange(
        &mut l,
        &v,
        100,
        cmd_long(
            MavCmd::MAV_CMD_DO_SET_MODE,
            [1.0, 4.0, 3.0, 0.0, 0.0, 0.0, 0.0],
        ),
    );
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_ACCEPTED);
    assert_eq!(heartbeat_of(&out).unwrap().custom_mode, px4(1, 0));
    let out = exchange(
        &mut l,
        &v,
        200,
        cmd_long(
            MavCmd::MAV_CMD_REQUEST_MESSAGE,
            [436.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    );
    let cm = out
        .iter()
        .find_map(|m| match m {
            MavMessage::CURRENT_MODE(c) => Some(c.clone()),
            _ => None,
        })
        .unwrap();
    assert_eq!(
        (cm.custom_mode, cm.intended_custom_mode),
        (px4(1, 0), px4(4, 3))
    );
}

/// MAVLink's long-running command pattern: IN_PROGRESS at once, then ACCEPTED only when the
/// board reports the save done (FAILED when the flash refused it); never while armed.
#[test]
fn preflight_storage_is_accepted_only_once_the_board_has_saved() {
    let mut l = link();
    let mut v = healthy();
    let store = |p1: f32| {
        cmd_long(
            MavCmd::MAV_CMD_PREFLIGHT_STORAGE,
            [p1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        )
    };
    exchange(
        &mut l,
        &v,
        0,
        param_set("RLL_KP", 2.0, MavParamType::MAV_PARAM_TYPE_REAL32),
    );
    let out = exchange(&mut l, &v, 1, store(1.0));
    let stored = MavCmd::MAV_CMD_PREFLIGHT_STORAGE;
    assert_eq!(acks(&out), [(stored, MavResult::MAV_RESULT_IN_PROGRESS)]);
    let asker = l.take_storage_request().expect("the board owes a save");
    assert_eq!(l.take_storage_request(), None, "once");
    l.storage_done(asker, true);
    assert_eq!(
        acks(&poll(&mut l, &v, 2)),
        [(stored, MavResult::MAV_RESULT_ACCEPTED)]
    );
    exchange(&mut l, &v, 3, store(1.0));
    let asker = l.take_storage_request().unwrap();
    l.storage_done(asker, false);
    let out = poll(&mut l, &v, 4);
    assert_eq!(acks(&out), [(stored, MavResult::MAV_RESULT_FAILED)]);
    assert!(texts(&out).iter().any(|t| t.contains("not saved")));

    v.armed = true;
    let out = exchange(&mut l, &v, 5, store(1.0));
    assert_eq!(
        acks(&out),
        [(stored, MavResult::MAV_RESULT_TEMPORARILY_REJECTED)]
    );
    let out = exchange(&mut l, &v, 6, store(2.0));
    assert_eq!(acks(&out), [(stored, MavResult::MAV_RESULT_DENIED)]);
    assert_eq!(l.take_storage_request(), None, "nothing saved armed");
    assert_eq!(l.params.get("RLL_KP"), Some(2.0));
    v.armed = false;
    let out = exchange(&mut l, &v, 7, store(2.0));
    assert_eq!(acks(&out), [(stored, MavResult::MAV_RESULT_IN_PROGRESS)]);
    assert_eq!(l.params.get("RLL_KP"), Some(0.8));
    assert!(l.take_storage_request().is_some());
}

#[test]
fn a_reboot_is_asked_of_the_board_only_when_disarmed() {
    let mut l = link();
    let mut v = healthy();
    let reboot = |p1: f32| {
        cmd_long(
            MavCmd::MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN,
            [p1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        )
    };
    let cmd = MavCmd::MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN;
    v.armed = true;
    let out = exchange(&mut l, &v, 0, reboot(1.0));
    assert_eq!(acks(&out), [(cmd, MavResult::MAV_RESULT_DENIED)]);
    assert!(!l.take_reboot_request());
    v.armed = false;
    let out = exchange(&mut l, &v, 1, reboot(2.0));
    assert_eq!(acks(&out), [(cmd, MavResult::MAV_RESULT_UNSUPPORTED)]);
    let out = exchange(&mut l, &v, 2, reboot(1.0));
    assert_eq!(acks(&out), [(cmd, MavResult::MAV_RESULT_ACCEPTED)]);
    assert!(l.take_reboot_request());
    assert!(!l.take_reboot_request());
}

/// An upload is checked as the navigator will fly it before it replaces the stored mission:
/// an impossible item is refused with the MAVLink code that names its field, the old mission
/// stays; what will be flown differently is accepted with a warning.
#[test]
fn uploads_are_checked_as_the_navigator_will_fly_them() {
    let mut l = link();
    let v = healthy();
    let mission = MavMissionType::MAV_MISSION_TYPE_MISSION;
    let good = waypoints(3, 0);
    assert_eq!(
        upload(&mut l, &v, 0, mission, &good),
        MavMissionResult::MAV_MISSION_ACCEPTED
    );
    let stored = l.plan.items(PlanKind::Mission).to_vec();
    let mut too_high = good.clone();
    too_high[1].z = 5000.0;
    assert_eq!(
        upload(&mut l, &v, 1_000_000, mission, &too_high),
        MavMissionResult::MAV_MISSION_INVALID_PARAM7
    );
    let mut bad_lat = good.clone();
    bad_lat[2].x = 950_000_000;
    assert_eq!(
        upload(&mut l, &v, 2_000_000, mission, &bad_lat),
        MavMissionResult::MAV_MISSION_INVALID_PARAM5_X
    );
    let mut jump = good.clone();
    jump[2].command = MavCmd::MAV_CMD_DO_JUMP;
    jump[2].frame = MavFrame::MAV_FRAME_MISSION;
    jump[2].param1 = 9.0;
    jump[2].param2 = 1.0;
    assert_eq!(
        upload(&mut l, &v, 3_000_000, mission, &jump),
        MavMissionResult::MAV_MISSION_INVALID_SEQUENCE
    );
    assert_eq!(l.plan.items(PlanKind::Mission), &stored[..]);
    let mut odd = good.clone();
    odd[1].command = MavCmd::MAV_CMD_DO_SET_SERVO;
    odd[1].frame = MavFrame::MAV_FRAME_MISSION;
    let (result, mut said) = upload_said(&mut l, &v, 4_000_000, mission, &odd);
    assert_eq!(result, MavMissionResult::MAV_MISSION_ACCEPTED);
    said.extend(texts(&poll(&mut l, &v, 4_500_000)));
    let said = said.join(" | ");
    assert!(said.contains("Item 1: command 183 unsupported"), "{said}");
    assert!(said.contains("no landing"), "{said}");
}

#[test]
fn change_speed_is_held_to_the_vehicles_airspeed_range() {
    let mut l = link();
    let v = healthy();
    let speed = |s: f32| {
        cmd_long(
            MavCmd::MAV_CMD_DO_CHANGE_SPEED,
            [0.0, s, -1.0, 0.0, 0.0, 0.0, 0.0],
        )
    };
    let out = exchange(&mut l, &v, 0, speed(20.0));
    assert_eq!(
        acks(&out),
        [(
            MavCmd::MAV_CMD_DO_CHANGE_SPEED,
            MavResult::MAV_RESULT_ACCEPTED
        )]
    );
    assert_eq!(l.take_requests().airspeed, Some(20.0));
    // Above NAV_ASPD_MAX (25 m/s here): denied, with the range in the text.
    let out = exchange(&mut l, &v, 0, speed(28.0));
    assert_eq!(
        acks(&out),
        [(
            MavCmd::MAV_CMD_DO_CHANGE_SPEED,
            MavResult::MAV_RESULT_DENIED
        )]
    );
    assert!(
        texts(&out).iter().any(|t| t.contains("[13, 25]")),
        "{:?}",
        texts(&out)
    );
    assert_eq!(l.take_requests().airspeed, None);
    // -1: "no change" in the command's own convention.
    let out = exchange(&mut l, &v, 0, speed(-1.0));
    assert_eq!(
        acks(&out),
        [(
            MavCmd::MAV_CMD_DO_CHANGE_SPEED,
            MavResult::MAV_RESULT_ACCEPTED
        )]
    );
    assert_eq!(l.take_requests().airspeed, None);
}

/// `MAV_CMD_DO_GO_AROUND` (PX4's and ArduPilot's abort of a landing) is accepted while the
/// vehicle is landing and armed, and queued for the navigator; in the air on any other leg,
/// or disarmed, it is refused for now (`TEMPORARILY_REJECTED`) and nothing is queued.
#[test]
fn a_go_around_is_accepted_only_while_landing() {
    let mut l = link();
    let go_around = || cmd_long(MavCmd::MAV_CMD_DO_GO_AROUND, [0.0; 7]);
    let mut v = healthy();
    for (armed, landed, expected) in [
        (true, LandedState::Landing, MavResult::MAV_RESULT_ACCEPTED),
        (
            true,
            LandedState::InAir,
            MavResult::MAV_RESULT_TEMPORARILY_REJECTED,
        ),
        (
            true,
            LandedState::OnGround,
            MavResult::MAV_RESULT_TEMPORARILY_REJECTED,
        ),
        (
            false,
            LandedState::Landing,
            MavResult::MAV_RESULT_TEMPORARILY_REJECTED,
        ),
    ] {
        v.armed = armed;
        v.landed = landed;
        let out = exchange(&mut l, &v, 0, go_around());
        assert_eq!(
            acks(&out),
            [(MavCmd::MAV_CMD_DO_GO_AROUND, expected)],
            "armed {armed}, {landed:?}"
        );
        assert_eq!(
            l.take_requests().go_around,
            expected == MavResult::MAV_RESULT_ACCEPTED,
            "armed {armed}, {landed:?}"
        );
    }
}

/// What the next poll sends back on `channel` (answers to its stations and broadcasts).
fn poll_channel(l: &mut Bench, v: &VehicleSnapshot, now: u64, channel: u8) -> Vec<MavMessage> {
    let mut out = Vec::new();
    l.poll_to(now, v, |d, m| {
        if d.reaches(channel) {
            out.push(m);
        }
    });
    out
}

#[test]
fn two_stations_with_one_identity_on_two_channels_cannot_interleave_an_upload() {
    let mut l = link();
    let v = healthy();
    let a = waypoints(3, 0);
    let b = waypoints(5, 100);
    // Both say "255/190"; only the board's channel tells them apart.
    l.handle_on(0, &hdr(), &count_msg(3), 0, &v);
    l.handle_on(1, &hdr(), &count_msg(5), 0, &v);
    let mut to_a = Vec::new();
    let mut to_b = Vec::new();
    l.poll_to(0, &v, |d, m| match d {
        Dest::Channel(0) => to_a.push(m),
        Dest::Channel(1) => to_b.push(m),
        _ => {}
    });
    assert_eq!(requests(&to_a), [0], "the first station's upload starts");
    assert_eq!(
        mission_acks(&to_b),
        [MavMissionResult::MAV_MISSION_DENIED],
        "the second is told the vehicle is busy, on its own channel only"
    );
    assert!(mission_acks(&to_a).is_empty());
    // The second station sends its items anyway, interleaved with the first's.
    let mut acks_a = Vec::new();
    for (i, item_b) in b.iter().enumerate() {
        if let Some(item) = a.get(i) {
            let m = MavMessage::MISSION_ITEM_INT(item.clone());
            l.handle_on(0, &hdr(), &m, 1, &v);
            acks_a.extend(mission_acks(&poll_channel(&mut l, &v, 1, 0)));
        }
        let m = MavMessage::MISSION_ITEM_INT(item_b.clone());
        l.handle_on(1, &hdr(), &m, 1, &v);
    }
    assert_eq!(acks_a, [MavMissionResult::MAV_MISSION_ACCEPTED]);
    // The stored mission is the first station's, complete.
    assert_eq!(l.plan.mission.len(), 3);
    for (stored, sent) in l.plan.mission.iter().zip(&a) {
        assert_eq!(stored.x, sent.x);
    }
}

#[test]
fn a_parameter_list_goes_to_the_channel_that_asked() {
    let mut l = link();
    let v = healthy();
    let list = MavMessage::PARAM_REQUEST_LIST(PARAM_REQUEST_LIST_DATA {
        target_system: 1,
        target_component: 1,
    });
    l.handle_on(2, &hdr(), &list, 0, &v);
    let mut dests = Vec::new();
    for k in 0..10 {
        l.poll_to(k * 20_000, &v, |d, m| {
            if matches!(m, MavMessage::PARAM_VALUE(_)) {
                dests.push(d);
            }
        });
    }
    assert_eq!(dests.len(), 6);
    assert!(dests.iter().all(|d| *d == Dest::Channel(2)), "{dests:?}");
}

#[test]
fn a_nan_message_interval_is_denied_and_the_rate_kept() {
    let mut l = link();
    let v = healthy();
    let set = |iv: f32| {
        cmd_long(
            MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
            [30.0, iv, 0.0, 0.0, 0.0, 0.0, 0.0],
        )
    };
    assert_eq!(
        acks(&exchange(&mut l, &v, 0, set(f32::NAN)))[0].1,
        MavResult::MAV_RESULT_DENIED
    );
    // ATTITUDE stays at its default 15 Hz, not the 1 kHz a NaN cast to an integer gave.
    let n = count_over(&mut l, &v, 1_000, 10, 30);
    assert!(n.abs_diff(150) <= 1, "default gave {n}");
}

#[test]
#[allow(deprecated)] // PROTOCOL_VERSION: deprecated in the dialect, still asked for by QGC 4.
fn protocol_version_is_answered_both_ways_with_mavlink_2() {
    let mut l = link();
    let v = healthy();
    for msg in [
        cmd_long(
            MavCmd::MAV_CMD_REQUEST_PROTOCOL_VERSION,
            [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
        cmd_long(
            MavCmd::MAV_CMD_REQUEST_MESSAGE,
            [300.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    ] {
        let out = exchange(&mut l, &v, 0, msg);
        assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_ACCEPTED);
        let pv = out.iter().find_map(|m| match m {
            MavMessage::PROTOCOL_VERSION(p) => Some(p.clone()),
            _ => None,
        });
        let pv = pv.expect("PROTOCOL_VERSION after the ACK");
        assert_eq!(
            (pv.version, pv.min_version, pv.max_version),
            (200, 100, 200)
        );
    }
}

#[test]
fn a_long_status_text_goes_out_in_chunks_a_station_can_join() {
    let mut l = link();
    let v = healthy();
    let long: std::string::String = (0..120)
        .map(|i| char::from(b'a' + (i % 26) as u8))
        .collect();
    l.send_statustext(MavSeverity::MAV_SEVERITY_WARNING, &long);
    let exact: std::string::String = "x".repeat(100);
    l.send_statustext(MavSeverity::MAV_SEVERITY_INFO, &exact);
    let chunks: Vec<STATUSTEXT_DATA> = poll(&mut l, &v, 0)
        .into_iter()
        .filter_map(|m| match m {
            MavMessage::STATUSTEXT(t) => Some(t),
            _ => None,
        })
        .collect();
    // 120 bytes: 50, 50 and 20 (NUL-terminated); 100 bytes: 50, 50 and an empty closing chunk.
    assert_eq!(chunks.len(), 6);
    let (a, b) = chunks.split_at(3);
    assert!(a.iter().all(|c| c.id == a[0].id) && a[0].id != 0);
    assert!(b.iter().all(|c| c.id == b[0].id) && b[0].id != a[0].id);
    assert_eq!(a.iter().map(|c| c.chunk_seq).collect::<Vec<_>>(), [0, 1, 2]);
    // Joined as QGroundControl joins them: up to the first NUL.
    let join = |cs: &[STATUSTEXT_DATA]| -> std::string::String {
        let bytes: Vec<u8> = cs.iter().flat_map(|c| c.text.iter().copied()).collect();
        let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
        std::string::String::from_utf8(bytes[..end].to_vec()).unwrap()
    };
    assert_eq!(join(a), long);
    assert_eq!(join(b), exact);
    assert_eq!(b[2].text[0], 0);
}

fn param_errors(out: &[MavMessage]) -> Vec<(i16, MavParamError)> {
    out.iter()
        .filter_map(|m| match m {
            MavMessage::PARAM_ERROR(e) => Some((e.param_index, e.error)),
            _ => None,
        })
        .collect()
}

#[test]
fn unknown_names_and_refused_values_get_a_param_error() {
    let mut l = link();
    let v = healthy();
    let out = exchange(
        &mut l,
        &v,
        0,
        param_set("NO_SUCH", 1.0, MavParamType::MAV_PARAM_TYPE_REAL32),
    );
    assert_eq!(
        param_errors(&out),
        [(-1, MavParamError::MAV_PARAM_ERROR_DOES_NOT_EXIST)]
    );
    let read = MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
        param_index: -1,
        target_system: 1,
        target_component: 1,
        param_id: "NO_SUCH".into(),
    });
    let out = exchange(&mut l, &v, 1, read);
    assert_eq!(
        param_errors(&out),
        [(-1, MavParamError::MAV_PARAM_ERROR_DOES_NOT_EXIST)]
    );
    // Out of bounds: PARAM_ERROR with its index, and the echo of the value kept.
    let out = exchange(
        &mut l,
        &v,
        2,
        param_set("RLL_KP", 9.0, MavParamType::MAV_PARAM_TYPE_REAL32),
    );
    assert_eq!(
        param_errors(&out),
        [(0, MavParamError::MAV_PARAM_ERROR_VALUE_OUT_OF_RANGE)]
    );
    assert_eq!(param_values(&out)[0].param_value, 0.8);
    // The wrong type for a real.
    let out = exchange(
        &mut l,
        &v,
        3,
        param_set("RLL_KP", 1.0, MavParamType::MAV_PARAM_TYPE_UINT8),
    );
    assert_eq!(
        param_errors(&out),
        [(0, MavParamError::MAV_PARAM_ERROR_TYPE_MISMATCH)]
    );
}

static GENERAL_JSON: &[u8] = br#"{"version":1,"metadataTypes":[]}"#;
static FILES: [super::ftp::File; 1] = [super::ftp::File {
    name: super::ftp::GENERAL,
    bytes: GENERAL_JSON,
}];

fn ftp_request(seq: u16, opcode: u8, data: &[u8]) -> MavMessage {
    let mut payload = [0u8; 251];
    payload[..2].copy_from_slice(&seq.to_le_bytes());
    payload[3] = opcode;
    payload[4] = data.len() as u8;
    payload[12..12 + data.len()].copy_from_slice(data);
    MavMessage::FILE_TRANSFER_PROTOCOL(FILE_TRANSFER_PROTOCOL_DATA {
        target_network: 0,
        target_system: 1,
        target_component: 1,
        payload,
    })
}

/// `MAV_CMD_REQUEST_MESSAGE` for message `id`.
fn request(id: f32) -> MavMessage {
    cmd_long(
        MavCmd::MAV_CMD_REQUEST_MESSAGE,
        [id, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    )
}

/// The capabilities of the `AUTOPILOT_VERSION` among `out`.
fn capabilities(out: &[MavMessage]) -> MavProtocolCapability {
    let caps = out.iter().find_map(|m| match m {
        MavMessage::AUTOPILOT_VERSION(d) => Some(d.capabilities),
        _ => None,
    });
    caps.expect("AUTOPILOT_VERSION after the ACK")
}

#[test]
fn component_metadata_points_to_the_general_file_which_ftp_serves_to_the_asker() {
    let mut l = link();
    l.link = GroundLink::new(LinkConfig {
        files: &FILES,
        ..LinkConfig::default()
    });
    let v = healthy();
    let out = exchange(&mut l, &v, 2_000_000, request(397.0));
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_ACCEPTED);
    let meta = out.iter().find_map(|m| match m {
        MavMessage::COMPONENT_METADATA(d) => Some(d.clone()),
        _ => None,
    });
    let meta = meta.expect("COMPONENT_METADATA after the ACK");
    assert_eq!(meta.uri.to_str().unwrap(), "mftp://general.json");
    assert_eq!(meta.file_crc, super::ftp::file_crc(GENERAL_JSON));
    assert_eq!(meta.time_boot_ms, 2000);
    // The deprecated COMPONENT_INFORMATION is not served: QGroundControl moves on at once.
    let out = exchange(&mut l, &v, 2_000_000, request(395.0));
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_UNSUPPORTED);
    // AUTOPILOT_VERSION says FTP is spoken.
    let out = exchange(&mut l, &v, 2_000_000, request(148.0));
    assert!(capabilities(&out).contains(MavProtocolCapability::MAV_PROTOCOL_CAPABILITY_FTP));
    // The file opens for the station on channel 2 and its answer goes there only.
    l.handle_on(
        2,
        &hdr(),
        &ftp_request(7, 4, b"/general.json"),
        2_000_000,
        &v,
    );
    let mut answers = Vec::new();
    l.poll_to(2_000_000, &v, |d, m| {
        if let MavMessage::FILE_TRANSFER_PROTOCOL(f) = m {
            answers.push((d, f));
        }
    });
    assert_eq!(answers.len(), 1);
    let (dest, f) = &answers[0];
    assert_eq!(*dest, Dest::Channel(2));
    // Sequence plus one, ACK, four bytes of length.
    assert_eq!(
        (
            u16::from_le_bytes([f.payload[0], f.payload[1]]),
            f.payload[3]
        ),
        (8, 128)
    );
    let len = u32::from_le_bytes([f.payload[12], f.payload[13], f.payload[14], f.payload[15]]);
    assert_eq!(len as usize, GENERAL_JSON.len());
    assert_eq!((f.target_system, f.target_component), GCS);
}

#[test]
fn without_served_files_component_metadata_is_unsupported_and_ftp_not_claimed() {
    let mut l = link();
    let v = healthy();
    let out = exchange(&mut l, &v, 0, request(397.0));
    assert_eq!(acks(&out)[0].1, MavResult::MAV_RESULT_UNSUPPORTED);
    let out = exchange(&mut l, &v, 0, request(148.0));
    assert!(!capabilities(&out).contains(MavProtocolCapability::MAV_PROTOCOL_CAPABILITY_FTP));
}

#[test]
fn sys_status_and_battery_status_carry_the_monitor_s_figures_or_say_unknown() {
    use crate::battery::{Battery, Warning};
    let mut v = healthy();
    // No battery monitored: MAVLink's unknowns.
    let MavMessage::SYS_STATUS(s) = super::telemetry::sys_status(&v, 0) else {
        panic!("SYS_STATUS")
    };
    assert_eq!(
        (s.voltage_battery, s.current_battery, s.battery_remaining),
        (u16::MAX, -1, -1)
    );
    assert!(!s
        .onboard_control_sensors_present
        .contains(MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_BATTERY));
    let MavMessage::BATTERY_STATUS(b) = super::telemetry::battery_status(&v) else {
        panic!("BATTERY_STATUS")
    };
    assert_eq!(b.voltages, [u16::MAX; 10]);
    assert_eq!(
        (b.current_consumed, b.energy_consumed, b.time_remaining),
        (-1, -1, 0)
    );
    assert_eq!(
        b.charge_state,
        MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_UNDEFINED
    );
    // 11.1 V, 8.25 A, 512.4 mAh and 5.5 Wh used (198 hJ), 84 % left, 20 min to go.
    v.battery = Battery {
        present: true,
        voltage_v: 11.1,
        current_a: 8.25,
        consumed_mah: 512.4,
        energy_wh: 5.5,
        remaining: 0.84,
        time_remaining_s: 1200.4,
        warning: Warning::None,
    };
    let MavMessage::SYS_STATUS(s) = super::telemetry::sys_status(&v, 0) else {
        panic!("SYS_STATUS")
    };
    assert_eq!(
        (s.voltage_battery, s.current_battery, s.battery_remaining),
        (11_100, 825, 84)
    );
    assert!(s
        .onboard_control_sensors_health
        .contains(MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_BATTERY));
    let MavMessage::BATTERY_STATUS(b) = super::telemetry::battery_status(&v) else {
        panic!("BATTERY_STATUS")
    };
    assert_eq!(b.voltages[0], 11_100);
    assert!(b.voltages[1..].iter().all(|&c| c == u16::MAX));
    assert_eq!(
        (
            b.current_battery,
            b.current_consumed,
            b.energy_consumed,
            b.battery_remaining,
            b.time_remaining
        ),
        (825, 512, 198, 84, 1200)
    );
    assert_eq!(
        b.charge_state,
        MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_OK
    );
    // Each warning level as its charge state; from Low the battery is unhealthy.
    for (w, state) in [
        (
            Warning::Low,
            MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_LOW,
        ),
        (
            Warning::Critical,
            MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_CRITICAL,
        ),
        (
            Warning::Emergency,
            MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_EMERGENCY,
        ),
    ] {
        v.battery.warning = w;
        let MavMessage::BATTERY_STATUS(b) = super::telemetry::battery_status(&v) else {
            panic!("BATTERY_STATUS")
        };
        assert_eq!(b.charge_state, state);
        let MavMessage::SYS_STATUS(s) = super::telemetry::sys_status(&v, 0) else {
            panic!("SYS_STATUS")
        };
        assert!(!s
            .onboard_control_sensors_health
            .contains(MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_BATTERY));
    }
}

#[test]
fn a_warnings_text_is_what_its_display_writes() {
    use crate::navigation::validate::ValidationWarning;
    for w in [
        ValidationWarning::NoLanding,
        ValidationWarning::WillSkip { seq: 0, command: 0 },
        ValidationWarning::WillSkip {
            seq: u16::MAX,
            command: u16::MAX,
        },
        ValidationWarning::ApproachTooShort { seq: 7 },
        ValidationWarning::ApproachTooShort { seq: u16::MAX },
    ] {
        assert_eq!(
            MissionManager::warning_text(&w).as_str(),
            w.to_string(),
            "{w:?}"
        );
    }
}

#[test]
fn a_line_writes_what_write_writes_and_stops_at_the_first_piece_that_does_not_fit() {
    use super::texts::Line;
    use crate::decimal::{fixed, trimmed};
    use std::format;
    for v in [0u64, 7, 10, 65_535, u64::from(u32::MAX), u64::MAX] {
        assert_eq!(Line::<40>::new().uint(v).as_str(), format!("{v}"));
    }
    for v in [0u32, 1, 0xf, 0x10, 0x0800_c0de, 0xdead_beef, u32::MAX] {
        assert_eq!(Line::<40>::new().hex8(v).as_str(), format!("{v:#010x}"));
    }
    for x in [
        0.0f32,
        -0.0,
        0.05,
        17.0,
        -3.25,
        1e30,
        f32::NAN,
        f32::INFINITY,
        1.0e-7,
    ] {
        for places in [0u8, 2, 6] {
            assert_eq!(
                Line::<80>::new().decimal(fixed(x, places)).as_str(),
                format!("{}", fixed(x, places))
            );
            assert_eq!(
                Line::<80>::new().decimal(trimmed(x, places)).as_str(),
                format!("{}", trimmed(x, places))
            );
        }
    }
    // As `write!` into a `heapless::String`: a piece is taken whole or not at all, and
    // nothing after the first that does not fit.
    let mut l = Line::<8>::new();
    l.str("abc").uint(12_345);
    assert_eq!(l.as_str(), "abc12345");
    assert!(!l.is_cut());
    l.str("e");
    assert!(l.is_cut());
    let mut l = Line::<8>::new();
    l.str("abcd").str("efghi").str("j");
    assert_eq!(l.as_str(), "abcd");
    assert!(l.is_cut());
    let mut s = heapless::String::<8>::new();
    let middle = "efghi".to_string();
    assert!(core::fmt::Write::write_fmt(&mut s, format_args!("abcd{middle}j")).is_err());
    assert_eq!(s.as_str(), l.as_str());
}

#[test]
fn the_targets_of_every_message_the_dialect_reads_are_the_crates() {
    use crate::link::dialect::Autopilot;
    use mavlink::Message;
    for &id in Autopilot::READS {
        let mut m = MavMessage::default_message_from_id(id).expect("a common message");
        // Different values in the two fields, so that one read for the other shows.
        if let Some(t) = m.target_system_id_mut() {
            *t = 7;
        }
        if let Some(c) = m.target_component_id_mut() {
            *c = 9;
        }
        assert_eq!(
            super::targets(&m),
            (m.target_system_id(), m.target_component_id()),
            "message {id}"
        );
    }
}

fn autotune_cmd(enable: bool) -> MavMessage {
    let p1 = if enable { 1.0 } else { 0.0 };
    cmd_long(
        MavCmd::MAV_CMD_DO_AUTOTUNE_ENABLE,
        [p1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    )
}

/// The autotune's answers with their progress.
fn autotune_acks(out: &[MavMessage]) -> Vec<(MavResult, u8)> {
    out.iter()
        .filter_map(|m| match m {
            MavMessage::COMMAND_ACK(a) if a.command == MavCmd::MAV_CMD_DO_AUTOTUNE_ENABLE => {
                Some((a.result, a.progress))
            }
            _ => None,
        })
        .collect()
}

/// Flying Altitude, armed, in the air.
fn airborne() -> VehicleSnapshot {
    VehicleSnapshot {
        armed: true,
        landed: LandedState::InAir,
        mode: FlightMode::Altitude,
        ..healthy()
    }
}

/// Autotune is refused, with the reason as a STATUSTEXT and nothing asked of the vehicle, on
/// the ground, in the navigator's modes, in a failsafe and with the GPS or the airspeed
/// sensor failed (as PX4 refuses it outside its stabilised modes).
#[test]
fn autotune_is_refused_on_the_ground_in_a_mission_in_a_failsafe_and_with_a_failed_sensor() {
    type Spoil = fn(&mut VehicleSnapshot);
    let cases: [(Spoil, &str); 5] = [
        (
            |v| v.landed = LandedState::OnGround,
            "Autotune refused: not in the air",
        ),
        (
            |v| v.mode = FlightMode::Mission,
            "Autotune refused: fly Stabilized, Altitude or Hold",
        ),
        (|v| v.failsafe = true, "Autotune refused: failsafe active"),
        (
            |v| v.health.gps_ok = false,
            "Autotune refused: GPS or airspeed failed",
        ),
        (
            |v| v.health.airspeed_ok = false,
            "Autotune refused: GPS or airspeed failed",
        ),
    ];
    for (spoil, why) in cases {
        let mut l = link();
        let mut v = airborne();
        spoil(&mut v);
        let out = exchange(&mut l, &v, 0, autotune_cmd(true));
        assert_eq!(
            autotune_acks(&out),
            [(MavResult::MAV_RESULT_DENIED, 0)],
            "{why}"
        );
        assert_eq!(texts(&out), [why]);
        assert_eq!(l.take_requests().autotune, None, "{why}");
    }
}

/// QGroundControl's autotune: the first command starts it (`IN_PROGRESS`, 0), the same
/// command every second after asks how far it is (`IN_PROGRESS` with the vehicle's progress,
/// no second start), and its end is told to the station that started it unasked (ACCEPTED,
/// progress 100); a poll already on its way gets the same answer, not a new autotune.
#[test]
fn autotune_starts_once_answers_polls_with_progress_and_tells_its_end() {
    let mut l = link();
    let mut v = airborne();
    let out = exchange(&mut l, &v, 0, autotune_cmd(true));
    assert_eq!(
        autotune_acks(&out),
        [(MavResult::MAV_RESULT_IN_PROGRESS, 0)]
    );
    assert_eq!(l.take_requests().autotune, Some(true));
    // The previous autotune's end, still in the snapshot, is not this one's.
    v.autotune = Status::Failed;
    assert!(autotune_acks(&poll(&mut l, &v, 20_000)).is_empty());
    v.autotune = Status::Running(27);
    let out = exchange(&mut l, &v, 1_000_000, autotune_cmd(true));
    assert_eq!(
        autotune_acks(&out),
        [(MavResult::MAV_RESULT_IN_PROGRESS, 27)]
    );
    assert_eq!(l.take_requests().autotune, None, "not started twice");
    v.autotune = Status::Succeeded;
    let out = poll(&mut l, &v, 2_000_000);
    assert_eq!(autotune_acks(&out), [(MavResult::MAV_RESULT_ACCEPTED, 100)]);
    assert!(
        autotune_acks(&poll(&mut l, &v, 2_100_000)).is_empty(),
        "told once"
    );
    let out = exchange(&mut l, &v, 2_500_000, autotune_cmd(true));
    assert_eq!(autotune_acks(&out), [(MavResult::MAV_RESULT_ACCEPTED, 100)]);
    assert_eq!(l.take_requests().autotune, None);
    // Later, the same command is a new autotune.
    let out = exchange(&mut l, &v, 9_000_000, autotune_cmd(true));
    assert_eq!(
        autotune_acks(&out),
        [(MavResult::MAV_RESULT_IN_PROGRESS, 0)]
    );
    assert_eq!(l.take_requests().autotune, Some(true));
}

/// An autotune that ends without gains is told as FAILED; param1 = 0 is accepted and asks the
/// vehicle to stop (or to put back the gains the last one replaced).
#[test]
fn a_failed_autotune_is_told_as_failed_and_a_disable_is_passed_on() {
    let mut l = link();
    let mut v = airborne();
    exchange(&mut l, &v, 0, autotune_cmd(true));
    l.take_requests();
    v.autotune = Status::Running(45);
    poll(&mut l, &v, 500_000);
    v.autotune = Status::Failed;
    let out = poll(&mut l, &v, 1_000_000);
    assert_eq!(autotune_acks(&out), [(MavResult::MAV_RESULT_FAILED, 0)]);
    let out = exchange(&mut l, &v, 9_000_000, autotune_cmd(false));
    assert_eq!(autotune_acks(&out), [(MavResult::MAV_RESULT_ACCEPTED, 0)]);
    assert_eq!(l.take_requests().autotune, Some(false));
}

/// A design that misses a margin is told in one STATUSTEXT with the loop, the margin and its
/// target (the longest loop name with the longest figures among them), within the 50
/// characters of the message.
#[test]
fn a_design_failure_fits_one_statustext_with_its_loop_margin_and_target() {
    use crate::tuning::autotune::{Failure, Report};
    use crate::tuning::design::{DesignFailure, Loop, Reason};
    let failed = |reason| {
        let r = Report::Failed(Failure::Design(DesignFailure {
            loop_: Some(Loop::AirspeedThrottle),
            reason,
        }));
        tune::words(&r).1.as_str().to_string()
    };
    assert_eq!(
        failed(Reason::PhaseMargin {
            deg: -137.1,
            min_deg: 30.0
        }),
        "Autotune failed: aspd-thr: PM -137.1 deg < 30"
    );
    assert_eq!(
        failed(Reason::GainMargin(-33.4)),
        "Autotune failed: aspd-thr: GM -33.4 dB < 6"
    );
    for l in Loop::ALL {
        let r = Report::Failed(Failure::Design(DesignFailure {
            loop_: Some(l),
            reason: Reason::PhaseMargin {
                deg: -137.1,
                min_deg: 45.0,
            },
        }));
        let text = tune::words(&r).1;
        assert!(text.as_str().ends_with("deg < 45"), "{}", text.as_str());
    }
}
