//! Monte Carlo campaigns: the campaign file's bad input is refused with file, key and value;
//! each flight's draws follow from the seed and its index alone; shards partition a campaign
//! and merge into the unsharded campaign's files byte for byte; a flight flown again by its
//! index gives its record.

use sim_host::aircraft::Aircraft;
use sim_host::campaign::output::{merge, read_campaign, write_campaign, RESULT_FILES};
use sim_host::campaign::spec::DEFAULT_CAMPAIGN_TOML;
use sim_host::campaign::{Campaign, CampaignSpec, MissionChoice, Shard, SpecError};
use std::path::Path;

fn campaign(runs: u64, seed: u64, mission: MissionChoice) -> Campaign {
    Campaign {
        seed,
        runs,
        spec: CampaignSpec::default(),
        spec_file: None,
        mission,
        aircraft: Aircraft::ultrastick25e().unwrap(),
        aircraft_file: None,
    }
}

fn refused(text: &str) -> String {
    let e = CampaignSpec::from_toml_str(text, Path::new("runs/wind.toml")).unwrap_err();
    assert!(matches!(e, SpecError::Value { .. }), "{e}");
    e.to_string()
}

#[test]
fn the_built_in_campaign_file_reads_as_the_default_campaign() {
    let spec = CampaignSpec::from_toml_str(DEFAULT_CAMPAIGN_TOML, Path::new("x")).unwrap();
    assert_eq!(spec, CampaignSpec::default());
    // A partial file keeps the defaults of every key it leaves out.
    let spec = CampaignSpec::from_toml_str("[wind]\nspeed_mps = [2, 4]\n", Path::new("x")).unwrap();
    assert_eq!(spec.wind.speed_mps, [2.0, 4.0]);
    assert_eq!(spec.aero, CampaignSpec::default().aero);
}

#[test]
fn an_unknown_key_is_refused_with_the_file_the_key_and_the_value() {
    let msg = refused("[wind]\nspeed_mps = [0, 8]\ngusts_kt = 12\n");
    assert!(
        msg.contains("runs/wind.toml") && msg.contains("`wind.gusts_kt`") && msg.contains("12"),
        "{msg}"
    );
    assert!(
        msg.contains("unknown key") && msg.contains("speed_mps"),
        "{msg}"
    );
    let msg = refused("[weather]\nrain = true\n");
    assert!(msg.contains("`weather`"), "{msg}");
}

#[test]
fn a_negative_spread_is_refused_with_the_file_the_key_and_the_value() {
    let msg = refused("[aero]\ncoefficient_spread = -0.2\n");
    assert!(
        msg.contains("runs/wind.toml")
            && msg.contains("`aero.coefficient_spread`")
            && msg.contains("-0.2")
            && msg.contains("negative"),
        "{msg}"
    );
    let msg = refused("[mass]\ncg_shift_m = [0.01, -0.002, 0.0]\n");
    assert!(
        msg.contains("`mass.cg_shift_m[1]`") && msg.contains("-0.002"),
        "{msg}"
    );
}

#[test]
fn an_impossible_range_is_refused_with_the_file_the_key_and_the_value() {
    let msg = refused("[wind]\nspeed_mps = [8, 2]\n");
    assert!(
        msg.contains("`wind.speed_mps`") && msg.contains("[8, 2]"),
        "{msg}"
    );
    // More wind than the simulator flies in.
    let msg = refused("[wind]\nspeed_mps = [0, 30]\n");
    assert!(
        msg.contains("`wind.speed_mps`") && msg.contains("0..15"),
        "{msg}"
    );
    let msg = refused("[wind]\nturbulence = [\"light\", \"gale\"]\n");
    assert!(
        msg.contains("`wind.turbulence[1]`") && msg.contains("gale"),
        "{msg}"
    );
    // A spread that would flip a coefficient's sign.
    let msg = refused("[aero]\ncoefficient_spread = 1.5\n");
    assert!(msg.contains("1.5") && msg.contains("at most"), "{msg}");
    let msg = refused("[sensors]\ngps_latency_s = \"long\"\n");
    assert!(
        msg.contains("`sensors.gps_latency_s`") && msg.contains("long"),
        "{msg}"
    );
}

