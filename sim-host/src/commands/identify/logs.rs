//! The logs `sim-host identify` reads: a simulator link's `.tlog`, a ground link's `.tlog` and
//! the autopilot's own flight log, each as the samples the identifier takes.

use crate::link::tlog::read_tlog;
use crate::report::sig;
use anyhow::{bail, Context};
use common::actuators::Surfaces;
use common::gcs::{COMPONENT_ID, SYSTEM_ID};
use common::link::framing::FrameParser;
use common::math::frames::{course_and_speed, Euler};
use common::math::STANDARD_GRAVITY;
use common::tuning::identify::Sample;
use mavlink::dialects::common::MavMessage;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use std::path::Path;

/// One sample of the log with its time and height, and the attitude and ground velocity its
/// angle of attack is read from once the wind is known.
#[derive(Clone, Copy)]
pub(super) struct Timed {
    pub(super) time_us: u64,
    pub(super) alt_m: f64,
    pub(super) armed: bool,
    pub(super) attitude: UnitQuaternion<f64>,
    pub(super) v_ned: Vector3<f64>,
    pub(super) sample: Sample,
}

/// The samples of a simulator-link `.tlog`: each truth frame joined with the autopilot's
/// answer to it.
pub(super) fn samples(bytes: &[u8]) -> Vec<Timed> {
    let mut parser = FrameParser::new();
    // The last truth frame, waiting for the autopilot's answer to it.
    let mut truth: Option<Timed> = None;
    let mut out = Vec::new();
    for (_, frame) in read_tlog(bytes) {
        parser.push(&frame, |f| match f.message {
            MavMessage::HIL_STATE_QUATERNION(d) => {
                let q = d.attitude_quaternion.map(f64::from);
                let Some(q) =
                    UnitQuaternion::try_new(Quaternion::new(q[0], q[1], q[2], q[3]), 1e-6)
                else {
                    return;
                };
                let e = Euler::from_quaternion(&q);
                let v = Vector3::new(f64::from(d.vx), f64::from(d.vy), f64::from(d.vz)) / 100.0;
                let (course, gs) = course_and_speed(&v);
                let va = f64::from(d.true_airspeed) / 100.0;
                let climb = -v.z;
                let s = Sample {
                    p: d.rollspeed,
                    q: d.pitchspeed,
                    r: d.yawspeed,
                    phi: e.phi as f32,
                    theta: e.theta as f32,
                    airspeed: va as f32,
                    ay: (f64::from(d.yacc) * STANDARD_GRAVITY / 1000.0) as f32,
                    accel_y: (f64::from(d.yacc) * STANDARD_GRAVITY / 1000.0) as f32,
                    climb_rate: climb as f32,
                    course: course as f32,
                    ground_speed: gs as f32,
                    ..Sample::default()
                };
                truth = Some(Timed {
                    time_us: d.time_usec,
                    alt_m: f64::from(d.alt) / 1000.0,
                    armed: false,
                    attitude: q,
                    v_ned: v,
                    sample: s,
                });
            }
            MavMessage::HIL_ACTUATOR_CONTROLS(d)
                if (f.header.system_id, f.header.component_id)
                    == (u32::from(SYSTEM_ID), COMPONENT_ID) =>
            {
                let Some(t) = truth.filter(|t| t.time_us == d.time_usec) else {
                    return;
                };
                let c = Surfaces::from_px4_controls([
                    d.controls[0],
                    d.controls[1],
                    d.controls[2],
                    d.controls[3],
                ]);
                out.push(Timed {
                    armed: d.mode.bits() & 128 != 0,
                    sample: Sample {
                        aileron: c.aileron,
                        elevator: c.elevator,
                        rudder: c.rudder,
                        throttle: c.throttle,
                        ..t.sample
                    },
                    ..t
                });
            }
            _ => {}
        });
    }
    out
}

/// A sample's climb rate, course and ground speed from the velocity over the ground (NED, m/s),
/// and its surfaces and throttle.
fn moving(v_ned: &Vector3<f64>, c: &Surfaces) -> Sample {
    let (course, gs) = course_and_speed(v_ned);
    Sample {
        climb_rate: -v_ned.z as f32,
        course: course as f32,
        ground_speed: gs as f32,
        aileron: c.aileron,
        elevator: c.elevator,
        rudder: c.rudder,
        throttle: c.throttle,
        ..Sample::default()
    }
}

/// The messages a ground-link `.tlog` is read from, each needed at [`ULOG_INTERVAL_MAX_S`]
/// or faster.
const GROUND_MESSAGES: [&str; 4] = [
    "ATTITUDE",
    "SERVO_OUTPUT_RAW",
    "GLOBAL_POSITION_INT",
    "VFR_HUD",
];

/// The latest of a ground link's messages, each with its boot time, µs.
#[derive(Default)]
struct GroundLatest {
    armed: bool,
    attitude: Option<(u64, mavlink::dialects::common::ATTITUDE_DATA)>,
    position: Option<(u64, mavlink::dialects::common::GLOBAL_POSITION_INT_DATA)>,
    hud: Option<(u64, f32)>,
}

