//! Firmware in the loop: the firmware's application flies the plant over the simulator link,
//! commanded by the scripted ground station.

use common::link::framing::{encode_v2, FrameParser, Sender};
use firmware::app::App;
use mavlink::dialects::common::{MavMessage, HEARTBEAT_DATA, HIL_SENSOR_DATA};
use sim_host::aircraft::Aircraft;
use sim_host::commands::fly::{fly_report, FlyOptions, LinkKind};
use sim_host::environment::wind::Turbulence;
use sim_host::flight::script::PX4_POSCTL;
use sim_host::flight::{
    fly, Action, FlightConfig, FlightError, FlightOutcome, InprocOnboard, Onboard, Script,
    ScriptStep,
};
use sim_host::link::lockstep::{LinkError, Lockstep};
use sim_host::link::tlog::read_tlog;
use sim_host::link::transport::{Inproc, Transport};
use std::time::Duration;

fn aircraft() -> Aircraft {
    Aircraft::ultrastick25e().expect("built-in aircraft")
}

/// Hold, then two right turns and an altitude step: short enough for the debug profile.
fn short_script() -> Script {
    let s = |t: f64, action| ScriptStep {
        after_arm_s: t,
        action,
    };
    Script {
        steps: vec![
            s(0.0, Action::Mode(PX4_POSCTL)),
            s(3.0, Action::Turn(90.0)),
            s(18.0, Action::AltitudeAboveHome(110.0)),
        ],
        ..Script::thesis()
    }
}

fn accepted(o: &FlightOutcome) {
    for c in &o.summary.commands {
        if c.what != "arm" {
            assert_eq!(c.result, "MAV_RESULT_ACCEPTED", "{c:?}");
        }
    }
    assert_eq!(
        o.summary
            .commands
            .iter()
            .filter(|c| c.result == "MAV_RESULT_ACCEPTED")
            .count(),
        o.summary
            .commands
            .iter()
            .filter(|c| c.what != "arm")
            .count()
            + 1,
        "one accepted arming: {:?}",
        o.summary.commands
    );
}

#[test]
fn the_same_flight_is_bit_identical_over_inproc_tcp_udp_and_pty() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = FlightConfig {
        duration_s: 35.0,
        turbulence: Turbulence::Light,
        seed: 11,
        script: short_script(),
        ..FlightConfig::default()
    };
    let run = |link: LinkKind| {
        let out = dir.path().join(link.name());
        let opts = FlyOptions {
            link,
            bind: "127.0.0.1:0".into(),
            out: Some(out.clone()),
            plots: false,
            ..FlyOptions::default()
        };
        let r = fly_report(&aircraft(), &cfg, &opts).expect("flight");
        let tlog = std::fs::read(out.join("simlink.tlog")).expect("tlog");
        let csv = std::fs::read(out.join("flight.csv")).expect("csv");
        let ground = std::fs::read(out.join("flight.tlog")).expect("ground tlog");
        (r.outcome, tlog, csv, ground)
    };
    let (a, tlog_a, csv_a, ground_a) = run(LinkKind::Inproc);
    // The flight's .tlog is the ground link as the station saw it, both ways: the vehicle's
    // heartbeats and telemetry, the station's heartbeats, its arming command and the answer.
    let ground = read_tlog(&ground_a);
    let mut parser = FrameParser::new();
    let (mut vehicle_hb, mut station_hb, mut arm, mut ack, mut attitude) = (0, 0, 0, 0, 0);
    for (_, f) in &ground {
        parser.push(f, |fr| match &fr.message {
            MavMessage::HEARTBEAT(_) if fr.header.system_id == 1 => vehicle_hb += 1,
            MavMessage::HEARTBEAT(_) if fr.header.system_id == 255 => station_hb += 1,
            MavMessage::COMMAND_LONG(_) => arm += 1,
            MavMessage::COMMAND_ACK(_) => ack += 1,
            MavMessage::ATTITUDE(_) => attitude += 1,
            _ => {}
        });
    }
    assert_eq!(parser.stats().frames_ok as usize, ground.len());
    assert_eq!(parser.stats().crc_errors, 0);
    assert!(ground.windows(2).all(|w| w[0].0 <= w[1].0), "time order");
    let secs = a.summary.sim_s;
    eprintln!(
        "ground tlog: {} frames, {vehicle_hb} vehicle and {station_hb} station heartbeats, {arm} commands, {ack} acks, {attitude} ATTITUDE over {secs:.0} s",
        ground.len()
    );
    // Heartbeats at 1 Hz each way, ATTITUDE at its default rate (several a second).
    assert!(vehicle_hb as f64 >= secs - 2.0 && station_hb as f64 >= secs - 2.0);
    assert!(arm >= 1 && ack >= arm, "commands {arm}, acks {ack}");
    assert!(attitude as f64 > 2.0 * secs, "ATTITUDE {attitude}");
    // The flight did something worth comparing: armed, turned, ten frames a second logged.
    accepted(&a);
    assert!(a.summary.armed_frames > 1000, "{}", a.summary.armed_frames);
    let frames = read_tlog(&tlog_a);
    // Per frame: HIL_STATE_QUATERNION, HIL_SENSOR and the answer, plus 5 Hz GPS and the
    // autopilot's boot heartbeat.
    assert!(frames.len() > 3 * 3500, "{} tlog frames", frames.len());
    // Every record is a whole MAVLink 2 frame with a good checksum, time-stamped in order.
    let mut parser = FrameParser::new();
    let mut sensors = 0;
    for (_, f) in &frames {
        parser.push(f, |fr| {
            if matches!(fr.message, MavMessage::HIL_SENSOR(_)) {
                sensors += 1;
            }
        });
    }
    assert_eq!(parser.stats().frames_ok as usize, frames.len());
    assert_eq!(parser.stats().crc_errors, 0);
    assert_eq!(sensors, a.summary.frames);
    assert!(frames.windows(2).all(|w| w[0].0 <= w[1].0), "time order");
    for link in [LinkKind::Tcp, LinkKind::Udp, LinkKind::Pty] {
        let (b, tlog_b, csv_b, ground_b) = run(link);
        assert!(ground_a == ground_b, "{}: ground tlog differs", link.name());
        assert_eq!(tlog_a.len(), tlog_b.len(), "{}: tlog length", link.name());
        assert!(tlog_a == tlog_b, "{}: tlog bytes differ", link.name());
        assert!(csv_a == csv_b, "{}: CSV differs", link.name());
        // Debug text of f64 round-trips bit-exactly (and NaN, before a position fix, equals).
        assert!(
            format!("{:?}", a.samples) == format!("{:?}", b.samples),
            "{}: samples differ",
            link.name()
        );
    }
}