#[test]
fn a_flights_draws_follow_from_the_seed_and_its_index_alone() {
    let small = campaign(10, 7, MissionChoice::Default);
    let large = campaign(100_000, 7, MissionChoice::Default);
    let (a, b) = (small.plan(5), large.plan(5));
    assert_eq!(a.draws, b.draws);
    assert_eq!(a.flight_seed, b.flight_seed);
    assert_eq!(a.aircraft, b.aircraft);
    assert_ne!(small.plan(6).draws, a.draws);
    assert_ne!(
        campaign(10, 8, MissionChoice::Default).plan(5).draws,
        a.draws
    );
    // Taking a spread away leaves every other quantity's draw as it was.
    let mut calm_aero = campaign(10, 7, MissionChoice::Default);
    calm_aero.spec.aero.coefficient_spread = 0.0;
    let c = calm_aero.plan(5);
    for ((n, x), (m, y)) in a.draws.0.iter().zip(&c.draws.0) {
        assert_eq!(n, m);
        if n.starts_with("aero.") {
            assert_eq!(*y, 1.0, "{n}");
        } else {
            assert_eq!(x, y, "{n}");
        }
    }
}

#[test]
fn every_dispersed_aircraft_of_a_thousand_flights_is_a_valid_aircraft_within_its_spreads() {
    let c = campaign(1000, 1, MissionChoice::Generated);
    let nominal = &c.aircraft;
    for i in 0..1000 {
        let p = c.plan(i);
        p.aircraft.validate(Path::new("dispersed")).unwrap();
        let k = p.aircraft.mass.mass_kg / nominal.mass.mass_kg;
        assert!((0.9..=1.1).contains(&k), "flight {i}: mass factor {k}");
        let v = p.draws.get("wind.speed_mps").unwrap();
        assert!((0.0..=8.0).contains(&v), "flight {i}: wind {v}");
        // Into the wind: the landing never has a tailwind.
        let hw = p.draws.get("derived.headwind_mps").unwrap();
        assert!(hw >= -1e-9, "flight {i}: headwind {hw}");
        assert!(p
            .config
            .script
            .params
            .iter()
            .all(|(n, _)| n == "EKF_GPS_DELAY"));
    }
}

#[test]
fn a_generated_mission_takes_off_and_lands_along_its_runway() {
    let c = campaign(50, 3, MissionChoice::Generated);
    for i in 0..50 {
        let p = c.plan(i);
        let hdg = p.config.runway_heading.unwrap();
        let l = p.landing.unwrap();
        let d = (l.direction_rad - hdg).sin().abs() + (1.0 - (l.direction_rad - hdg).cos());
        assert!(
            d < 1e-3,
            "flight {i}: lands at {} on a runway of {hdg}",
            l.direction_rad
        );
        assert!(
            l.point_ne.0.hypot(l.point_ne.1) < 0.05,
            "flight {i}: {:?}",
            l.point_ne
        );
        let items = &p.config.script.mission;
        assert_eq!(
            items[0].command,
            mavlink::dialects::common::MavCmd::MAV_CMD_NAV_TAKEOFF
        );
        assert!(items.len() >= 10);
        assert!(p.draws.get("mission.length_m").is_some());
    }
    // The default mission records no generated numbers.
    assert!(campaign(5, 3, MissionChoice::Default)
        .plan(0)
        .draws
        .get("mission.length_m")
        .is_none());
}

#[test]
fn shards_partition_a_campaign_into_contiguous_runs_of_flights() {
    for runs in [1u64, 7, 10, 1000] {
        for count in 1..=6u64 {
            let mut all = Vec::new();
            for index in 0..count {
                all.extend(Shard { index, count }.indices(runs));
            }
            assert_eq!(all, (0..runs).collect::<Vec<_>>(), "{runs} in {count}");
        }
    }
    assert!(Shard::parse("3/3").is_err());
    assert!(Shard::parse("1/0").is_err());
    assert_eq!(Shard::parse("2/5").unwrap(), Shard { index: 2, count: 5 });
}

/// Three flights, whole and in two uneven shards (1 + 2): the merge writes the same bytes, and
/// a flight flown again by its index gives the same record.
#[test]
fn merged_shards_equal_the_unsharded_campaign_byte_for_byte() {
    let c = campaign(3, 11, MissionChoice::Default);
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole");
    let records = c.run(Shard::WHOLE, 2, false).unwrap();
    write_campaign(&whole, &c.meta(Shard::WHOLE), &records).unwrap();
    let mut shards = Vec::new();
    for index in 0..2 {
        let s = Shard { index, count: 2 };
        let d = dir.path().join(format!("shard{index}"));
        write_campaign(&d, &c.meta(s), &c.run(s, 1, false).unwrap()).unwrap();
        shards.push(d);
    }
    let merged = dir.path().join("merged");
    merge(&shards, &merged).unwrap();
    for f in RESULT_FILES {
        let (a, b) = (
            std::fs::read(whole.join(f)).unwrap(),
            std::fs::read(merged.join(f)).unwrap(),
        );
        assert!(
            a == b,
            "{f} differs between the unsharded and the merged campaign"
        );
    }
    let (_, back) = read_campaign(&whole).unwrap();
    let (again, _) = c.fly(1);
    assert_eq!(
        serde_json::to_string(&again).unwrap(),
        serde_json::to_string(&back[1]).unwrap()
    );
}

