//! Processor in the loop: the release MCU image (`thumbv7em-none-eabihf`) on QEMU's emulated
//! STM32F405 flies the plant, USART1 on the simulator link and USART2 on the ground link behind
//! the UDP bridge, commanded by the scripted ground station exactly as the host build is.
//!
//! Same code, same answers: the image and the host build run the same `f32` code of `common`,
//! and no instruction of either rounds differently (Rust contracts no multiply-add into an FMA
//! on either side). What differs is the code behind the elementary functions: the MCU image has
//! no std, so `atan2`, `exp`, `sqrt`... come from the `libm` crate, and its `sin`, `cos`,
//! `tan`, `asin`, `hypot` and `powf` from `common::math::elementary` (in `f32`, where `libm`'s
//! compute in software `f64`); the host build has std and `libm`'s, and the two round some
//! results differently in the last bit. Built with sim-host's `mcu-libm` feature, which sends
//! the host's calls to the same code, the host build answers bit for bit as the image (the
//! ignored test at the end; docs/PIL.md).

use sim_host::aircraft::Aircraft;
use sim_host::commands::compare::compare_with_host;
use sim_host::commands::fly::{fly_report, FlyOptions, LinkKind};
use sim_host::commands::flying::MCU_LOG;
use sim_host::flight::missions::{
    autotune_then_thesis, default_mission, runway_mission, AUTOTUNE_AT_S, AUTOTUNE_FOR_S,
};
use sim_host::flight::summary::Ending;
use sim_host::flight::{Action, FlightConfig};
use sim_host::link::qemu::{QemuConfig, BUILD_COMMAND};
use sim_host::plant::ModelParams;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use system_tests::{build_mcu_firmware, build_sim_host_with_mcu_libm, spawn_qemu, tool_available};

/// Simulated time of the flight CI flies: the take-off (item 0, done at about 28 s) and the
/// first two legs (items 1 and 2, reached at about 49 s and 71 s).
const FIRST_LEGS_S: f64 = 75.0;

/// Largest difference of any control (PX4-normalised: -1..1, throttle 0..1) between the MCU
/// image's answers and the shipped host build's over [`FIRST_LEGS_S`]: measured 4.4e-3 (roll,
/// 0.11 deg of aileron) with seed 1 (3.6e-3 with `libm`'s `f32` functions on the image), the
/// last-bit differences of the elementary functions carried by the closed loop. A tenth of a
/// degree of surface; the bound leaves a margin of about two.
const FIRST_LEGS_BOUND: f64 = 1e-2;

fn aircraft() -> Aircraft {
    Aircraft::ultrastick25e().expect("built-in aircraft")
}

/// The image and QEMU, or `None` (skipped) on a machine without QEMU (an error under CI).
fn mcu() -> Option<QemuConfig> {
    if !tool_available("qemu-system-arm") {
        return None;
    }
    Some(QemuConfig {
        elf: build_mcu_firmware(),
        ..QemuConfig::default()
    })
}

fn mission(duration_s: f64) -> FlightConfig {
    FlightConfig {
        duration_s,
        ..runway_mission(default_mission(ModelParams::new(&aircraft()).home))
    }
}

fn pil_options(qemu: QemuConfig, out: &Path) -> FlyOptions {
    FlyOptions {
        link: LinkKind::Qemu,
        qemu,
        out: Some(out.to_path_buf()),
        plots: false,
        ..FlyOptions::default()
    }
}