#[test]
fn the_scripted_flight_holds_its_setpoints() {
    // The thesis's script in calm air: +100 m climb, four 90 deg turns, +-10 m doublet.
    let cfg = FlightConfig::default();
    let o = fly_report(&aircraft(), &cfg, &FlyOptions::default())
        .expect("flight")
        .outcome;
    accepted(&o);
    let armed = o.summary.armed_at_s.expect("armed");
    // The estimator converges within a few seconds of GPS (docs/ESTIMATOR.md).
    assert!(armed < 15.0, "armed at {armed} s");
    let segs = &o.summary.segments;
    assert_eq!(segs.len(), 8, "climb, four turns, three altitude steps");
    for s in segs {
        // "A few" m and deg: 3 m of altitude, 3 deg of course.
        let limit = 3.0;
        assert!(
            s.final_error_max < limit,
            "{}: off by {:.2} over the last 5 s of the segment",
            s.what,
            s.final_error_max
        );
        assert!(
            s.metrics.rise_time_s.is_some(),
            "{}: never reached 90 %",
            s.what
        );
    }
    // Altitude held through each turn (after 15 s of the climb for the first segment).
    for s in segs.iter().filter(|s| s.signal == "course") {
        assert!(
            s.alt_hold_error_max_m < 3.0,
            "{}: altitude off by {:.2} m",
            s.what,
            s.alt_hold_error_max_m
        );
    }
    // Four right turns: the course ends where it began, and the track closes a rectangle.
    let course = |t: f64| {
        o.samples
            .iter()
            .find(|x| x.t >= t)
            .map(|x| x.course.to_degrees())
            .expect("sample")
    };
    let c0 = course(segs[1].t_s - 1.0);
    let c4 = course(segs[5].t_s - 1.0);
    let d = (c4 - c0 + 540.0).rem_euclid(360.0) - 180.0;
    assert!(d.abs() < 3.0, "course after four turns {c4:.1} vs {c0:.1}");
}