#[test]
fn merge_refuses_a_shard_of_another_campaign_a_missing_one_and_one_given_twice() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, c: &Campaign, s: Shard| {
        let d = dir.path().join(name);
        // Identity only: the shard's flights are checked after its identity.
        write_campaign(&d, &c.meta(s), &[]).unwrap();
        d
    };
    let a = campaign(0, 1, MissionChoice::Default);
    let b = campaign(0, 2, MissionChoice::Default);
    let s0 = write("a0", &a, Shard { index: 0, count: 2 });
    let other = write("b1", &b, Shard { index: 1, count: 2 });
    let out = dir.path().join("out");
    let msg = merge(&[s0.clone(), other.clone()], &out)
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("another campaign") && msg.contains("`seed`"),
        "{msg}"
    );
    let msg = merge(std::slice::from_ref(&s0), &out)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("1/2") && msg.contains("missing"), "{msg}");
    let msg = merge(&[s0.clone(), s0.clone()], &out)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("given twice"), "{msg}");
    let mut spread = campaign(0, 1, MissionChoice::Default);
    spread.spec.wind.speed_mps = [0.0, 5.0];
    let s1 = write("c1", &spread, Shard { index: 1, count: 2 });
    let msg = merge(&[s0, s1], &out).unwrap_err().to_string();
    assert!(msg.contains("campaign.wind.speed_mps"), "{msg}");
}

