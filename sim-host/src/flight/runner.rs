//! The flight loop.

use super::config::{Fault, FlightConfig};
use super::onboard::Onboard;
use super::record::{AutopilotView, NavView, Sample};
use super::script::GroundStation;
use super::strikes::{propeller_hub_m, strike_points, survey};
use super::summary::{
    mission_summary, summarise, touchdown_summary, Ending, FlightFacts, FlightSummary,
};
use crate::aircraft::Aircraft;
use crate::analysis::trim::{trim_with, TrimTarget};
use crate::environment::wind::Wind;
use crate::link::lockstep::{LinkError, Lockstep};
use crate::link::tlog::TlogWriter;
use crate::link::transport::Transport;
use crate::plant::battery::Battery;
use crate::plant::inputs::{Controls, Environment};
use crate::plant::params::ModelParams;
use crate::plant::propulsion::motor_power_w;
use crate::plant::servo::ServoBank;
use crate::plant::{Plant, Touchdown};
use crate::sensors::models::{SensorSuite, Truth};
use common::link::simlink::{
    encode_battery_status, encode_distance_sensor, encode_hil_gps, encode_hil_sensor,
    encode_rc_channels,
};
use common::math::atmosphere::standard_atmosphere;
use common::math::geodetic::ned_offset;
use common::math::ned_to_body;
use common::math::STANDARD_GRAVITY;
use mavlink::dialects::common::{MavMessage, HIL_STATE_QUATERNION_DATA};
use nalgebra::Vector3;
use std::time::{Duration, Instant};