/// Level flight in Hold with two turns in light turbulence and a 3.6 m/s wind.
fn estimator_flight() -> FlightConfig {
    // Level flight in Hold with two turns; errors counted once the estimator says it
    // converged, against the truth the simulator logs.
    let s = |t: f64, action| ScriptStep {
        after_arm_s: t,
        action,
    };
    FlightConfig {
        duration_s: 120.0,
        turbulence: Turbulence::Light,
        wind_ned: [3.0, -2.0, 0.0],
        seed: 5,
        script: Script {
            steps: vec![
                s(0.0, Action::Mode(PX4_POSCTL)),
                s(40.0, Action::Turn(90.0)),
                s(70.0, Action::Turn(-90.0)),
            ],
            ..Script::thesis()
        },
        ..FlightConfig::default()
    }
}

/// The estimator's targets, once converged, on a flight in light turbulence and a steady
/// 3.6 m/s wind. Counted from 30 s after convergence: the launch transient (the autopilot
/// taking over a hand-launched aircraft) is flown out; docs/RESULTS-SITL.md gives both
/// windows. The wind is compared with the total wind at the aircraft (steady plus Dryden):
/// that is the air mass the wind triangle measures.
#[test]
fn the_estimator_meets_its_targets_in_light_turbulence() {
    let cfg = estimator_flight();
    let o = fly_report(&aircraft(), &cfg, &FlyOptions::default())
        .expect("flight")
        .outcome;
    accepted(&o);
    let all = o.summary.estimator.expect("converged");
    let e = o.summary.estimator_settled.expect("settled");
    eprintln!("from convergence: {all:#?}\nfrom 30 s after: {e:#?}");
    assert!(e.roll_rms_deg < 0.5, "roll RMS {:.3} deg", e.roll_rms_deg);
    assert!(
        e.pitch_rms_deg < 0.5,
        "pitch RMS {:.3} deg",
        e.pitch_rms_deg
    );
    assert!(
        e.heading_rms_deg < 2.0,
        "heading RMS {:.3} deg",
        e.heading_rms_deg
    );
    assert!(e.alt_rms_m < 1.0, "altitude RMS {:.3} m", e.alt_rms_m);
    assert!(
        e.airspeed_rms_mps < 0.5,
        "airspeed RMS {:.3} m/s",
        e.airspeed_rms_mps
    );
    assert!(
        e.wind_total_rms_mps < 1.0,
        "wind RMS {:.3} m/s",
        e.wind_total_rms_mps
    );
}

/// Chapter 4's turn figures, flown on the estimate and on the simulator's truth
/// (`SIM_USE_TRUTH`), same seed and turbulence: rise and settling times within 10 % of the
/// truth's; overshoot within 10 % of the truth's or one percentage point, whichever is
/// larger: a tenth of a 1-3 % overshoot is below what one turbulent flight resolves (one
/// point of a 90 deg turn is 0.9 deg, about three times the RMS course wander light
/// turbulence leaves in straight flight on the truth, 0.26 deg); the course error over the
/// last 5 s before the next command within 0.5 deg of the truth's. The settling times are
/// compared only where both overshoots are clear of the 2 % settling band by more than that
/// one point's tolerance: an overshoot on the band's edge (2.00 % against 1.90 % in one
/// flight) settles at its first entry into the band or only after the overshoot's return,
/// 0.6 s apart, for a difference the overshoot's own check allows.
#[test]
fn turns_flown_on_the_estimate_match_turns_flown_on_the_truth() {
    let cfg = estimator_flight();
    let fly = |use_truth| {
        fly_report(
            &aircraft(),
            &cfg,
            &FlyOptions {
                use_truth,
                ..FlyOptions::default()
            },
        )
        .expect("flight")
        .outcome
    };
    let (est, truth) = (fly(false), fly(true));
    accepted(&est);
    accepted(&truth);
    let turns = |o: &FlightOutcome| -> Vec<_> {
        o.summary
            .segments
            .iter()
            .filter(|s| s.signal == "course")
            .cloned()
            .collect()
    };
    let (a, b) = (turns(&est), turns(&truth));
    assert_eq!(a.len(), 2);
    assert_eq!(b.len(), 2);
    let within = |x: Option<f64>, y: Option<f64>, what: &str| {
        let (x, y) = (x.expect(what), y.expect(what));
        assert!(
            (x - y).abs() <= 0.1 * y,
            "{what}: estimate {x:.2} truth {y:.2}"
        );
    };
    for (e, t) in a.iter().zip(&b) {
        eprintln!("{}: est {:?} truth {:?}", e.what, e.metrics, t.metrics);
        within(e.metrics.rise_time_s, t.metrics.rise_time_s, "rise");
        let tol = (0.1 * t.metrics.overshoot_pct).max(1.0);
        let clear = |o: f64| (o - SETTLING_BAND_PCT).abs() > tol;
        if clear(e.metrics.overshoot_pct) && clear(t.metrics.overshoot_pct) {
            within(
                e.metrics.settling_time_s,
                t.metrics.settling_time_s,
                "settling",
            );
        }
        assert!(
            (e.metrics.overshoot_pct - t.metrics.overshoot_pct).abs() <= tol,
            "overshoot: estimate {:.2} truth {:.2}",
            e.metrics.overshoot_pct,
            t.metrics.overshoot_pct
        );
        assert!(
            (e.final_error_max - t.final_error_max).abs() < 0.5,
            "final error: estimate {:.2} truth {:.2}",
            e.final_error_max,
            t.final_error_max
        );
    }
}