/// The samples of a ground-link `.tlog` (what a station records of the autopilot's
/// telemetry): each `SERVO_OUTPUT_RAW` (servos 1-4 as `Surfaces::to_pwm_us` maps them) with
/// the latest `ATTITUDE`, `GLOBAL_POSITION_INT` and `VFR_HUD` of the same control period,
/// armed as the autopilot's `HEARTBEAT` says; `None` when the log has no `SERVO_OUTPUT_RAW`
/// of the autopilot. The messages carry no accelerometer: the roll model's lateral force is
/// the sideslip's (`beta Va^2`, as the vehicle's own autotune takes it) and the sideslip
/// model is not fitted. An error when the messages come too seldom to resolve the fast
/// modes, naming those to ask for.
pub(super) fn ground_samples(path: &Path, bytes: &[u8]) -> anyhow::Result<Option<Vec<Timed>>> {
    use mavlink::dialects::common::MavModeFlag;
    let mut parser = FrameParser::new();
    let mut latest = GroundLatest::default();
    let mut out = Vec::new();
    // Each of `GROUND_MESSAGES`' boot times, µs: its own stamp, or (VFR_HUD has none) the
    // attitude's.
    let mut stamps: [Vec<u64>; 4] = Default::default();
    // A SERVO_OUTPUT_RAW makes it a ground-link log, stamped or not (one before any ATTITUDE
    // cannot be placed in time): such a log is refused for its missing messages, by name.
    let mut servo_seen = false;
    for (_, frame) in read_tlog(bytes) {
        parser.push(&frame, |f| {
            if (f.header.system_id, f.header.component_id) != (u32::from(SYSTEM_ID), COMPONENT_ID) {
                return;
            }
            match f.message {
                MavMessage::HEARTBEAT(h) => {
                    latest.armed = h
                        .base_mode
                        .contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED);
                }
                MavMessage::ATTITUDE(a) => {
                    let t = u64::from(a.time_boot_ms) * 1000;
                    stamps[0].push(t);
                    latest.attitude = Some((t, a));
                }
                MavMessage::GLOBAL_POSITION_INT(p) => {
                    let t = u64::from(p.time_boot_ms) * 1000;
                    stamps[2].push(t);
                    latest.position = Some((t, p));
                }
                MavMessage::VFR_HUD(h) => {
                    let t = latest.attitude.as_ref().map_or(0, |a| a.0);
                    stamps[3].push(t);
                    latest.hud = Some((t, h.airspeed));
                }
                MavMessage::SERVO_OUTPUT_RAW(s) => {
                    servo_seen = true;
                    // The 32-bit microseconds wrap every 71 min: unwrapped against the
                    // attitude's milliseconds of the same period.
                    let Some((t_att, a)) = latest.attitude.clone() else {
                        return;
                    };
                    let wrap = 1u64 << 32;
                    let base = t_att - t_att % wrap;
                    let t = [base.wrapping_sub(wrap), base, base + wrap]
                        .into_iter()
                        .map(|b| b.wrapping_add(u64::from(s.time_usec)))
                        .min_by_key(|t| t.abs_diff(t_att))
                        .unwrap_or(t_att);
                    stamps[1].push(t);
                    let fresh = |x: u64| t.abs_diff(x) as f64 * 1e-6 <= ULOG_INTERVAL_MAX_S;
                    let (Some((t_pos, p)), Some((t_hud, va))) =
                        (latest.position.clone(), latest.hud)
                    else {
                        return;
                    };
                    if !(fresh(t_att) && fresh(t_pos) && fresh(t_hud)) {
                        return;
                    }
                    let c = Surfaces::from_pwm_us([
                        s.servo1_raw,
                        s.servo2_raw,
                        s.servo3_raw,
                        s.servo4_raw,
                    ]);
                    let attitude =
                        Euler::new(f64::from(a.roll), f64::from(a.pitch), f64::from(a.yaw))
                            .to_quaternion();
                    let v_ned =
                        Vector3::new(f64::from(p.vx), f64::from(p.vy), f64::from(p.vz)) / 100.0;
                    out.push(Timed {
                        time_us: t,
                        alt_m: f64::from(p.alt) / 1000.0,
                        armed: latest.armed,
                        attitude,
                        v_ned,
                        sample: Sample {
                            p: a.rollspeed,
                            q: a.pitchspeed,
                            r: a.yawspeed,
                            phi: a.roll,
                            theta: a.pitch,
                            airspeed: va,
                            // No accelerometer on the ground link: see above.
                            accel_y: 0.0,
                            ..moving(&v_ned, &c)
                        },
                    });
                }
                _ => {}
            }
        });
    }
    if !servo_seen {
        return Ok(None);
    }
    let slow: Vec<String> = GROUND_MESSAGES
        .iter()
        .zip(&stamps)
        .filter_map(|(name, t)| match median_interval_s(t) {
            _ if t.is_empty() => Some(format!("{name} (absent)")),
            m if m > ULOG_INTERVAL_MAX_S => Some(format!("{name} (every {} ms)", sig(m * 1e3, 2))),
            _ => None,
        })
        .collect();
    if !slow.is_empty() {
        bail!(
            "{}: a ground link's log needs {} at 50 Hz to resolve the fast modes, and has {}: \
             ask for them before the flight (MAV_CMD_SET_MESSAGE_INTERVAL; `sim-host fly \
             --message-rate NAME=50`, QGroundControl's MAVLink Inspector)",
            path.display(),
            GROUND_MESSAGES.join(", "),
            slow.join(", ")
        );
    }
    Ok(Some(out))
}

