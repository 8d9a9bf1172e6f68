//! `sim-host log FILE` on the log of a flight flown here: its summary against the
//! simulator's truth and against docs/LOGGING.md's rates; the same log cut short at many
//! bytes, corrupted, and files that are no log at all.

mod support;

use sim_host::commands::log::{summarize, LogSummary};
use sim_host::flight::Sample;
use sim_host::ulog_read::{parse, read_file, Ulog};
use std::path::Path;
use std::process::{Command, Output};
use support::{flight, Flown};

const DEG: f64 = 180.0 / std::f64::consts::PI;

fn summary(flown: &Flown) -> (Ulog, LogSummary) {
    let log = read_file(&flown.log).expect("the log reads");
    let s = summarize("log_001.ulg", &log);
    (log, s)
}

/// The frames from arming on.
fn armed(flown: &Flown) -> Vec<&Sample> {
    flown.outcome.samples.iter().filter(|s| s.armed).collect()
}

fn sim_host(args: &[&str], file: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sim-host"))
        .arg("log")
        .arg(file)
        .args(args)
        .output()
        .expect("sim-host runs")
}

#[test]
fn the_summary_of_the_log_agrees_with_the_simulators_truth_of_the_armed_flight() {
    let flown = flight();
    let (_, s) = summary(flown);
    let truth = armed(flown);
    let (first, last) = (truth[0], truth[truth.len() - 1]);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!((s.dropouts, s.dropout_ms), (0, 0));

    // The log starts at arming and holds the armed flight to its last frame (its fastest
    // topics every 40 ms).
    let armed_at = flown.outcome.summary.armed_at_s.expect("armed");
    assert!(
        (s.start_s - armed_at).abs() < 0.011,
        "{} {armed_at}",
        s.start_s
    );
    let span = last.t - first.t;
    assert!(
        s.duration_s <= span + 0.011 && s.duration_s > span - 0.05,
        "log {} s, armed {span} s",
        s.duration_s
    );
    assert_eq!(s.sys_name.as_deref(), Some("fixed-wing autopilot"));

    // The vehicle's status texts of the armed flight are in the log, each one the station
    // received as a STATUSTEXT, within a control period or two of when it arrived there.
    let station = &flown.outcome.summary.texts;
    assert!(!s.texts.is_empty(), "no text logged");
    for t in &s.texts {
        let at = s.start_s + t.t_s;
        assert!(
            station
                .iter()
                .any(|(t_s, text)| *text == t.text && (t_s - at).abs() < 0.1),
            "{t:?} at {at:.2} s not among the station's {station:?}"
        );
    }

    // The modes, at the PX4 main mode the simulator saw every frame: the same sequence, each
    // change within the 0.5 s between two `vehicle_status` samples.
    let main = |name: &str| {
        common::vehicle::modes::MODES
            .iter()
            .find(|m| m.name == name)
            .unwrap_or_else(|| panic!("mode {name}"))
            .px4
            .0
    };
    let mut logged: Vec<(f64, u8)> = Vec::new();
    for m in &s.modes {
        if logged.last().is_none_or(|l| l.1 != main(&m.mode)) {
            logged.push((s.start_s + m.from_s, main(&m.mode)));
        }
    }
    let mut flown_modes: Vec<(f64, u8)> = Vec::new();
    for f in &truth {
        if flown_modes.last().is_none_or(|l| l.1 != f.mode) {
            flown_modes.push((f.t, f.mode));
        }
    }
    assert!(logged.len() >= 2, "{:?}", s.modes);
    assert_eq!(
        logged.iter().map(|m| m.1).collect::<Vec<_>>(),
        flown_modes.iter().map(|m| m.1).collect::<Vec<_>>(),
        "{:?} against {flown_modes:?}",
        s.modes
    );
    for (l, f) in logged.iter().zip(&flown_modes) {
        assert!(l.0 >= f.0 - 0.011 && l.0 < f.0 + 0.51, "{l:?} {f:?}");
    }
    let last_mode = s.modes.last().expect("a mode");
    assert!((last_mode.to_s - s.duration_s).abs() < 1e-9);

    // Attitude: the estimate's extremes and RMS within its documented error of the truth's
    // (0.5 deg RMS), the extremes within a turn's transient of it.
    let a = s.attitude.expect("attitude");
    let roll: Vec<f64> = truth.iter().map(|f| f.roll * DEG).collect();
    let pitch: Vec<f64> = truth.iter().map(|f| f.pitch * DEG).collect();
    let roll_max = roll.iter().fold(0.0f64, |m, r| m.max(r.abs()));
    assert!(roll_max > 20.0, "the flight turns: {roll_max}");
    assert!(
        (a.roll_max_abs_deg - roll_max).abs() < 2.0,
        "{a:?} {roll_max}"
    );
    assert!((a.roll_rms_deg - support::rms(&roll)).abs() < 0.5, "{a:?}");
    assert!(
        (a.pitch_rms_deg - support::rms(&pitch)).abs() < 0.5,
        "{a:?}"
    );
    let (pmin, pmax) = pitch
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    assert!((a.pitch_min_deg - pmin).abs() < 2.0, "{a:?} {pmin}");
    assert!((a.pitch_max_deg - pmax).abs() < 2.0, "{a:?} {pmax}");

    // Height above where it armed: the estimate within 1 m (0.07 m RMS documented).
    let h = s.height_m.expect("height");
    let heights: Vec<f64> = truth.iter().map(|f| f.alt - first.alt).collect();
    let (hmin, hmax) = heights
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(*x), hi.max(*x))
        });
    assert!(hmax > 30.0, "the flight climbs: {hmax}");
    assert!(
        (h.min - hmin).abs() < 1.0 && (h.max - hmax).abs() < 1.0,
        "{h:?} {hmin} {hmax}"
    );
    // Above sea level the estimate carries the error of the GPS fix home was set on.
    let amsl = s.altitude_amsl_m.expect("altitude");
    assert!((amsl.max - truth.iter().map(|f| f.alt).fold(f64::MIN, f64::max)).abs() < 3.0);

    // Airspeed: the extremes within 1 m/s, the mean within 0.3 m/s.
    let v = s.airspeed_mps.expect("airspeed");
    let va: Vec<f64> = truth.iter().map(|f| f.airspeed).collect();
    let vmax = va.iter().copied().fold(f64::MIN, f64::max);
    let vmean = va.iter().sum::<f64>() / va.len() as f64;
    assert!((v.max - vmax).abs() < 1.0, "{v:?} {vmax}");
    assert!((v.mean - vmean).abs() < 0.3, "{v:?} {vmean}");
    assert!(v.min < 2.0, "from a standstill on the runway: {v:?}");

    // Distance over the ground: the estimate at 10 Hz against the truth at 100 Hz, within 2 %.
    let d_truth: f64 = truth
        .windows(2)
        .map(|w| (w[1].north - w[0].north).hypot(w[1].east - w[0].east))
        .sum();
    let d = s.distance_m.expect("distance");
    assert!(d_truth > 1000.0, "{d_truth}");
    assert!(
        (d / d_truth - 1.0).abs() < 0.02,
        "{d} m against {d_truth} m"
    );

    // The battery: the charge the autopilot measured drawn against the simulated pack's.
    let b = s.battery.expect("battery");
    let drawn = last.bat_drawn_mah - first.bat_drawn_mah;
    assert!((b.used_mah / drawn - 1.0).abs() < 0.05, "{b:?} {drawn}");
    assert!(
        (b.voltage_min_v - truth.iter().map(|f| f.bat_voltage).fold(f64::MAX, f64::min)).abs()
            < 0.1
    );
    assert!(b.remaining_end_pct < b.remaining_start_pct);

    let store = common::params::ParamStore::new(common::vehicle::params::REGISTRY);
    assert_eq!(s.parameters, store.len());
    assert_eq!(s.parameter_changes, 0);
}