/// Why a flight stopped.
#[derive(Debug, thiserror::Error)]
pub enum FlightError {
    /// The autopilot never started answering.
    #[error(transparent)]
    Link(#[from] LinkError),
    /// The autopilot stopped answering, or its link failed, during the flight: the flight
    /// as flown up to then comes with the error, so that its log can be kept.
    #[error("{cause} (the flight ended at t = {:.2} s after {} frames)", partial.summary.sim_s, partial.summary.frames)]
    Interrupted {
        /// What happened.
        cause: LinkError,
        /// The flight up to the failure.
        partial: Box<FlightOutcome>,
    },
    /// The configuration cannot be flown.
    #[error("flight configuration: {0}")]
    Config(String),
}

impl FlightError {
    /// The flight flown before the failure, if any.
    pub fn partial(&self) -> Option<&FlightOutcome> {
        match self {
            FlightError::Interrupted { partial, .. } => Some(partial),
            _ => None,
        }
    }
}

/// The ground stations' turn: frames from the port beside the script (QGroundControl
/// watching) into the autopilot, then the script, which takes the autopilot's queue and
/// hands every frame on to that port too, so that both see every message they are owed
/// (with no script, the port takes the queue itself).
fn serve_stations<T: Transport, O: Onboard<T>>(
    t_s: f64,
    gcs: Option<&mut GroundStation>,
    bridge: Option<&mut firmware::sitl::GcsUdp>,
    link: &mut Lockstep<T>,
    onboard: &mut O,
) {
    match (gcs, bridge) {
        (Some(g), Some(b)) => {
            // A station that misbehaves must not stop the flight.
            onboard.with_app(link, |app| b.receive(app).ok());
            g.poll(t_s, link, onboard);
            for (dest, frame) in g.take_beside() {
                b.send(dest, &frame);
            }
        }
        (Some(g), None) => g.poll(t_s, link, onboard),
        (None, Some(b)) => {
            onboard.with_app(link, |app| b.service(app).ok());
        }
        (None, None) => {}
    }
}

/// Whether a link error is the autopilot closing its end.
fn closed(e: &LinkError) -> bool {
    matches!(e, LinkError::Io(io) if io.kind() == std::io::ErrorKind::UnexpectedEof)
}

/// A flown flight: the log and its summary.
#[derive(Clone, Debug)]
pub struct FlightOutcome {
    /// One sample per sensor frame.
    pub samples: Vec<Sample>,
    /// Figures of the flight.
    pub summary: FlightSummary,
}

fn validate(cfg: &FlightConfig, frame_s: f64) -> Result<(), FlightError> {
    let bad = |m: String| Err(FlightError::Config(m));
    // Infinite: until the link closes or Ctrl-C (`sim-host sim`).
    if cfg.duration_s.is_nan() || cfg.duration_s <= 0.0 {
        return bad(format!("duration {} s: must be positive", cfg.duration_s));
    }
    if !(cfg.speed.is_finite() && cfg.speed > 0.0) {
        return bad(format!("speed {}: must be a positive factor", cfg.speed));
    }
    if !(cfg.dt_s.is_finite() && cfg.dt_s > 0.0 && cfg.dt_s <= frame_s) {
        return bad(format!(
            "step {} s: must be positive and at most the sensor frame period {frame_s} s",
            cfg.dt_s
        ));
    }
    if cfg
        .wind_ned
        .iter()
        .any(|w| !w.is_finite() || w.abs() > 15.0)
    {
        return bad(format!(
            "wind {:?} m/s: each component must be finite and within +-15 m/s (the aircraft flies at 17 m/s)",
            cfg.wind_ned
        ));
    }
    Ok(())
}

/// Flies `cfg` with the autopilot at the other end of `link`, reached through `onboard`.
///
/// Waits for the autopilot's boot heartbeat first; fails with [`LinkError::Silent`] if it
/// does not answer a frame within `cfg.link_timeout`.
pub fn fly<T: Transport, O: Onboard<T>>(
    aircraft: &Aircraft,
    cfg: &FlightConfig,
    link: &mut Lockstep<T>,
    onboard: &mut O,
) -> Result<FlightOutcome, FlightError> {
    let params = ModelParams::new(aircraft);
    let home = params.home;
    let home_alt = params.home_alt_msl_m;
    if aircraft.sensors.rangefinder.is_none()
        && cfg
            .faults
            .iter()
            .any(|w| matches!(w.fault, Fault::Range(_)))
    {
        return Err(FlightError::Config(
            "a rangefinder fault needs a rangefinder: `--rangefinder`, or a [sensors.rangefinder] table in the aircraft file".into(),
        ));
    }
    let mut sensors = SensorSuite::new(aircraft.sensors.clone(), home, home_alt, cfg.seed);
    let frame_us = sensors.period_us();
    let frame_s = frame_us as f64 * 1e-6;
    validate(cfg, frame_s)?;
    let substeps = ((frame_s / cfg.dt_s).round() as usize).max(1);
    let dt = frame_s / substeps as f64;
    let mut bridge = match &cfg.ground_link {
        Some((bind, remote)) => Some(firmware::sitl::GcsUdp::open(bind, Some(remote)).map_err(
            |e| FlightError::Config(format!("ground-station port {bind} -> {remote}: {e}")),
        )?),
        None => None,
    };

    // Trimmed, level, 100 m above home (TrimTarget::level is at 100 m AGL), at the aircraft's
    // cruise airspeed (the 25e's 17 m/s): a hand launch starts there, and a take-off from the
    // runway holds the trim's surfaces until the autopilot takes over.
    let level = TrimTarget::cruise(aircraft);
    let trim = trim_with(&params, &level);
    if !trim.converged {
        return Err(FlightError::Config(format!(
            "level trim did not converge (residual {:.3e})",
            trim.residual_norm
        )));
    }
    let (mut plant, trim_controls) = match cfg.runway_heading {
        // On the wheels, engine off, surfaces at trim until the autopilot takes over.
        // Held where it stands until the take-off roll's run-up, as on a real runway.
        Some(hdg) => (
            {
                let mut p = Plant::at_rest_on_ground(aircraft, 0.0, 0.0, hdg);
                p.hold_until_throttle();
                p
            },
            Controls {
                throttle: 0.0,
                ..trim.controls
            },
        ),
        None => {
            // Trimmed in the air mass: the steady wind carries the aircraft, so the airspeed
            // is the trim's whatever the wind.
            let mut start = trim.state;
            start.vel_body += ned_to_body(&start.attitude, &Vector3::from(cfg.wind_ned));
            (Plant::from_params(params.clone(), start), trim.controls)
        }
    };
    let mut servos = ServoBank::new(&aircraft.actuators, &trim_controls);
    // Powered up with the avionics; the motor draws what the plant's throttle asks.
    let mut battery = Battery::new(&aircraft.battery);
    let mut wind = Wind::new(Vector3::from(cfg.wind_ned), cfg.turbulence, cfg.seed);
    let q0 = plant.attitude();
    let env0 = Environment {
        wind_ned: wind.step(0.0, plant.air_data().va, -plant.position_ned().z, &q0),
    };
    plant.set_inputs(&trim_controls, &env0);
    let mut env = env0;

    // The ground station tells the autopilot its GPS receiver's latency, as an operator
    // configures the airframe's receiver (the parameter's default is another receiver's).
    let mut script = cfg.script.clone();
    if !script.params.iter().any(|(n, _)| n == "EKF_GPS_DELAY") {
        script.params.insert(
            0,
            (
                "EKF_GPS_DELAY".into(),
                aircraft.sensors.gps.latency_s as f32,
            ),
        );
    }
    let mut gcs = match cfg.scripted_station {
        true => {
            let mut g = GroundStation::new(script, home_alt);
            if let Some(p) = &cfg.ground_tlog {
                let w = TlogWriter::create(p).map_err(|e| {
                    FlightError::Config(format!("cannot create `{}`: {e}", p.display()))
                })?;
                g = g.with_tlog(w);
            }
            if bridge.is_some() {
                g = g.with_stations_beside();
            }
            Some(g)
        }
        false => None,
    };
    link.wait_for_autopilot(cfg.link_timeout)?;

    // An endless flight (`sim-host sim` without --duration) saturates to u64::MAX frames.
    let frames = (cfg.duration_s / frame_s).round() as u64;
    let bar = progress_bar(cfg.progress, cfg.duration_s.is_finite().then_some(frames));
    let start = Instant::now();
    let mut samples = Vec::with_capacity(frames.min(1 << 20) as usize + 1);
    let mut armed_frames = 0u64;
    // The landing the autopilot flew: the plant's touchdown as it stood at the last armed
    // frame. Once disarmed the aircraft is the ground crew's (a light model left on the runway
    // in gusts lifts off at its three-point attitude; see `FlightSummary::lifted_after_disarm`).
    let mut armed_touchdown = None;
    let mut energy_j = 0.0;
    // The motor's energy when the mission started: a mission started in the air is measured
    // from there (`mission_window`).
    let mut energy_at_mission_j = None;
    let mut ended = Ending::Duration;
    let mut failure = None;
    for k in 0..frames {
        if cfg.stopped() {
            ended = Ending::Stopped;
            break;
        }
        let time_us = sensors.next_time_us();
        let t_s = time_us as f64 * 1e-6;
        let truth = Truth {
            pos_ned: plant.position_ned(),
            vel_ned: plant.velocity_ned(),
            attitude: plant.attitude(),
            omega_body: plant.body_rates(),
            specific_force_body: plant.specific_force_body(),
            airspeed_mps: plant.air_data().va,
        };
        sensors.faults = cfg.faults_at(t_s);
        let (frame, fix) = sensors.sample(&truth);
        let alt_amsl = home_alt - truth.pos_ned.z;
        let mut msgs = Vec::with_capacity(3);
        if let Some(f) = fix {
            msgs.push(MavMessage::HIL_GPS(encode_hil_gps(time_us, &f)));
        }
        let pack = battery.output();
        if let Some(b) = sensors.sample_battery(time_us, pack.voltage_v, pack.current_a) {
            msgs.push(MavMessage::BATTERY_STATUS(encode_battery_status(&b)));
        }
        if let (Some(r), Some((sigma, fov))) = (
            sensors.sample_range(time_us, &truth),
            sensors.range_noise_and_fov(),
        ) {
            msgs.push(MavMessage::DISTANCE_SENSOR(encode_distance_sensor(
                time_us, &r, sigma, fov,
            )));
        }
        if k % 2 == 0 {
            if let Some(r) = cfg.rc_sticks.iter().rev().find(|r| r.from_s <= t_s) {
                msgs.push(MavMessage::RC_CHANNELS(encode_rc_channels(
                    time_us, r.roll, r.pitch, r.throttle, r.yaw,
                )));
            }
        }
        if cfg.truth_frames {
            msgs.push(MavMessage::HIL_STATE_QUATERNION(truth_frame(
                time_us, &truth, &plant, alt_amsl,
            )));
        }
        msgs.push(MavMessage::HIL_SENSOR(encode_hil_sensor(
            &frame,
            alt_amsl as f32,
        )));

        serve_stations(t_s, gcs.as_mut(), bridge.as_mut(), link, onboard);
        if energy_at_mission_j.is_none()
            && gcs
                .as_ref()
                .is_some_and(|g| g.mission_started_s().is_some())
        {
            energy_at_mission_j = Some(energy_j);
        }
        let answer = match link.exchange(time_us, &msgs) {
            Ok(a) => a,
            Err(e) if cfg.until_link_closes && closed(&e) => {
                ended = Ending::LinkClosed;
                break;
            }
            Err(e) => {
                ended = Ending::LinkFailed;
                failure = Some(e);
                break;
            }
        };
        let landed = cfg.stop_when_landed
            && armed_frames > 0
            && !answer.armed
            && plant.on_ground()
            && plant.velocity_ned().norm() < 1.0;
        let command = if answer.armed {
            armed_frames += 1;
            energy_j += motor_power_w(
                &params,
                f64::from(answer.surfaces.throttle),
                plant.engine_speed(),
            ) * frame_s;
            Controls::from(answer.surfaces)
        } else {
            // The safety pilot holds the trim until the autopilot is armed.
            trim_controls
        };
        let (view, monitor) = onboard
            .with_app(link, |app| {
                let estimate = app.estimate();
                let monitor = app.vehicle().battery();
                (
                    AutopilotView {
                        est_ne: ned_offset::<f64>(home, estimate.position),
                        nav: NavView::of(
                            app.navigation(),
                            app.mode().needs_navigator(),
                            &estimate.pos_ned,
                        ),
                        estimate,
                        setpoints: app.setpoints(),
                        loops: app.vehicle().loop_commands(),
                        mode: app.mode(),
                    },
                    monitor.present.then_some(monitor.remaining),
                )
            })
            .unzip();
        samples.push(
            Sample::new(
                t_s,
                &truth,
                alt_amsl,
                &env.wind_ned,
                &Vector3::from(cfg.wind_ned),
                view.as_ref(),
                answer.armed,
                &answer.surfaces,
            )
            .with_battery(&battery, monitor.flatten()),
        );
        if landed {
            // The frame that disarmed is logged; the stations read what came with it.
            serve_stations(t_s, gcs.as_mut(), bridge.as_mut(), link, onboard);
            ended = Ending::Landed;
            break;
        }

        for _ in 0..substeps {
            let seen = plant.step_servos(&mut servos, &command, &env, dt);
            let shaft_w = motor_power_w(&params, seen.throttle, plant.engine_speed());
            battery.step(battery.electrical_power_w(shaft_w), dt);
        }
        if answer.armed {
            armed_touchdown = plant.touchdown().copied();
        }
        let q = plant.attitude();
        env.wind_ned = wind.step(frame_s, plant.air_data().va, -plant.position_ned().z, &q);

        if cfg.realtime {
            let due = Duration::from_secs_f64((k + 1) as f64 * frame_s / cfg.speed);
            if let Some(wait) = due.checked_sub(start.elapsed()) {
                std::thread::sleep(wait);
            }
        }
        if k % 100 == 0 {
            bar.set_position(k);
            bar.set_message(format!("{t_s:6.1} s"));
        }
    }
    bar.finish_and_clear();
    let wall_s = start.elapsed().as_secs_f64();
    if let (Some(g), Some(t)) = (gcs.as_mut(), samples.last().map(|s| s.t)) {
        g.finish(t, link, onboard);
    }
    if let Some(Err(e)) = gcs.as_mut().map(GroundStation::finish_tlog) {
        // The flight is flown and its other files are still to be written.
        eprintln!("warning: the ground link's .tlog is incomplete: {e}");
    }
    let health = onboard.with_app(link, |app| (app.sim_health(), app.sim_link_stats()));
    let mut summary = summarise(
        cfg,
        &samples,
        &FlightFacts {
            gcs: gcs.as_ref(),
            frames: samples.len() as u64,
            frame_s,
            armed_frames,
            wall_s,
            sim_rx: link.stats(),
            health,
            home_alt,
            ended,
        },
    );
    let land_point = cfg
        .script
        .mission
        .iter()
        .rev()
        .find(|i| i.command == mavlink::dialects::common::MavCmd::MAV_CMD_NAV_LAND)
        .map(|i| {
            ned_offset::<f64>(
                home,
                common::math::geodetic::GeoPoint {
                    lat_e7: i.x,
                    lon_e7: i.y,
                },
            )
        })
        .filter(|_| gcs.is_some());
    let (landing, lifted) =
        landing_and_lift(armed_frames, armed_touchdown.as_ref(), plant.touchdown());
    summary.touchdown = landing.map(|t| touchdown_summary(t, land_point));
    summary.lifted_after_disarm = lifted.map(|t| touchdown_summary(t, land_point));
    if let Some(g) = gcs.as_ref().filter(|_| !cfg.script.mission.is_empty()) {
        let reached: Vec<u16> = g.reached.iter().map(|r| r.1).collect();
        let from_s = mission_window(&samples, g.mission_started_s(), home_alt);
        let energy_before_j = energy_at_mission_j.filter(|_| from_s.is_finite());
        let mut m = mission_summary(
            &cfg.script.mission,
            land_point,
            &samples,
            from_s,
            &reached,
            landing,
            energy_j - energy_before_j.unwrap_or(0.0),
            frame_s,
        );
        // The aircraft's file places the CG (a campaign, which shifts it, judges its flights
        // with the propeller's hub moved too).
        let points = strike_points(aircraft, propeller_hub_m(aircraft, [0.0; 3]));
        m.judge(survey(&samples, &points, home_alt));
        summary.mission = Some(m);
    }
    let outcome = FlightOutcome { samples, summary };
    match failure {
        Some(cause) => Err(FlightError::Interrupted {
            cause,
            partial: Box::new(outcome),
        }),
        None => Ok(outcome),
    }
}

/// The progress bar: a bar towards `frames`, or a spinner for an endless flight.
fn progress_bar(show: bool, frames: Option<u64>) -> indicatif::ProgressBar {
    if !show {
        return indicatif::ProgressBar::hidden();
    }
    let (b, template) = match frames {
        Some(n) => (
            indicatif::ProgressBar::new(n),
            "{spinner} simulated {msg} [{bar:30}] {percent}% {elapsed_precise}",
        ),
        None => (
            indicatif::ProgressBar::new_spinner(),
            "{spinner} simulated {msg} {elapsed_precise}",
        ),
    };
    if let Ok(style) = indicatif::ProgressStyle::with_template(template) {
        b.set_style(style.progress_chars("=> "));
    }
    b
}

/// HIL_STATE_QUATERNION from the truth: logged and, with `SIM_USE_TRUTH`, flown on.
fn truth_frame(time_us: u64, t: &Truth, plant: &Plant, alt_amsl: f64) -> HIL_STATE_QUATERNION_DATA {
    let q = t.attitude.quaternion();
    let p = plant.geodetic();
    let cm = |v: f64| (v * 100.0).round().clamp(-32768.0, 32767.0) as i16;
    let mg = |v: f64| {
        (v / STANDARD_GRAVITY * 1000.0)
            .round()
            .clamp(-32768.0, 32767.0) as i16
    };
    let rho0 = standard_atmosphere(0.0).density;
    let rho = standard_atmosphere(alt_amsl).density;
    let eas = t.airspeed_mps * (rho / rho0).sqrt();
    let speed_cm = |v: f64| (v * 100.0).round().clamp(0.0, 65535.0) as u16;
    HIL_STATE_QUATERNION_DATA {
        time_usec: time_us,
        attitude_quaternion: [q.w as f32, q.i as f32, q.j as f32, q.k as f32],
        rollspeed: t.omega_body.x as f32,
        pitchspeed: t.omega_body.y as f32,
        yawspeed: t.omega_body.z as f32,
        lat: p.lat_e7,
        lon: p.lon_e7,
        alt: (alt_amsl * 1000.0).round() as i32,
        vx: cm(t.vel_ned.x),
        vy: cm(t.vel_ned.y),
        vz: cm(t.vel_ned.z),
        ind_airspeed: speed_cm(eas),
        true_airspeed: speed_cm(t.airspeed_mps),
        xacc: mg(t.specific_force_body.x),
        yacc: mg(t.specific_force_body.y),
        zacc: mg(t.specific_force_body.z),
    }
}

/// Height above home over which an aircraft counts as in the air when its mission starts, m.
const IN_THE_AIR_M: f64 = 5.0;

/// From when a mission's figures count, s: from its start (`started_s`, the station's
/// accepted `MAV_CMD_MISSION_START`) when the aircraft was already in the air then, after a
/// take-off, a hand launch or an autotune flown in another mode; else from the beginning
/// (`-inf`), the runway's take-off being the mission's own.
fn mission_window(samples: &[Sample], started_s: Option<f64>, home_alt: f64) -> f64 {
    started_s
        .and_then(|t| samples.iter().find(|s| s.t >= t))
        .filter(|s| s.alt - home_alt > IN_THE_AIR_M)
        .map_or(f64::NEG_INFINITY, |s| s.t)
}

/// The landing the autopilot flew and, apart from it, a touchdown after the wind lifted the
/// disarmed aircraft: from the plant's touchdown as it stood at the last armed frame
/// (`armed`) and at the end (`last`). A flight never armed has only the last.
fn landing_and_lift<'a>(
    armed_frames: u64,
    armed: Option<&'a Touchdown>,
    last: Option<&'a Touchdown>,
) -> (Option<&'a Touchdown>, Option<&'a Touchdown>) {
    if armed_frames == 0 {
        return (last, None);
    }
    // The same touchdown has only gained bounces since.
    let lifted = last.filter(|t| armed.is_none_or(|a| a.time_s != t.time_s));
    (armed, lifted)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn at(time_s: f64, bounces: u32) -> Touchdown {
        Touchdown {
            time_s,
            pos_ned: Vector3::zeros(),
            vel_ned: Vector3::new(12.0, 0.0, 0.5),
            point: 0,
            bounces,
        }
    }

    #[test]
    fn a_flight_never_armed_lands_where_it_last_touched_down() {
        let last = at(30.0, 0);
        assert_eq!(landing_and_lift(0, None, Some(&last)), (Some(&last), None));
    }

    #[test]
    fn bounces_after_the_disarm_leave_the_landing_as_it_was_flown() {
        let (armed, last) = (at(300.0, 2), at(300.0, 5));
        assert_eq!(
            landing_and_lift(1000, Some(&armed), Some(&last)),
            (Some(&armed), None)
        );
    }

    #[test]
    fn a_lift_by_the_wind_after_the_disarm_is_not_the_landing() {
        let (armed, last) = (at(300.0, 2), at(340.0, 0));
        assert_eq!(
            landing_and_lift(1000, Some(&armed), Some(&last)),
            (Some(&armed), Some(&last))
        );
        // Disarmed in the air (a failsafe's stop): whatever came after is not a landing
        // the autopilot flew.
        assert_eq!(
            landing_and_lift(1000, None, Some(&last)),
            (None, Some(&last))
        );
    }
}