#[test]
fn the_mcu_image_takes_off_flies_the_first_legs_and_answers_as_the_host_build_to_a_hundredth() {
    let Some(qemu) = mcu() else { return };
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = mission(FIRST_LEGS_S);
    let opts = pil_options(qemu, dir.path());
    let pil = fly_report(&aircraft(), &cfg, &opts).expect("the PIL flight");
    let cmp = compare_with_host(&aircraft(), &cfg, &opts).expect("the host build's flight");
    let (s, host) = (&pil.outcome.summary, &cmp.host.summary);
    eprintln!(
        "PIL: {:.1} s simulated in {:.1} s ({:.2}x real time); host build: {:.0}x",
        s.sim_s, s.wall_s, s.real_time_factor, host.real_time_factor
    );

    // The scripted station flew the image as it flies the host build: parameters, upload,
    // arming refused until the estimator converged, then accepted at the same second.
    assert_eq!(s.upload_results(), ["MAV_MISSION_ACCEPTED"]);
    assert_eq!(s.armed_at_s, host.armed_at_s);
    assert!(s.armed_at_s.is_some_and(|t| t < 15.0), "{:?}", s.armed_at_s);
    let results = |x: &sim_host::flight::summary::FlightSummary| {
        x.commands
            .iter()
            .map(|c| (c.what.clone(), c.result.clone()))
            .collect::<Vec<_>>()
    };
    assert_eq!(results(s), results(host), "every command answered alike");
    // Take-off and the first two legs: items 0, 1 and 2 reached, at 60 m.
    let m = s.mission.as_ref().expect("a mission");
    assert_eq!(m.reached, [0, 1, 2], "items reached in {FIRST_LEGS_S} s");
    let last = pil.outcome.samples.last().expect("samples");
    assert!(last.armed && (last.alt - 60.0).abs() < 5.0, "{last:?}");
    assert_eq!(s.frames, (FIRST_LEGS_S * 100.0) as u64);
    assert_eq!(s.sim_rx.crc_errors, 0);

    // The image measured itself: one control period per 20 ms of the flight (each period
    // closes when the next begins), a stack peak within the 76 KiB stack region of memory.x.
    let b = pil.mcu.expect("the image's figures of itself");
    let periods = s.frames / 2;
    assert!(
        b.control_periods + 100 >= periods && b.control_periods <= periods,
        "{} control periods measured in {periods}",
        b.control_periods
    );
    assert!(
        b.stack_peak_bytes > 1024 && b.stack_peak_bytes < 76 * 1024,
        "{b:?}"
    );
    assert!(
        b.instr_per_control_period_mean > 0.0
            && b.instr_per_control_period_max >= b.instr_per_control_period_mean,
        "{b:?}"
    );
    eprintln!("MCU budget: {b:?}");

    // Same answers: bit for bit until the first frame whose computation meets an elementary
    // function the two libraries round apart (after arming: until then the answer is the
    // trim, whatever the estimator holds), then within the bound.
    let a = &cmp.answers;
    assert_eq!(a.compared, s.frames as usize);
    let armed_frame = pil
        .outcome
        .samples
        .iter()
        .position(|x| x.armed)
        .expect("armed");
    match a.first_difference {
        None => eprintln!("answers identical bit for bit over {} frames", a.compared),
        Some(d) => {
            eprintln!(
                "answers identical for {} frames; frame {} (t = {:.2} s) differs first, control {:?}: {:e} vs {:e} (glibc's and the libm crate's last bits); largest differences {:?}",
                a.identical_frames, d.frame, d.time_s, d.control, d.a, d.b, a.max_abs_diff
            );
            assert!(
                d.frame >= armed_frame,
                "{d:?} before arming at {armed_frame}"
            );
            assert!(d.control.is_some(), "times, modes and flags agree: {d:?}");
        }
    }
    for (c, diff) in a.max_abs_diff.iter().enumerate() {
        assert!(
            *diff < FIRST_LEGS_BOUND,
            "control {c} differs by {diff:e} (bound {FIRST_LEGS_BOUND:e})"
        );
    }
    // And so the two aircraft fly the same path, to the centimetre.
    let apart = pil
        .outcome
        .samples
        .iter()
        .zip(&cmp.host.samples)
        .map(|(p, h)| {
            (p.north - h.north)
                .hypot(p.east - h.east)
                .max((p.alt - h.alt).abs())
        })
        .fold(0.0, f64::max);
    assert!(apart < 0.05, "{apart} m apart");
}

#[test]
#[ignore = "about 5 min: docs/PIL.md gives its figures; `cargo test -p system-tests --test pil -- --ignored`"]
fn the_mcu_image_flies_the_whole_default_mission_from_the_runway_to_the_runway() {
    let Some(qemu) = mcu() else { return };
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = runway_mission(default_mission(ModelParams::new(&aircraft()).home));
    let r = fly_report(&aircraft(), &cfg, &pil_options(qemu, dir.path())).expect("flight");
    let s = &r.outcome.summary;
    eprintln!("{}", serde_json::to_string_pretty(s).unwrap_or_default());
    eprintln!("MCU budget over the flight: {:?}", r.mcu);
    let m = s.mission.as_ref().expect("a mission");
    assert!(
        m.all_reached,
        "reached {:?} of {:?}",
        m.reached, m.nav_items
    );
    let td = m.touchdown.expect("a touchdown");
    assert!(td.distance_m < 20.0 && td.sink_rate_mps < 1.5, "{td:?}");
    assert_eq!(s.ended, Ending::Landed);
    assert!(
        !r.outcome.samples.last().expect("samples").armed,
        "disarmed"
    );
}