/// The rates of docs/LOGGING.md's topics table: `| \`topic\` | rate | bytes | what |`.
fn documented_rates() -> Vec<(String, f64)> {
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/LOGGING.md"))
            .expect("docs/LOGGING.md");
    let section = doc
        .split("## Topics and rates")
        .nth(1)
        .expect("the topics section");
    section
        .lines()
        .take_while(|l| !l.starts_with("## "))
        .filter_map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            let name = cells.get(1)?.strip_prefix('`')?.strip_suffix('`')?;
            Some((name.to_string(), cells.get(2)?.parse().ok()?))
        })
        .collect()
}

#[test]
fn every_topic_is_logged_at_the_rate_docs_logging_md_gives_it() {
    let flown = flight();
    let (_, s) = summary(flown);
    let mut documented = documented_rates();
    assert_eq!(documented.len(), 20, "{documented:?}");
    let mut logged: Vec<(String, f64)> = s
        .topics
        .iter()
        .map(|t| (t.name.clone(), t.rate_hz))
        .collect();
    documented.sort_by(|a, b| a.0.cmp(&b.0));
    logged.sort_by(|a, b| a.0.cmp(&b.0));
    assert_eq!(
        logged.iter().map(|t| &t.0).collect::<Vec<_>>(),
        documented.iter().map(|t| &t.0).collect::<Vec<_>>()
    );
    for ((name, rate), (_, doc)) in logged.iter().zip(&documented) {
        assert!(
            (rate / doc - 1.0).abs() < 0.02,
            "{name}: {rate} Hz, documented {doc}"
        );
    }
    // And no sample short: as many as the rate gives over the log, within one, less what
    // the log's opening holds back (its definitions go out over the first half second,
    // docs/LOGGING.md).
    for t in &s.topics {
        let (_, doc) = documented
            .iter()
            .find(|d| d.0 == t.name)
            .expect("documented");
        let expected = doc * s.duration_s;
        let opening = doc * 0.5;
        assert!(
            t.samples as f64 <= expected + 1.5 && t.samples as f64 >= expected - opening - 1.5,
            "{}: {} samples, {expected} expected",
            t.name,
            t.samples
        );
    }
}