/// The median interval between consecutive times (µs) that move forward, s; infinite with
/// none.
fn median_interval_s(times_us: &[u64]) -> f64 {
    let mut gaps: Vec<u64> = times_us
        .windows(2)
        .filter_map(|w| w[1].checked_sub(w[0]).filter(|g| *g > 0))
        .collect();
    gaps.sort_unstable();
    gaps.get(gaps.len() / 2)
        .map_or(f64::INFINITY, |g| *g as f64 * 1e-6)
}

/// Longest median interval between a flight log's surface samples that the fits take, s: the
/// control rate's 20 ms and some room (the default profile's 40 ms does not resolve a 60 ms
/// roll mode).
const ULOG_INTERVAL_MAX_S: f64 = 0.03;

/// The samples of the autopilot's flight log: each `actuator_outputs` sample with the latest
/// attitude, inertial sample, velocity and airspeed at or before it.
pub(super) fn ulog_samples(path: &Path, bytes: &[u8]) -> anyhow::Result<Vec<Timed>> {
    let log =
        crate::ulog_read::parse(bytes).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let topic = |name: &str| {
        log.dataset(name)
            .filter(|d| !d.is_empty())
            .with_context(|| format!("{}: no `{name}` in the flight log", path.display()))
    };
    let fields = |name: &str, keys: &[&str]| -> anyhow::Result<(Vec<u64>, Vec<Vec<f64>>)> {
        let d = topic(name)?;
        let columns = keys
            .iter()
            .map(|k| {
                d.field(k)
                    .with_context(|| format!("{}: no `{name}.{k}`", path.display()))
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        Ok((d.timestamps_us().to_vec(), columns))
    };
    let (t_out, out) = fields(
        "actuator_outputs",
        &["output[0]", "output[1]", "output[2]", "output[3]"],
    )?;
    let median_s = median_interval_s(&t_out);
    if median_s > ULOG_INTERVAL_MAX_S {
        bail!(
            "{}: surfaces logged every {} ms: too far apart to resolve the fast modes; fly with \
             SDLOG_PROFILE's system-identification bit (`SDLOG_PROFILE 9`) for 100 Hz",
            path.display(),
            sig(median_s * 1e3, 2)
        );
    }
    let att = fields("vehicle_attitude", &["q[0]", "q[1]", "q[2]", "q[3]"])?;
    let imu = fields(
        "sensor_combined",
        &[
            "gyro_rad[0]",
            "gyro_rad[1]",
            "gyro_rad[2]",
            "accelerometer_m_s2[1]",
        ],
    )?;
    let pos = fields("vehicle_local_position", &["vx", "vy", "vz", "z"])?;
    let air = fields("airspeed_validated", &["true_airspeed_m_s"])?;
    // The latest sample of a topic at or before `t`.
    let at = |(times, columns): &(Vec<u64>, Vec<Vec<f64>>), t: u64| -> Option<Vec<f64>> {
        let i = times.partition_point(|n| *n <= t).checked_sub(1)?;
        columns.iter().map(|c| c.get(i).copied()).collect()
    };
    let mut samples = Vec::new();
    for (k, &t) in t_out.iter().enumerate() {
        let controls: Option<Vec<f64>> = out.iter().map(|c| c.get(k).copied()).collect();
        let (Some(u), Some(q), Some(w), Some(v), Some(va)) =
            (controls, at(&att, t), at(&imu, t), at(&pos, t), at(&air, t))
        else {
            continue;
        };
        let Some(q) = UnitQuaternion::try_new(Quaternion::new(q[0], q[1], q[2], q[3]), 1e-3) else {
            continue;
        };
        let e = Euler::from_quaternion(&q);
        let v_ned = Vector3::new(v[0], v[1], v[2]);
        let c = Surfaces::from_px4_controls([u[0], u[1], u[2], u[3]].map(|x| x as f32));
        samples.push(Timed {
            time_us: t,
            alt_m: -v[3],
            // A flight log is written from arming (or from boot: the runway's samples are
            // then left out by their height).
            armed: true,
            attitude: q,
            v_ned,
            sample: Sample {
                p: w[0] as f32,
                q: w[1] as f32,
                r: w[2] as f32,
                phi: e.phi as f32,
                theta: e.theta as f32,
                airspeed: va[0] as f32,
                ay: w[3] as f32,
                accel_y: w[3] as f32,
                ..moving(&v_ned, &c)
            },
        });
    }
    Ok(samples)
}