#[test]
fn the_command_line_prints_the_campaign_in_force_and_refuses_a_bad_file_before_flying() {
    let bin = env!("CARGO_BIN_EXE_sim-host");
    let out = std::process::Command::new(bin)
        .args(["campaign", "--print-campaign"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let printed = String::from_utf8(out.stdout).unwrap();
    let spec = CampaignSpec::from_toml_str(&printed, Path::new("printed")).unwrap();
    assert_eq!(spec, CampaignSpec::default());

    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bad.toml");
    std::fs::write(&file, "[servos]\nrate_limit_spread = -0.3\n").unwrap();
    let out = std::process::Command::new(bin)
        .args(["campaign", "--runs", "2", "--campaign"])
        .arg(&file)
        .arg("--out")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("bad.toml")
            && err.contains("`servos.rate_limit_spread`")
            && err.contains("-0.3"),
        "{err}"
    );
    assert!(
        !dir.path().join("out").exists(),
        "nothing flown, nothing written"
    );
}

/// Half the aircraft of the built-in campaign carry a rangefinder (about 500 of 1000, within
/// four binomial standard deviations of 16), drawn after everything else, so every other draw
/// of a flight is the one it has with none fitted; the flare's oracle changes nothing but the one parameter the station
/// sets; a share outside 0..1 is refused naming the key.
#[test]
fn a_share_of_the_aircraft_carry_a_rangefinder_and_the_oracle_only_sets_sim_use_truth() {
    let mut plain = campaign(1000, 1, MissionChoice::Default);
    plain.spec.rangefinder.fitted_share = 0.0;
    let fitted = campaign(1000, 1, MissionChoice::Default);
    assert_eq!(
        fitted.spec.rangefinder.fitted_share, 0.5,
        "the built-in share"
    );
    let mut carried = 0;
    for i in 0..1000 {
        let (a, b) = (plain.plan(i), fitted.plan(i));
        assert!(a.aircraft.sensors.rangefinder.is_none());
        let flag = b.draws.get("rangefinder.fitted").expect("drawn");
        assert_eq!(flag == 1.0, b.aircraft.sensors.rangefinder.is_some());
        carried += usize::from(flag == 1.0);
        let others: Vec<_> = b
            .draws
            .0
            .iter()
            .filter(|(n, _)| n != "rangefinder.fitted")
            .cloned()
            .collect();
        assert_eq!(others, a.draws.0, "flight {i}");
    }
    assert!((436..=564).contains(&carried), "{carried} of 1000 fitted");

    let mut oracle = campaign(10, 1, MissionChoice::Default);
    oracle.spec.oracle.flare_on_truth = true;
    let (a, b) = (fitted.plan(3), oracle.plan(3));
    assert_eq!(a.draws, b.draws);
    let mut params = b.config.script.params.clone();
    assert_eq!(params.pop(), Some(("SIM_USE_TRUTH".to_string(), 2.0)));
    assert_eq!(params, a.config.script.params);

    let msg = refused("[rangefinder]\nfitted_share = 1.5\n");
    assert!(
        msg.contains("`rangefinder.fitted_share`") && msg.contains("1.5"),
        "{msg}"
    );
}

/// `[station] autotune` flies each flight's own draws with the autotune before the mission, as
/// a QGroundControl user flies it: Takeoff a second after arming, Hold, the autotune pressed,
/// the mission started last; the same parameters (nothing tuned by the station), and the
/// plain campaign presses none of it.
#[test]
fn the_station_s_autotune_key_flies_the_same_draws_with_takeoff_hold_autotune_then_the_mission() {
    use sim_host::flight::missions::{AUTOTUNE_AFTER_TAKEOFF_S, MISSION_AFTER_AUTOTUNE_S};
    use sim_host::flight::script::Action;
    let plain = campaign(10, 1, MissionChoice::Default);
    let spec = CampaignSpec::from_toml_str("[station]\nautotune = true\n", Path::new("x")).unwrap();
    let tuned = Campaign {
        spec,
        ..plain.clone()
    };
    let (a, b) = (plain.plan(4), tuned.plan(4));
    assert_eq!(a.draws, b.draws);
    assert_eq!(a.config.script.params, b.config.script.params);
    let when = |p: &sim_host::campaign::record::Plan, f: &dyn Fn(&Action) -> bool| {
        p.config
            .script
            .steps
            .iter()
            .filter(|s| f(&s.action))
            .map(|s| s.after_arm_s)
            .collect::<Vec<_>>()
    };
    let takeoff = |x: &Action| matches!(x, Action::Takeoff);
    let autotune = |x: &Action| matches!(x, Action::Autotune(true));
    let start = |x: &Action| matches!(x, Action::MissionStart);
    assert!(when(&a, &takeoff).is_empty() && when(&a, &autotune).is_empty());
    assert_eq!(when(&b, &takeoff), [1.0]);
    assert_eq!(when(&b, &autotune), [AUTOTUNE_AFTER_TAKEOFF_S]);
    assert_eq!(when(&b, &start).last(), Some(&MISSION_AFTER_AUTOTUNE_S));
    assert!(b.config.duration_s >= a.config.duration_s + MISSION_AFTER_AUTOTUNE_S);
}

/// Two flights, and beside them the same two with the first one's verdict turned over: the
/// pairing counts that flight as passing on one side only, every group's counts add up to
/// its flights, the changed key is named, and a campaign of another seed is refused.
#[test]
fn a_campaign_beside_another_of_the_same_flights_pairs_their_verdicts_flight_for_flight() {
    use sim_host::campaign::groups::{beside, rates};
    let mut c = campaign(2, 5, MissionChoice::Default);
    // Grouped by turbulence alone: no rangefinder drawn.
    c.spec.rangefinder.fitted_share = 0.0;
    let meta = c.meta(Shard::WHOLE);
    let records = c.run(Shard::WHOLE, 2, false).unwrap();
    let mut other = c.clone();
    other.spec.oracle.flare_on_truth = true;
    let mut turned = records.clone();
    turned[0].verdict.pass = !turned[0].verdict.pass;
    let b = beside(
        &meta,
        &records,
        Path::new("out/oracle"),
        (&other.meta(Shard::WHOLE), &turned),
    )
    .unwrap();
    let all = &b.rows[0];
    assert_eq!(all.here.group, "every flight");
    assert_eq!(all.here.flights, 2);
    let first_passed = records[0].verdict.pass;
    assert_eq!(
        (all.only_here, all.only_beside),
        if first_passed { (1, 0) } else { (0, 1) }
    );
    assert_eq!(
        all.beside.passed + all.only_here,
        all.here.passed + all.only_beside
    );
    let groups = rates(&meta, &records);
    let light_and_moderate: u64 = groups[1..].iter().map(|g| g.flights).sum();
    assert_eq!((groups.len(), light_and_moderate), (3, 2));
    assert_eq!(
        b.changes,
        vec!["`oracle.flare_on_truth`: false here, true beside".to_string()]
    );
    assert!(b.command.contains("--out out/oracle"), "{}", b.command);
    let elsewhere = campaign(2, 6, MissionChoice::Default).meta(Shard::WHOLE);
    let msg = beside(&meta, &records, Path::new("x"), (&elsewhere, &turned))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("seed is 6"), "{msg}");
}