/// The MCU image lands the default mission on its rangefinder (the simulated LIDAR-Lite v3 on
/// the simulator link's `DISTANCE_SENSOR`, `docs/RANGEFINDER.md`): every item reached, the
/// touchdown within 20 m of the point under 1.5 m/s, disarmed on the ground; the readings the
/// image took are in the flight log it wrote to its flash (`distance_sensor`, at the image's
/// 4 Hz cap, over the 2.5 minutes a log holds from the arming: at least 200 samples); and the
/// whole flight, landing included, within the image's budgets.
#[test]
#[ignore = "about 3 to 5 min: the whole default mission in QEMU; docs/PIL.md gives its figures; `cargo test -p system-tests --test pil -- --ignored`"]
fn the_mcu_image_lands_the_default_mission_on_its_rangefinder_within_its_budget() {
    let Some(mut qemu) = mcu() else { return };
    let dir = tempfile::tempdir().expect("tempdir");
    let storage = dir.path().join("storage.bin");
    qemu.storage = Some(storage.clone());
    let mut a = aircraft();
    a.sensors.rangefinder = Some(sim_host::sensors::RangefinderConfig::default());
    let cfg = runway_mission(default_mission(ModelParams::new(&a).home));
    let r = fly_report(&a, &cfg, &pil_options(qemu, dir.path())).expect("flight");
    let s = &r.outcome.summary;
    let m = s.mission.as_ref().expect("a mission");
    let td = m.touchdown.expect("a touchdown");
    let b = r.mcu.expect("the image's figures of itself");
    let logs = system_tests::flash_logs(&storage);
    let (_, bytes) = logs.last().expect("a flight log in flash");
    let ulog = sim_host::ulog_read::parse(bytes).expect("a ULog");
    let ranges = ulog.dataset("distance_sensor").map_or(0, |d| d.len());
    eprintln!("{td:?}, {ranges} distance_sensor samples, MCU budget over the flight: {b:?}");
    assert!(
        m.all_reached,
        "reached {:?} of {:?}",
        m.reached, m.nav_items
    );
    assert!(td.distance_m < 20.0 && td.sink_rate_mps < 1.5, "{td:?}");
    assert_eq!(s.ended, Ending::Landed);
    assert!(ranges >= 200, "{ranges} distance_sensor samples");
    assert!(b.flash_bytes <= 192 * 1024, "flash {b:?}");
    assert!(b.ram_bytes() <= 64 * 1024, "RAM {b:?}");
    assert!(b.instr_per_control_period_mean <= 100_000.0, "{b:?}");
    assert!(b.instr_per_control_period_max <= 150_000.0, "{b:?}");
}

#[test]
#[ignore = "builds sim-host a second time (mcu-libm) and flies 80 s in QEMU: docs/PIL.md"]
fn with_the_libm_crate_on_both_sides_the_host_build_answers_bit_for_bit_as_the_mcu_image() {
    let Some(qemu) = mcu() else { return };
    let sim_host = build_sim_host_with_mcu_libm();
    let dir = tempfile::tempdir().expect("tempdir");
    let out = std::process::Command::new(sim_host)
        .args([
            "fly",
            "--mission",
            "default",
            "--link",
            "qemu",
            "--compare-host",
        ])
        .args(["--duration", "80", "--json", "--elf"])
        .arg(&qemu.elf)
        .arg("--out")
        .arg(dir.path())
        .output()
        .expect("sim-host runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let a = &json["answers"];
    assert_eq!(a["compared"], 8000, "{a}");
    assert!(a["first_difference"].is_null(), "{a}");
}

/// A shell script standing in for QEMU.
fn fake_qemu(dir: &Path, body: &str) -> PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let path = dir.join("qemu-system-arm");
    std::fs::write(&path, format!("#!/bin/sh\n{body}\n")).expect("script");
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    path
}