/// The settling band of `analysis::metrics`, % of the step.
const SETTLING_BAND_PCT: f64 = 2.0;

/// Wraps the in-process pipe and spoils the simulator's bytes on the way to the autopilot.
struct Tamper {
    inner: Inproc,
    frame: u64,
    foreign: Sender,
    heartbeat: Vec<u8>,
    parser: FrameParser,
    garbage: bool,
    poison: bool,
}

impl Tamper {
    fn spoil(&mut self, bytes: &[u8]) -> Vec<u8> {
        self.frame += 1;
        let k = self.frame;
        // The real frames, re-encoded; every 19th HIL_SENSOR with a NaN gyro and absurd
        // acceleration and pressures.
        let poison = self.poison && k.is_multiple_of(19);
        let mut real: Vec<Vec<u8>> = Vec::new();
        self.parser.push(bytes, |f| {
            let mut m = f.message.clone();
            if poison {
                if let MavMessage::HIL_SENSOR(d) = &mut m {
                    d.xgyro = f32::NAN;
                    d.zacc = 1e12;
                    d.abs_pressure = -5.0;
                    d.diff_pressure = f32::INFINITY;
                }
            }
            real.push(encode_v2(f.header, &m).raw_bytes().to_vec());
        });
        let mut out = Vec::new();
        let hb = self.heartbeat.clone();
        // Every 7th frame: a heartbeat with a bad checksum.
        if self.garbage && k.is_multiple_of(7) {
            let mut bad = hb.clone();
            let n = bad.len();
            bad[n - 1] ^= 0x5A;
            out.extend_from_slice(&bad);
        }
        // Every 11th: a heartbeat cut after its header and 4 payload bytes (truncated).
        if self.garbage && k.is_multiple_of(11) {
            out.extend_from_slice(&hb[..14]);
        }
        // Every 13th: a frame of a message id no dialect knows (id 0xABCDE).
        if self.garbage && k.is_multiple_of(13) {
            let payload = [1u8, 2, 3, 4];
            let mut f = vec![0xFD, payload.len() as u8, 0, 0, (k % 256) as u8, 1, 51];
            f.extend_from_slice(&[0xDE, 0xBC, 0x0A]);
            f.extend_from_slice(&payload);
            f.extend_from_slice(&[0x12, 0x34]);
            out.extend_from_slice(&f);
        }
        // Every 17th: a well-formed HIL_SENSOR from another system (42), with absurd values.
        if self.garbage && k.is_multiple_of(17) {
            let d = HIL_SENSOR_DATA {
                time_usec: 1 << 40,
                xacc: 1e9,
                ..Default::default()
            };
            out.extend_from_slice(self.foreign.encode(&MavMessage::HIL_SENSOR(d)).raw_bytes());
        }
        for r in real {
            out.extend_from_slice(&r);
        }
        out
    }
}

/// A heartbeat of the simulator's whose bytes after the first hold no start marker, spoiled
/// or not: a parser that resynchronises after it finds the next real frame. (A corrupt frame
/// holding a false marker followed by an unknown message id can cost the next frame: on a
/// lock-step link that is a stall, reported as a silent autopilot, see below.)
fn clean_heartbeat() -> Vec<u8> {
    let hb = Sender::new(1, 51)
        .encode(&MavMessage::HEARTBEAT(HEARTBEAT_DATA::default()))
        .raw_bytes()
        .to_vec();
    let n = hb.len();
    assert!(
        !hb[1..].contains(&0xFD) && hb[n - 1] ^ 0x5A != 0xFD,
        "{hb:02x?}"
    );
    hb
}