#[test]
fn sim_host_log_prints_the_summary_and_draws_the_figures_a_simulated_flight_draws() {
    let flown = flight();
    let out = tempfile::tempdir().expect("tempdir");
    let r = sim_host(&["--out", out.path().to_str().expect("UTF-8")], &flown.log);
    let stdout = String::from_utf8_lossy(&r.stdout);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(
        r.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    for part in [
        "Flight log",
        "Modes",
        "Mission",
        "Battery",
        "Topics",
        "vehicle_attitude",
    ] {
        assert!(stdout.contains(part), "{part} in\n{stdout}");
    }
    for f in ["altitude", "course", "attitude", "battery", "ground_track"] {
        let png = std::fs::read(out.path().join(format!("{f}.png"))).expect(f);
        assert_eq!(&png[1..4], b"PNG", "{f}");
        assert!(stdout.contains(&format!("{f}.png")), "{stdout}");
    }

    let r = sim_host(
        &["--json", "--out", out.path().to_str().expect("UTF-8")],
        &flown.log,
    );
    assert!(r.status.success());
    let j: serde_json::Value = serde_json::from_slice(&r.stdout).expect("JSON");
    let (_, s) = summary(flown);
    assert_eq!(j["duration_s"].as_f64(), Some(s.duration_s));
    assert_eq!(j["topics"].as_array().map(Vec::len), Some(20));
    assert_eq!(j["modes"][1]["mode"], "Mission", "{}", j["modes"]);
}

/// Where each message of `bytes` starts (after the 16-byte header), and its type.
fn messages(bytes: &[u8]) -> Vec<(usize, u8)> {
    let mut at = 16;
    let mut out = Vec::new();
    while at + 3 <= bytes.len() {
        out.push((at, bytes[at + 2]));
        at += 3 + usize::from(u16::from_le_bytes([bytes[at], bytes[at + 1]]));
    }
    out
}

#[test]
fn a_log_cut_anywhere_reads_to_its_last_whole_message_or_fails_naming_where() {
    let flown = flight();
    let whole = std::fs::read(&flown.log).expect("the log");
    let full = parse(&whole).expect("the whole log");
    let starts = messages(&whole);
    let data: Vec<usize> = starts.iter().filter(|m| m.1 == b'D').map(|m| m.0).collect();
    let data_at = data[data.len() / 2];
    // Every byte of the header and the definitions, every few hundred bytes across the data,
    // and every byte of one data message.
    let data_from = data[0];
    let mut cuts: Vec<usize> = (0..=data_from).collect();
    cuts.extend((data_from..whole.len()).step_by(331));
    cuts.extend(data_at..data_at + 40);
    cuts.push(whole.len() - 1);
    for &cut in &cuts {
        match parse(&whole[..cut]) {
            Err(e) => {
                assert!(cut < 16, "cut at {cut}: {e}");
                assert_eq!(e.offset, cut, "{e}");
            }
            Ok(log) => {
                assert!(cut >= 16, "cut at {cut} reads");
                let end = starts
                    .iter()
                    .map(|m| m.0)
                    .chain([whole.len()])
                    .rfind(|&s| s <= cut)
                    .unwrap_or(16);
                assert_eq!(log.bytes_read, end, "cut at {cut}");
                match log.warnings.as_slice() {
                    [] => assert_eq!(end, cut, "cut at {cut}: a message's end"),
                    [w] => {
                        assert_eq!(w.offset, end, "cut at {cut}");
                        assert!(w.what.contains("the file ends"), "cut at {cut}: {w}");
                    }
                    more => panic!("cut at {cut}: {more:?}"),
                }
                for d in &log.datasets {
                    let f = full.dataset(&d.name).expect("in the whole log");
                    assert!(f.timestamps_us().starts_with(d.timestamps_us()));
                }
            }
        }
    }

    // The command reads a log cut inside a data message, and says where it ends.
    let dir = tempfile::tempdir().expect("tempdir");
    let cut = dir.path().join("cut.ulg");
    std::fs::write(&cut, &whole[..data_at + 11]).expect("written");
    let r = sim_host(&["--out", dir.path().to_str().expect("UTF-8")], &cut);
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "warning: {}: byte {data_at}: message of type 'D' claims",
            cut.display()
        )) && stderr.contains("only 8 left"),
        "{stderr}"
    );
    // A header cut short is an error naming the file and the byte.
    std::fs::write(&cut, &whole[..9]).expect("written");
    let e = read_file(&cut).expect_err("no header");
    assert_eq!(
        e.to_string(),
        format!(
            "{}: byte 9: the header is 16 bytes, the file ends after 9",
            cut.display()
        )
    );
}