/// Flies 60 s of the default mission on `qemu`, expecting an error; returns it, the wall time
/// it took and the output directory.
fn failing_flight(
    qemu: QemuConfig,
    link_timeout: Duration,
) -> (String, Duration, tempfile::TempDir) {
    let dir = tempfile::tempdir().expect("tempdir");
    let cfg = FlightConfig {
        link_timeout,
        ..mission(60.0)
    };
    let start = Instant::now();
    let e = match fly_report(&aircraft(), &cfg, &pil_options(qemu, dir.path())) {
        Ok(r) => panic!("flew {} frames", r.outcome.summary.frames),
        Err(e) => format!("{e:#}"),
    };
    eprintln!("after {:.1} s: {e}", start.elapsed().as_secs_f64());
    (e, start.elapsed(), dir)
}

#[test]
fn a_missing_image_is_an_error_that_names_the_command_that_builds_it() {
    let qemu = QemuConfig {
        elf: PathBuf::from("/nonexistent/firmware"),
        ..QemuConfig::default()
    };
    let (e, _, _) = failing_flight(qemu, Duration::from_secs(5));
    assert!(
        e.contains(BUILD_COMMAND) && e.contains("/nonexistent/firmware"),
        "{e}"
    );
}

/// Flies on a stand-in for QEMU whose run does `body` (its `--version` answers as QEMU's does),
/// the image a placeholder file; returns the error and how long it took to come.
fn fake_qemu_flight(program: Option<&str>, body: &str) -> (String, Duration) {
    let dir = tempfile::tempdir().expect("tempdir");
    let elf = dir.path().join("firmware");
    std::fs::write(&elf, b"not run").expect("file");
    let program = match program {
        Some(p) => PathBuf::from(p),
        None => fake_qemu(
            dir.path(),
            &format!("[ \"$1\" = --version ] && exit 0\n{body}"),
        ),
    };
    let qemu = QemuConfig {
        elf,
        program,
        ..QemuConfig::default()
    };
    let (e, took, _) = failing_flight(qemu, Duration::from_secs(5));
    (e, took)
}

#[test]
fn a_missing_qemu_is_an_error_that_names_the_package_to_install() {
    let (e, _) = fake_qemu_flight(Some("/nonexistent/qemu-system-arm"), "");
    assert!(e.contains("apt-get install qemu-system-arm"), "{e}");
}

#[test]
fn a_qemu_that_dies_at_start_ends_the_flight_with_its_status_and_what_it_said() {
    let (e, took) = fake_qemu_flight(
        None,
        "echo 'qemu-system-arm: cannot load the image' >&2\nexit 3",
    );
    assert!(
        e.contains("exited with status 3") && e.contains("cannot load the image"),
        "{e}"
    );
    assert!(took < Duration::from_secs(3), "{took:?}");
}

#[test]
fn a_qemu_that_never_connects_ends_the_flight_within_its_connection_wait() {
    let (e, took) = fake_qemu_flight(None, "exec sleep 60");
    assert!(
        e.contains("USART1 (the simulator link) did not connect")
            && e.contains("is running but did not connect it within 5s"),
        "{e}"
    );
    // The connection wait (5 s), and the sleeping stand-in ended with its process group.
    assert!(took < Duration::from_secs(8), "{took:?}");
}

/// A QEMU that runs the image and after `secs` gets `signal` from `timeout(1)`.
fn qemu_signalled_after(dir: &Path, secs: u32, signal: &str) -> Option<QemuConfig> {
    let qemu = mcu()?;
    let program = fake_qemu(
        dir,
        &format!("exec timeout -s {signal} {secs} qemu-system-arm \"$@\""),
    );
    Some(QemuConfig { program, ..qemu })
}

/// The log of a failed flight: the CSV up to the failure and its summary.
fn kept_log(dir: &Path) -> (usize, serde_json::Value) {
    let csv = std::fs::read_to_string(dir.join("flight.csv")).expect("flight.csv kept");
    let json = std::fs::read_to_string(dir.join("summary.json")).expect("summary.json kept");
    assert!(dir.join("simlink.tlog").is_file() && dir.join(MCU_LOG).is_file());
    (
        csv.lines().count() - 1,
        serde_json::from_str(&json).expect("JSON"),
    )
}