impl Transport for Tamper {
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        let spoiled = self.spoil(bytes);
        self.inner.send(&spoiled)
    }
    fn recv(&mut self, buf: &mut [u8], t: Duration) -> std::io::Result<usize> {
        self.inner.recv(buf, t)
    }
    fn describe(&self) -> String {
        "tampered in-process pipe".into()
    }
}

struct TamperOnboard;
impl Onboard<Tamper> for TamperOnboard {
    fn with_app<R>(
        &mut self,
        link: &mut Lockstep<Tamper>,
        f: impl FnOnce(&mut App) -> R,
    ) -> Option<R> {
        Some(f(link.transport_mut().inner.app_mut()))
    }
}

fn tampered_flight(garbage: bool, poison: bool) -> (FlightOutcome, FlightOutcome, u64) {
    let cfg = FlightConfig {
        duration_s: 60.0,
        script: short_script(),
        ..FlightConfig::default()
    };
    let t = Tamper {
        inner: Inproc::new(App::new()),
        frame: 0,
        foreign: Sender::new(42, 1),
        heartbeat: clean_heartbeat(),
        parser: FrameParser::new(),
        garbage,
        poison,
    };
    let mut link = Lockstep::new(t, Duration::from_secs(2));
    let o = fly(&aircraft(), &cfg, &mut link, &mut TamperOnboard).expect("the flight goes on");
    let answered = link.answered();
    let mut clean_link = Lockstep::new(Inproc::new(App::new()), Duration::from_secs(2));
    let clean = fly(&aircraft(), &cfg, &mut clean_link, &mut InprocOnboard).expect("clean");
    (o, clean, answered)
}

/// Largest |altitude setpoint - altitude| over the last 10 s, m.
fn final_alt_error(o: &FlightOutcome) -> f64 {
    let end = o.samples.last().map_or(0.0, |s| s.t);
    o.samples
        .iter()
        .filter(|s| s.t >= end - 10.0)
        .map(|s| (s.alt - s.sp_alt).abs())
        .fold(0.0, f64::max)
}

#[test]
fn garbage_on_the_sim_link_is_counted_and_changes_nothing() {
    // Bad checksums, truncated frames, unknown message ids and frames from another system.
    let (o, clean, answered) = tampered_flight(true, false);
    let rx = o
        .summary
        .autopilot_rx
        .expect("the autopilot runs in this process");
    let frames = o.summary.frames as u32;
    assert!(rx.framing.crc_errors >= frames / 7 + frames / 11, "{rx:?}");
    assert!(rx.framing.unknown_ids >= frames / 13, "{rx:?}");
    assert!(rx.foreign_frames >= frames / 17, "{rx:?}");
    assert_eq!(answered, o.summary.frames, "every sensor frame answered");
    accepted(&o);
    // The autopilot saw exactly the frames of the clean flight: it flies it bit for bit.
    assert!(
        format!("{:?}", o.samples) == format!("{:?}", clean.samples),
        "the garbage changed the flight"
    );
    assert!(final_alt_error(&o) < 3.0, "{:.2} m", final_alt_error(&o));
}

#[test]
fn absurd_sensor_values_are_rejected_and_the_autopilot_keeps_flying() {
    // Every 19th sensor frame: NaN gyro, 1e12 m/s^2, negative static and infinite dynamic
    // pressure.
    let (o, clean, answered) = tampered_flight(false, true);
    let rx = o
        .summary
        .autopilot_rx
        .expect("the autopilot runs in this process");
    let frames = o.summary.frames as u32;
    assert_eq!(rx.rejected[0], frames / 19, "IMU groups rejected: {rx:?}");
    assert!(rx.rejected[2] >= 1 && rx.rejected[3] >= 1, "{rx:?}");
    assert_eq!(answered, o.summary.frames, "every sensor frame answered");
    accepted(&o);
    // Still flying under control. It flies worse than the clean flight: the autopilot drops
    // the rejected IMU sample's time from its attitude integration (the next sample is
    // integrated over one frame, not two), so 5 % of the rotation is lost, likely the cause; measured: 29 m
    // altitude error over the last 10 s against 1.6 m clean. A firmware issue, reported.
    let (bad, good) = (final_alt_error(&o), final_alt_error(&clean));
    eprintln!(
        "altitude error over the last 10 s: {bad:.2} m with absurd values, {good:.2} m without"
    );
    assert!(good < 3.0, "{good:.2} m");
    for s in &o.samples {
        assert!(
            s.roll.abs().to_degrees() < 80.0,
            "roll {:.1} at {:.1} s",
            s.roll.to_degrees(),
            s.t
        );
        assert!(
            (s.alt - 100.0).abs() < 60.0,
            "altitude {:.1} at {:.1} s",
            s.alt,
            s.t
        );
    }
}