#[test]
fn bytes_corrupted_inside_a_log_are_skipped_and_the_rest_still_reads() {
    let flown = flight();
    let whole = std::fs::read(&flown.log).expect("the log");
    let full = parse(&whole).expect("the whole log");
    let samples = |l: &Ulog| l.datasets.iter().map(|d| d.len()).sum::<usize>();
    // A fixed sequence of positions and values (a linear congruential generator).
    let mut x: u64 = 0x2545_F491_4F6C_DD1D;
    let mut next = || {
        x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        (x >> 33) as usize
    };
    // Anywhere, the definitions included: the reader answers (a flip in a subscription
    // costs that topic's data, in a format every topic nesting it).
    for _ in 0..200 {
        let mut bytes = whole.clone();
        let at = 16 + next() % (bytes.len() - 16);
        bytes[at] ^= (next() % 255 + 1) as u8;
        if let Err(e) = parse(&bytes) {
            // Only the flag bits can refuse a log, when a flip sets an incompatible flag.
            assert!(e.what.contains("incompatible flags"), "{e}");
        }
    }
    // Among the samples: what is lost is at most the second up to the next sync marker.
    let data_from = messages(&whole)
        .iter()
        .find(|m| m.1 == b'D')
        .map(|m| m.0)
        .expect("data");
    let mut warned = 0;
    for _ in 0..200 {
        let mut bytes = whole.clone();
        for _ in 0..3 {
            let at = data_from + next() % (bytes.len() - data_from);
            bytes[at] ^= (next() % 255 + 1) as u8;
        }
        let log = parse(&bytes).expect("the definitions are whole");
        warned += usize::from(!log.warnings.is_empty());
        assert!(
            samples(&log) * 100 >= samples(&full) * 95,
            "{} of {} samples: {:?}",
            samples(&log),
            samples(&full),
            log.warnings
        );
    }
    assert!(warned > 0, "some flips hit the messages' structure");
}

#[test]
fn a_file_that_is_no_log_fails_with_an_error_naming_the_file_and_why() {
    let dir = tempfile::tempdir().expect("tempdir");
    let whole = std::fs::read(&flight().log).expect("the log");
    let mut wrong_magic = whole.clone();
    wrong_magic[3] = b'X';
    let garbage: Vec<u8> = (0u32..5000)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    let cases: [(&str, Option<Vec<u8>>, &str); 5] = [
        ("empty.ulg", Some(Vec::new()), "byte 0: the file is empty"),
        (
            "wrong_magic.ulg",
            Some(wrong_magic),
            "byte 0: not a ULog file: it starts with 55 4C 6F 58 01 12 35",
        ),
        ("garbage.ulg", Some(garbage), "byte 0: not a ULog file"),
        ("missing.ulg", None, "cannot read"),
        ("", None, "cannot read"),
    ];
    for (name, bytes, why) in cases {
        let path = dir.path().join(name);
        if let Some(b) = &bytes {
            std::fs::write(&path, b).expect("written");
        }
        let r = sim_host(&["--out", dir.path().to_str().expect("UTF-8")], &path);
        let stderr = String::from_utf8_lossy(&r.stderr);
        // 1 is the command's failure; a panic would exit 101.
        assert_eq!(r.status.code(), Some(1), "{name}: {stderr}");
        assert!(
            stderr.starts_with(&format!("error: {}: ", path.display())) && stderr.contains(why),
            "{name}: {stderr}"
        );
    }
}