#[test]
fn a_qemu_that_hangs_mid_flight_ends_it_within_the_link_timeout_and_the_log_is_kept() {
    let scripts = tempfile::tempdir().expect("tempdir");
    let Some(qemu) = qemu_signalled_after(scripts.path(), 4, "STOP") else {
        return;
    };
    let (e, took, dir) = failing_flight(qemu, Duration::from_secs(2));
    assert!(
        e.contains("the autopilot is silent") && e.contains("is still running"),
        "{e}"
    );
    // 4 s of running, 2 s of silence, and the time to write the log.
    assert!(took < Duration::from_secs(12), "{took:?}");
    let (rows, summary) = kept_log(dir.path());
    assert!(rows > 50, "{rows} rows");
    assert_eq!(summary["ended"], "link_failed");
    assert_eq!(summary["frames"], rows);
}

#[test]
fn a_qemu_that_dies_mid_flight_ends_it_at_once_naming_how_and_the_log_is_kept() {
    let scripts = tempfile::tempdir().expect("tempdir");
    let Some(qemu) = qemu_signalled_after(scripts.path(), 4, "KILL") else {
        return;
    };
    let (e, took, dir) = failing_flight(qemu, Duration::from_secs(5));
    assert!(
        e.contains("QEMU (pid") && e.contains("killed by signal 9"),
        "{e}"
    );
    // 4 s of running and the time to write the log: no wait for the 5 s link timeout.
    assert!(took < Duration::from_secs(8), "{took:?}");
    let (rows, summary) = kept_log(dir.path());
    assert!(rows > 50, "{rows} rows");
    assert_eq!(summary["ended"], "link_failed");
}

/// The budget of the MCU image (docs/PERFORMANCE.md, "MCU image budget"; the design's budget
/// since it took in autotune and the flight log): flash at most 192 KiB; statics, the stack's
/// measured peak and the log's buffers at most 64 KiB; per 20 ms control period at most
/// 100,000 instructions on average and 150,000 at most, over the runway, the station's
/// parameter and mission traffic, the take-off and the first legs (every period counted).
/// Measured 2026-12-06 (profile `mcu`, 75 s of flight) with the flight log written to the
/// storage file's log sectors: flash 193,916 B, statics 2,140 B + stack peak 50,140 B, 95,400
/// instructions per control period on average and 145,890 at most.
#[test]
fn the_mcu_image_stays_within_its_flash_ram_and_instruction_budget() {
    let Some(mut qemu) = mcu() else { return };
    let dir = tempfile::tempdir().expect("tempdir");
    // With its storage file, so the flight log is written to its flash sectors as on a board.
    let storage = dir.path().join("storage.bin");
    qemu.storage = Some(storage.clone());
    let pil = fly_report(
        &aircraft(),
        &mission(FIRST_LEGS_S),
        &pil_options(qemu, dir.path()),
    )
    .expect("the PIL flight");
    let b = pil.mcu.expect("the image's figures of itself");
    let logged: Vec<_> = system_tests::flash_logs(&storage)
        .into_iter()
        .map(|(l, _)| l)
        .collect();
    eprintln!("flight logs in the image's flash: {logged:?}");
    assert_eq!(logged.len(), 1, "one log of the flight in flash");
    assert!(logged[0].bytes > 100_000, "{logged:?}");
    eprintln!("MCU budget: {b:?}");
    assert!(b.flash_bytes <= 192 * 1024, "flash {b:?}");
    assert!(b.ram_bytes() <= 64 * 1024, "RAM {b:?}");
    assert!(b.instr_per_control_period_mean <= 100_000.0, "{b:?}");
    assert!(b.instr_per_control_period_max <= 150_000.0, "{b:?}");
}