/// Forwards frames until `stop_after`, then swallows everything: an autopilot that hangs.
struct Stops {
    inner: Inproc,
    sent: u64,
    stop_after: u64,
}

impl Transport for Stops {
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.sent += 1;
        if self.sent <= self.stop_after {
            self.inner.send(bytes)
        } else {
            Ok(())
        }
    }
    fn recv(&mut self, buf: &mut [u8], t: Duration) -> std::io::Result<usize> {
        let n = self.inner.recv(buf, t)?;
        if n == 0 {
            std::thread::sleep(t.min(Duration::from_millis(5)));
        }
        Ok(n)
    }
    fn describe(&self) -> String {
        "a pipe that stops".into()
    }
}

struct StopsOnboard;
impl Onboard<Stops> for StopsOnboard {
    fn with_app<R>(
        &mut self,
        link: &mut Lockstep<Stops>,
        f: impl FnOnce(&mut App) -> R,
    ) -> Option<R> {
        Some(f(link.transport_mut().inner.app_mut()))
    }
}

#[test]
fn a_link_that_stops_is_reported_as_a_silent_autopilot() {
    let cfg = FlightConfig {
        duration_s: 20.0,
        link_timeout: Duration::from_millis(300),
        ..FlightConfig::default()
    };
    let t = Stops {
        inner: Inproc::new(App::new()),
        sent: 0,
        stop_after: 500,
    };
    let mut link = Lockstep::new(t, cfg.link_timeout);
    let start = std::time::Instant::now();
    match fly(&aircraft(), &cfg, &mut link, &mut StopsOnboard) {
        Err(FlightError::Interrupted {
            cause: LinkError::Silent { frames, time_s, .. },
            partial,
        }) => {
            assert_eq!(frames, 500);
            assert!((time_s - 5.0).abs() < 1e-9, "{time_s}");
            // The flight up to the silence is kept: 500 frames answered and logged.
            assert_eq!(partial.samples.len(), 500);
        }
        other => panic!(
            "expected a silent autopilot, got {:?}",
            other.map(|o| o.summary.frames)
        ),
    }
    assert!(start.elapsed() < Duration::from_secs(10));
}

#[test]
fn the_inproc_onboard_reaches_the_flying_application() {
    // The ground station's view and the simulator's are the same application.
    let cfg = FlightConfig {
        duration_s: 12.0,
        script: short_script(),
        ..FlightConfig::default()
    };
    let mut link = Lockstep::new(Inproc::new(App::new()), Duration::from_secs(2));
    let o = fly(&aircraft(), &cfg, &mut link, &mut InprocOnboard).expect("flight");
    let app = link.transport().app();
    assert_eq!(app.armed(), o.samples.last().expect("sample").armed);
    assert_eq!(app.sim_health().sensor_frames as u64, o.summary.frames);
}