/// The autotune flown by the image itself (`sim-host fly --link qemu --autotune`, the
/// hand-launched 25e in Hold): its excitation, its least-squares fits and the successive loop
/// closure's design run on board, spread over control periods, and every period since boot,
/// the autotune's included, stays within the budget: at most 100,000 instructions on average
/// and 150,000 in any period. The image identifies the 25e, meets every loop's margins and
/// applies the gains. (Measured 2026-12-08: 82,833 / 122,579, docs/PERFORMANCE.md's last
/// row; the gains' application, 118 k in one pass of work before it wrote whole stages by
/// position and re-read the gains alone, was the costliest period.) The scripted
/// station's reads of the autotune's forty parameters are left out: each is an exchange in
/// lock-step, the simulation held until the answer, so all forty fall in one control period
/// of the image (578 k instructions measured with them), where a station over a real link
/// reads them over real time.
#[test]
fn the_mcu_image_autotunes_itself_within_its_instruction_budget() {
    let Some(mut qemu) = mcu() else { return };
    let dir = tempfile::tempdir().expect("tempdir");
    // With its storage file, so the flight log is written to its flash sectors as on a board.
    qemu.storage = Some(dir.path().join("storage.bin"));
    let mut cfg = FlightConfig {
        duration_s: AUTOTUNE_AT_S + AUTOTUNE_FOR_S,
        ..autotune_then_thesis()
    };
    cfg.script
        .steps
        .retain(|s| !matches!(s.action, Action::ReadParams(_)));
    let pil =
        fly_report(&aircraft(), &cfg, &pil_options(qemu, dir.path())).expect("the PIL flight");
    let texts = &pil.outcome.summary.texts;
    for (t, text) in texts.iter().filter(|(_, t)| t.starts_with("Autotune")) {
        eprintln!("{t:6.1} s  {text}");
    }
    assert!(
        texts.iter().any(|(_, t)| t == "Autotune: gains applied"),
        "{texts:?}"
    );
    let b = pil.mcu.expect("the image's figures of itself");
    eprintln!("MCU budget over the autotune: {b:?}");
    assert!(b.instr_per_control_period_mean <= 100_000.0, "{b:?}");
    assert!(b.instr_per_control_period_max <= 150_000.0, "{b:?}");
    assert!(b.ram_bytes() <= 64 * 1024, "RAM {b:?}");
}

/// The profile by function (`sim-host fly --link qemu --profile`) counts the image's work from
/// QEMU's instruction trace; the image counts the same work with SysTick. Two counters that
/// share nothing but the image agree on the size of a control period, and the profile holds
/// the stages every period runs.
#[test]
fn a_profile_from_qemus_trace_counts_the_work_the_image_counts_with_its_own_clock() {
    let Some(qemu) = mcu() else { return };
    let dir = tempfile::tempdir().expect("tempdir");
    let window = sim_host::link::profile::ProfileWindow::parse("4:10").expect("window");
    let qemu = QemuConfig {
        profile: Some((window, dir.path().to_path_buf())),
        ..qemu
    };
    let r = fly_report(&aircraft(), &mission(6.0), &pil_options(qemu, dir.path()))
        .expect("the PIL flight");
    let (b, p) = (
        r.mcu.expect("the image's figures"),
        r.mcu_profile.expect("the profile"),
    );
    eprintln!("{}", p.markdown(15));
    assert_eq!(p.periods, 10);
    // On the runway the periods differ (the station's parameter and mission traffic comes
    // in bursts): the same order of magnitude, not the same number.
    let ratio = p.instr_per_period / b.instr_per_control_period_mean;
    assert!((0.3..3.0).contains(&ratio), "{ratio}: {b:?}");
    let share: f64 = p.functions.iter().map(|f| f.percent).sum();
    assert!((share - 100.0).abs() < 1e-6, "{share}");
    for stage in ["Ins::predict", "FrameParser"] {
        assert!(
            p.functions.iter().any(|f| f.function.contains(stage)),
            "{stage} missing from the profile"
        );
    }
    // The costliest pass of work is one of the window's passes: no larger than the window's
    // whole count, and its memory routines no more than the pass.
    let c = p.costliest_pass.expect("the costliest pass");
    let window = p.instr_per_period * f64::from(p.periods);
    assert!((1.0..=window).contains(&(c.instructions as f64)), "{c:?}");
    let memory: f64 = c.memory_callers.iter().map(|f| f.instr_per_period).sum();
    assert!(memory <= c.instructions as f64, "{memory} {c:?}");
}