/// The simulator's radio flies Stabilized: RC_CHANNELS on the simulator link (PX4's channel
/// order, 1000-2000 us) are the sticks, and half right roll stick holds half the roll limit
/// (`LIM_ROLL_DEG` 45 deg: 22.5 deg) in the true aircraft, centred sticks wings level.
#[test]
fn the_radio_flies_stabilized_through_rc_channels() {
    use sim_host::flight::RcSticks;
    let sticks = |from_s, roll| RcSticks {
        from_s,
        roll,
        pitch: 0.0,
        throttle: 0.6,
        yaw: 0.0,
    };
    let cfg = FlightConfig {
        duration_s: 40.0,
        script: Script {
            steps: vec![ScriptStep {
                after_arm_s: 0.0,
                action: Action::Mode(7),
            }],
            ..Script::thesis()
        },
        rc_sticks: vec![sticks(0.0, 0.0), sticks(25.0, 0.5)],
        ..FlightConfig::default()
    };
    let o = fly_report(&aircraft(), &cfg, &FlyOptions::default())
        .expect("flight")
        .outcome;
    accepted(&o);
    let mean_roll_deg = |from: f64, to: f64| {
        let v: Vec<f64> = o
            .samples
            .iter()
            .filter(|s| s.t >= from && s.t < to)
            .map(|s| s.roll.to_degrees())
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let level = mean_roll_deg(18.0, 24.0);
    let banked = mean_roll_deg(32.0, 40.0);
    eprintln!("roll: sticks centred {level:.2} deg, half right {banked:.2} deg");
    assert!(level.abs() < 1.0, "wings level {level:.2} deg");
    assert!((banked - 22.5).abs() < 1.5, "half stick {banked:.2} deg");
    let armed_at = o.summary.armed_at_s.expect("armed");
    assert!(
        o.samples
            .iter()
            .filter(|s| s.t > armed_at + 1.0)
            .all(|s| s.mode == 7),
        "Stabilized throughout"
    );
}

#[test]
fn leaving_the_truth_out_of_the_frames_changes_no_answer_of_an_autopilot_flying_on_its_estimate() {
    // Over QEMU's UARTs the truth (HIL_STATE_QUATERNION) is left out unless the autopilot flies
    // on it; the flight must be the same without it.
    let dir = tempfile::tempdir().expect("tempdir");
    let fly_with = |truth_frames: bool, sub: &str| {
        let cfg = FlightConfig {
            duration_s: 60.0,
            truth_frames,
            ..sim_host::flight::missions::runway_mission(
                sim_host::flight::missions::default_mission(
                    sim_host::plant::ModelParams::new(&aircraft()).home,
                ),
            )
        };
        let opts = FlyOptions {
            out: Some(dir.path().join(sub)),
            plots: false,
            ..FlyOptions::default()
        };
        fly_report(&aircraft(), &cfg, &opts).expect("flight");
        let tlog = std::fs::read(dir.path().join(sub).join("simlink.tlog")).expect("tlog");
        sim_host::flight::compare::answers(&tlog)
    };
    let (with, without) = (fly_with(true, "with"), fly_with(false, "without"));
    let c = sim_host::flight::compare::compare_answers(&with, &without);
    assert_eq!(c.compared, 6000);
    assert!(c.identical(), "{c:?}");
}

/// A station on the port beside the script (QGroundControl watching `fly --realtime`) and the
/// script share the autopilot's one outgoing queue: each must still see every message it is
/// owed. Over the default mission both hear every MISSION_ITEM_REACHED (a broadcast).
#[test]
fn a_station_beside_the_script_and_the_script_both_hear_every_item_reached() {
    use sim_host::flight::missions::{default_mission, runway_mission};
    let station = std::net::UdpSocket::bind("127.0.0.1:0").expect("station socket");
    station
        .set_read_timeout(Some(Duration::from_millis(200)))
        .expect("timeout");
    let remote = station.local_addr().expect("address").to_string();
    let done = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let listening = done.clone();
    let heard = std::thread::spawn(move || {
        let (mut parser, mut reached, mut buf) = (FrameParser::new(), Vec::new(), [0u8; 2048]);
        while !listening.load(std::sync::atomic::Ordering::Relaxed) {
            if let Ok(n) = station.recv(&mut buf) {
                parser.push(&buf[..n], |f| {
                    if let MavMessage::MISSION_ITEM_REACHED(r) = &f.message {
                        reached.push(r.seq);
                    }
                });
            }
        }
        reached
    });
    let cfg = FlightConfig {
        ground_link: Some(("127.0.0.1:0".into(), remote)),
        ..runway_mission(default_mission(
            sim_host::plant::ModelParams::new(&aircraft()).home,
        ))
    };
    let r = fly_report(&aircraft(), &cfg, &FlyOptions::default()).expect("flight");
    // The last datagrams are on their way over loopback.
    std::thread::sleep(Duration::from_millis(500));
    done.store(true, std::sync::atomic::Ordering::Relaxed);
    let beside = heard.join().expect("station thread");
    let m = r.outcome.summary.mission.expect("mission flown");
    assert!(
        m.all_reached,
        "the script heard {:?} of {:?}",
        m.reached, m.nav_items
    );
    let mut beside_items = beside.clone();
    beside_items.dedup();
    assert_eq!(
        beside_items, m.reached,
        "the station beside heard {beside:?}"
    );
}