/// A ground station's bursts (640 bytes each, more than the image's 512-byte receive ring)
/// written while the image works through sensor frames, its first ones included: the receive
/// interrupts take every byte that arrives during a tick into the ring and the transmit path
/// sends every answer, so every request is answered and no frame arrives corrupted on either
/// link. QEMU hands the USART one byte per pass of its own main loop, so under QEMU the ring
/// does not fill (the full-ring path, which masks the interrupt until the loop has made room,
/// is not reached here).
#[test]
fn ground_bursts_sent_while_the_image_is_busy_are_answered_in_full_with_no_byte_lost() {
    use mavlink::dialects::common::{MavMessage, PARAM_REQUEST_READ_DATA};
    use sim_host::link::lockstep::Lockstep;
    use sim_host::link::transport::TcpServer;
    use std::collections::BTreeSet;
    use std::io::{Read, Write};
    use std::sync::{Arc, Mutex};

    let Some(qemu) = mcu() else { return };
    let (_qemu, sim, gcs) = spawn_qemu(|s, g| qemu.command(s, g));
    let sim = TcpServer::accept(&sim, Some(Duration::from_secs(20)), || Ok(()))
        .expect("QEMU connects USART1");
    let (mut station, _) = gcs.accept().expect("QEMU connects USART2");
    station
        .set_read_timeout(Some(Duration::from_millis(50)))
        .unwrap();

    // What comes down the ground link: the parameter indexes answered, the SYS_STATUS
    // receive-error counts, frames that failed their CRC.
    #[derive(Default)]
    struct Heard {
        answered: BTreeSet<u16>,
        errors_comm: Vec<u16>,
        bad_frames: u32,
    }
    let heard = Arc::new(Mutex::new(Heard::default()));
    let done = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let reader = {
        let (heard, done) = (heard.clone(), done.clone());
        let mut rx = station.try_clone().expect("clone");
        std::thread::spawn(move || {
            let mut parser = common::link::framing::FrameParser::new();
            let mut buf = [0u8; 4096];
            while !done.load(std::sync::atomic::Ordering::Relaxed) {
                let Ok(n) = rx.read(&mut buf) else { continue };
                if n == 0 {
                    break;
                }
                let mut h = heard.lock().unwrap();
                parser.push(&buf[..n], |f| match f.message {
                    MavMessage::PARAM_VALUE(v) => {
                        h.answered.insert(v.param_index);
                    }
                    MavMessage::SYS_STATUS(s) => h.errors_comm.push(s.errors_comm),
                    _ => {}
                });
                h.bad_frames = parser.stats().crc_errors;
            }
        })
    };

    let mut link = Lockstep::new(sim, Duration::from_secs(10));
    link.wait_for_autopilot(Duration::from_secs(20))
        .expect("the MCU announces itself once its UART is up");
    let mut tx = common::link::framing::Sender::new(255, 190);
    let count = common::params::ParamStore::new(common::vehicle::params::REGISTRY).len() as u16;
    let per_burst = 40u16.min(count);
    let mut asked = BTreeSet::new();
    let mut next = 0u16;
    for k in 0..400u64 {
        // Bursts before the first frames and then every second of the image's clock.
        if k < 3 || k % 100 == 0 {
            let mut burst = Vec::new();
            for _ in 0..per_burst {
                let index = next % count;
                next += 1;
                asked.insert(index);
                let msg = MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
                    param_index: index as i16,
                    target_system: 1,
                    target_component: 1,
                    param_id: "".into(),
                });
                burst.extend_from_slice(tx.encode(&msg).raw_bytes());
            }
            assert!(burst.len() > 512, "{} bytes", burst.len());
            station.write_all(&burst).expect("ground UART");
        }
        let t = k * 10_000;
        let frame = common::link::simlink::SensorFrame {
            time_us: t,
            imu: Some(common::sensors::ImuSample {
                accel: nalgebra::Vector3::new(0.0, 0.0, -9.8),
                gyro: nalgebra::Vector3::zeros(),
            }),
            ..Default::default()
        };
        let msg = MavMessage::HIL_SENSOR(common::link::simlink::encode_hil_sensor(&frame, 0.0));
        let answer = link
            .exchange(t, &[msg])
            .expect("the MCU answers every frame");
        assert_eq!(answer.time_us, t);
    }
    std::thread::sleep(Duration::from_millis(500));
    done.store(true, std::sync::atomic::Ordering::Relaxed);
    let _ = reader.join();
    let h = heard.lock().unwrap();
    let missing: Vec<_> = asked.difference(&h.answered).collect();
    assert!(missing.is_empty(), "unanswered: {missing:?}");
    assert_eq!(h.bad_frames, 0, "frames from the image with a bad CRC");
    assert!(
        h.errors_comm.len() >= 2 && h.errors_comm.iter().all(|&e| e == 0),
        "SYS_STATUS errors_comm: {:?}",
        h.errors_comm
    );
    assert_eq!(link.stats().crc_errors, 0, "simulator link");
}
