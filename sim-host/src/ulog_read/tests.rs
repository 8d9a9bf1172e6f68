//! The reader on logs built byte by byte from PX4's specification ("ULog File Format"), not
//! with the project's encoder (one test reads that encoder's messages back too).

use super::*;

/// The 16-byte header: magic, version 1, the start time.
fn header(start_us: u64) -> Vec<u8> {
    let mut b = vec![0x55, 0x4c, 0x6f, 0x67, 0x01, 0x12, 0x35, 0x01];
    b.extend(start_us.to_le_bytes());
    b
}

/// A message: `msg_size` (u16 LE), `msg_type`, the payload.
fn msg(kind: u8, payload: &[u8]) -> Vec<u8> {
    let mut b = (payload.len() as u16).to_le_bytes().to_vec();
    b.push(kind);
    b.extend(payload);
    b
}

/// The flag bits: compat, incompat, three appended offsets.
fn flags(incompat0: u8, appended: [u64; 3]) -> Vec<u8> {
    let mut p = vec![0u8; 8];
    p.push(incompat0);
    p.extend([0u8; 7]);
    for o in appended {
        p.extend(o.to_le_bytes());
    }
    msg(b'B', &p)
}

/// A keyed message (`I`, `P`): key length, `type name`, the value's bytes, after `prefix`.
fn keyed(kind: u8, prefix: &[u8], key: &str, value: &[u8]) -> Vec<u8> {
    let mut p = prefix.to_vec();
    p.push(key.len() as u8);
    p.extend(key.as_bytes());
    p.extend(value);
    msg(kind, &p)
}

fn add_logged(multi_id: u8, msg_id: u16, name: &str) -> Vec<u8> {
    let mut p = vec![multi_id];
    p.extend(msg_id.to_le_bytes());
    p.extend(name.as_bytes());
    msg(b'A', &p)
}

fn data(msg_id: u16, sample: &[u8]) -> Vec<u8> {
    let mut p = msg_id.to_le_bytes().to_vec();
    p.extend(sample);
    msg(b'D', &p)
}

/// An attitude sample: timestamp and quaternion, the trailing padding left out.
fn attitude(t_us: u64, q: [f32; 4]) -> Vec<u8> {
    let mut s = t_us.to_le_bytes().to_vec();
    for x in q {
        s.extend(x.to_le_bytes());
    }
    s
}

/// A log written message by message with the project's encoder (`common::ulog`).
#[derive(Default)]
pub(crate) struct Encoded(pub(crate) Vec<u8>);

impl Encoded {
    /// Appends what `f` encodes.
    pub(crate) fn put(
        &mut self,
        f: impl FnOnce(&mut [u8]) -> Result<usize, common::ulog::TooLong>,
    ) -> &mut Self {
        let mut buf = [0u8; 512];
        let n = f(&mut buf).unwrap();
        self.0.extend_from_slice(&buf[..n]);
        self
    }
}

const SYNC: [u8; 8] = [0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12];

/// A log with every message type of the specification.
fn every_message() -> Vec<u8> {
    let mut b = header(1_000);
    b.extend(flags(0, [0; 3]));
    b.extend(msg(
        b'F',
        b"vehicle_attitude:uint64_t timestamp;float[4] q;uint8_t[4] _padding0;",
    ));
    b.extend(keyed(b'I', &[], "char[5] sys_name", b"plane"));
    b.extend(keyed(
        b'I',
        &[],
        "uint32_t ver_hw_subtype",
        &7u32.to_le_bytes(),
    ));
    b.extend(keyed(b'P', &[], "int32_t SYS_X", &(-3i32).to_le_bytes()));
    b.extend(keyed(b'P', &[], "float FW_Y", &1.5f32.to_le_bytes()));
    b.extend(keyed(b'Q', &[1], "float FW_Y", &1.0f32.to_le_bytes()));
    b.extend(add_logged(0, 7, "vehicle_attitude"));
    b.extend(data(7, &attitude(2_000, [1.0, 0.0, 0.0, 0.0])));
    let mut l = vec![b'6'];
    l.extend(2_500u64.to_le_bytes());
    l.extend(b"armed");
    b.extend(msg(b'L', &l));
    b.extend(msg(b'S', &SYNC));
    let mut c = vec![b'4'];
    c.extend(9u16.to_le_bytes());
    c.extend(2_600u64.to_le_bytes());
    c.extend(b"tagged");
    b.extend(msg(b'C', &c));
    b.extend(data(7, &attitude(3_000, [0.0, 1.0, 0.0, 0.0])));
    b.extend(msg(b'O', &120u16.to_le_bytes()));
    b.extend(keyed(b'P', &[], "float FW_Y", &2.5f32.to_le_bytes()));
    b.extend(keyed(b'M', &[0], "char[3] perf", b"abc"));
    b.extend(keyed(b'M', &[1], "char[3] perf", b"def"));
    b
}

#[test]
fn every_message_type_of_the_specification_is_read_into_the_log() {
    let log = parse(&every_message()).unwrap();
    assert_eq!(log.warnings, vec![], "a whole, well-formed log");
    assert_eq!((log.version, log.start_us), (1, 1_000));
    assert_eq!(log.info_text("sys_name").as_deref(), Some("plane"));
    assert_eq!(log.info["ver_hw_subtype"], Value::UInt(7));
    assert_eq!(log.params["SYS_X"], Value::Int(-3));
    assert_eq!(log.params["FW_Y"], Value::Float(1.5));
    assert_eq!(
        log.param_defaults,
        vec![ParamDefault {
            default_types: 1,
            name: "FW_Y".into(),
            value: Value::Float(1.0)
        }]
    );
    // The change after the data started, at the last timestamp seen (the second sample).
    assert_eq!(
        log.param_changes,
        vec![ParamChange {
            timestamp_us: 3_000,
            name: "FW_Y".into(),
            value: Value::Float(2.5)
        }]
    );
    let att = log.dataset("vehicle_attitude").unwrap();
    assert_eq!(att.timestamps_us(), &[2_000, 3_000]);
    assert_eq!(att.field("q[0]").unwrap(), vec![1.0, 0.0]);
    assert_eq!(att.field("q[1]").unwrap(), vec![0.0, 1.0]);
    assert!(att.field("_padding0[0]").is_none(), "padding is no field");
    assert_eq!(att.layout.size, 8 + 16 + 4);
    assert_eq!(att.layout.min_size, 8 + 16);
    assert_eq!(
        log.texts,
        vec![
            Text {
                level: 6,
                tag: None,
                timestamp_us: 2_500,
                text: "armed".into()
            },
            Text {
                level: 4,
                tag: Some(9),
                timestamp_us: 2_600,
                text: "tagged".into()
            }
        ]
    );
    assert_eq!(log.texts[1].level_name(), "warning");
    assert_eq!(log.syncs, 1);
    assert_eq!(
        log.dropouts,
        vec![Dropout {
            timestamp_us: 3_000,
            duration_ms: 120
        }]
    );
    assert_eq!(log.info_multi["perf"], vec![Value::Text("abcdef".into())]);
    assert_eq!(log.bytes_read, every_message().len());
    assert_eq!(log.last_us(), 3_000);
}

#[test]
fn nested_formats_and_their_arrays_lie_flat_under_pyulogs_names() {
    let mut b = header(0);
    b.extend(flags(0, [0; 3]));
    b.extend(msg(b'F', b"esc_report:int32_t esc_rpm;uint8_t esc_state;"));
    b.extend(msg(
        b'F',
        b"esc_status:uint64_t timestamp;uint8_t esc_count;esc_report[2] esc;",
    ));
    b.extend(add_logged(1, 3, "esc_status"));
    let mut s = 50u64.to_le_bytes().to_vec();
    s.push(2);
    s.extend(1200i32.to_le_bytes());
    s.push(1);
    s.extend((-5i32).to_le_bytes());
    s.push(0);
    b.extend(data(3, &s));
    let log = parse(&b).unwrap();
    assert_eq!(log.warnings, vec![]);
    let d = log.dataset("esc_status").unwrap();
    assert_eq!(d.multi_id, 1);
    let names: Vec<&str> = d.layout.fields.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "timestamp",
            "esc_count",
            "esc[0].esc_rpm",
            "esc[0].esc_state",
            "esc[1].esc_rpm",
            "esc[1].esc_state"
        ]
    );
    assert_eq!(d.field("esc[0].esc_rpm").unwrap(), vec![1200.0]);
    assert_eq!(d.field("esc[1].esc_rpm").unwrap(), vec![-5.0]);
    assert_eq!(d.timestamps_us(), &[50]);
}

#[test]
fn a_format_that_contains_itself_is_a_warning_and_its_data_are_skipped() {
    let mut b = header(0);
    b.extend(msg(b'F', b"loop:uint64_t timestamp;loop inner;"));
    b.extend(add_logged(0, 0, "loop"));
    b.extend(data(0, &[0; 16]));
    let log = parse(&b).unwrap();
    assert!(log.datasets.is_empty());
    let text: Vec<String> = log.warnings.iter().map(Warning::to_string).collect();
    assert!(text[0].contains("nests more than"), "{text:?}");
    assert!(
        text[1].contains("data for message id 0, which no subscription names"),
        "{text:?}"
    );
}

#[test]
fn an_array_of_empty_nested_formats_cannot_make_the_reader_expand_without_end() {
    let mut b = header(0);
    b.extend(msg(b'F', b"empty:"));
    b.extend(msg(b'F', b"mid:empty[60000] e;"));
    b.extend(msg(b'F', b"top:uint64_t timestamp;mid[60000] m;"));
    b.extend(add_logged(0, 0, "top"));
    let log = parse(&b).unwrap();
    assert!(log.datasets.is_empty());
    assert!(
        log.warnings[0].what.contains("expands to more than"),
        "{:?}",
        log.warnings
    );
}

#[test]
fn unknown_incompatible_flags_stop_the_reader_at_the_flag_bits() {
    let mut b = header(0);
    b.extend(flags(0b10, [0; 3]));
    let e = parse(&b).unwrap_err();
    assert_eq!(e.offset, 16);
    assert!(e.what.contains("incompatible flags"), "{e}");
    assert!(e.to_string().starts_with("byte 16: "), "{e}");
}

#[test]
fn appended_data_are_read_after_a_part_that_ends_mid_message() {
    let mut b = header(0);
    let flags_at = b.len();
    b.extend(flags(1, [0; 3]));
    b.extend(msg(b'F', b"t:uint64_t timestamp;float x;"));
    b.extend(add_logged(0, 0, "t"));
    let mut s = 10u64.to_le_bytes().to_vec();
    s.extend(1.0f32.to_le_bytes());
    b.extend(data(0, &s));
    // A sample cut in two: the writer stopped here, and appended from the next byte.
    b.extend(&data(0, &s)[..7]);
    let appended = b.len() as u64;
    let mut s2 = 20u64.to_le_bytes().to_vec();
    s2.extend(2.0f32.to_le_bytes());
    b.extend(data(0, &s2));
    b[flags_at + 3 + 16..flags_at + 3 + 24].copy_from_slice(&appended.to_le_bytes());
    let log = parse(&b).unwrap();
    assert_eq!(
        log.warnings,
        vec![],
        "a cut part before appended data is expected"
    );
    let t = log.dataset("t").unwrap();
    assert_eq!(t.timestamps_us(), &[10, 20]);
    assert_eq!(t.field("x").unwrap(), vec![1.0, 2.0]);
}

#[test]
fn bytes_that_are_no_message_are_skipped_to_the_next_sync_marker() {
    let mut b = every_message();
    // Garbage where the second attitude sample was written, and a sync marker after it.
    let cut = b.len();
    b.extend([0xEE; 40]);
    b.extend(msg(b'S', &SYNC));
    b.extend(data(7, &attitude(9_000, [0.5, 0.5, 0.5, 0.5])));
    let log = parse(&b).unwrap();
    assert_eq!(log.warnings.len(), 1, "{:?}", log.warnings);
    assert_eq!(log.warnings[0].offset, cut);
    assert!(
        log.warnings[0].what.contains("type byte 0xEE"),
        "{}",
        log.warnings[0]
    );
    assert_eq!(
        log.dataset("vehicle_attitude").unwrap().timestamps_us(),
        &[2_000, 3_000, 9_000]
    );
}

#[test]
fn a_sample_its_format_cannot_hold_is_corruption_skipped_to_the_next_sync_marker() {
    let mut b = every_message();
    let bad = b.len();
    // A size byte gone wrong: the message claims 5 bytes of a 28-byte format, and the next
    // message is not where it says; the one after the sync marker is.
    b.extend(data(7, &[0; 5]));
    b.extend(data(7, &attitude(4_000, [1.0; 4])));
    b.extend(msg(b'S', &SYNC));
    b.extend(data(7, &attitude(5_000, [1.0; 4])));
    let log = parse(&b).unwrap();
    assert_eq!(
        log.dataset("vehicle_attitude").unwrap().timestamps_us(),
        &[2_000, 3_000, 5_000]
    );
    assert_eq!(log.warnings.len(), 1, "{:?}", log.warnings);
    assert_eq!(log.warnings[0].offset, bad);
    assert!(
        log.warnings[0]
            .what
            .starts_with("a sample of `vehicle_attitude` is 5 bytes, its format 28: the file is corrupt; skipped"),
        "{}",
        log.warnings[0]
    );

    // Without a sync marker after it, reading stops there.
    let mut b = every_message();
    b.extend(data(7, &[0; 40]));
    let log = parse(&b).unwrap();
    assert!(
        log.warnings[0].what.contains("no sync marker follows"),
        "{:?}",
        log.warnings
    );
    assert_eq!(log.bytes_read, every_message().len());
}

#[test]
fn data_that_no_subscription_names_are_skipped_and_counted() {
    let mut b = every_message();
    b.extend(data(99, &[0; 24]));
    b.extend(data(99, &[0; 24]));
    b.extend(data(7, &attitude(4_000, [1.0; 4])));
    let log = parse(&b).unwrap();
    assert_eq!(log.dataset("vehicle_attitude").unwrap().len(), 3);
    let text: Vec<String> = log.warnings.iter().map(Warning::to_string).collect();
    assert_eq!(text.len(), 1, "{text:?}");
    assert!(
        text[0].contains(
            "data for message id 99, which no subscription names: skipped (and 1 more like it)"
        ),
        "{text:?}"
    );
}

#[test]
fn a_removed_subscription_takes_no_more_data_until_it_is_added_again() {
    let mut b = every_message();
    b.extend(msg(b'R', &7u16.to_le_bytes()));
    b.extend(data(7, &attitude(4_000, [1.0; 4])));
    b.extend(add_logged(0, 8, "vehicle_attitude"));
    b.extend(data(8, &attitude(5_000, [1.0; 4])));
    let log = parse(&b).unwrap();
    assert_eq!(log.datasets.len(), 1, "the same topic, subscribed again");
    assert_eq!(log.datasets[0].timestamps_us(), &[2_000, 3_000, 5_000]);
    assert_eq!(log.warnings.len(), 1, "{:?}", log.warnings);
}

#[test]
fn a_file_that_is_no_log_is_an_error_at_byte_zero_saying_why() {
    let e = parse(&[]).unwrap_err();
    assert_eq!(e.offset, 0);
    assert!(e.what.contains("empty"), "{e}");

    let e = parse(b"\x7fELF\x02\x01\x01\0\0\0\0\0\0\0\0\0\0").unwrap_err();
    assert_eq!(e.offset, 0);
    assert!(
        e.what
            .contains("not a ULog file: it starts with 7F 45 4C 46"),
        "{e}"
    );

    let e = parse(&header(0)[..11]).unwrap_err();
    assert_eq!(e.offset, 11);
    assert!(e.what.contains("the header is 16 bytes"), "{e}");

    // The first bytes of the magic alone are a cut log, not another kind of file.
    let e = parse(b"UL").unwrap_err();
    assert!(e.what.contains("the header is 16 bytes"), "{e}");
}

#[test]
fn a_log_cut_at_any_byte_reads_its_whole_messages_or_says_its_header_is_cut() {
    let whole = every_message();
    let full = parse(&whole).unwrap();
    // Where each message ends: a cut there leaves whole messages only.
    let mut ends = vec![16];
    let mut at = 16;
    while at < whole.len() {
        at += 3 + usize::from(u16::from_le_bytes([whole[at], whole[at + 1]]));
        ends.push(at);
    }
    for cut in 0..whole.len() {
        match parse(&whole[..cut]) {
            Err(e) => assert!(cut < 16, "cut at {cut}: {e}"),
            Ok(log) => {
                assert!(cut >= 16, "cut at {cut} read");
                let last_end = *ends.iter().rfind(|&&e| e <= cut).unwrap();
                assert_eq!(log.bytes_read, last_end, "cut at {cut}");
                if ends.contains(&cut) {
                    assert_eq!(log.warnings, vec![], "cut at {cut}, a message's end");
                } else {
                    assert_eq!(log.warnings.len(), 1, "cut at {cut}");
                    assert_eq!(log.warnings[0].offset, last_end, "cut at {cut}");
                    assert!(
                        log.warnings[0].what.contains("the file ends"),
                        "cut at {cut}: {}",
                        log.warnings[0]
                    );
                }
                for d in &log.datasets {
                    let f = full.dataset(&d.name).unwrap();
                    assert!(
                        f.timestamps_us().starts_with(d.timestamps_us()),
                        "cut at {cut}"
                    );
                }
            }
        }
    }
}

#[test]
fn the_project_encoders_log_reads_back_as_written() {
    use common::logger::topics::VehicleAttitude;
    use common::ulog::topic::Topic;
    use common::ulog::{self as enc, Level};
    let mut b = Encoded::default();
    b.put(|x| enc::header(x, 5_000_000));
    b.put(enc::flag_bits);
    b.put(|x| enc::info_str(x, "ver_sw", "0.1.0"));
    b.put(|x| enc::info_u32(x, "ver_hw_rev", 3));
    b.put(|x| enc::parameter_f32(x, "NAV_ASPD", 17.0));
    b.put(|x| enc::parameter_i32(x, "SYS_GAIN_SET", 2));
    b.put(|x| enc::format(x, &VehicleAttitude::FORMAT));
    b.put(|x| enc::add_logged(x, 0, 4, "vehicle_attitude"));
    let q = VehicleAttitude {
        q: [0.5, -0.5, 0.25, 0.75],
    };
    b.put(|x| enc::data(x, 4, 5_010_000, |c| q.encode(c)));
    b.put(|x| enc::logging(x, Level::Warning, 5_020_000, "battery low"));
    b.put(enc::sync);
    b.put(|x| enc::dropout(x, 70_000));
    let log = parse(&b.0).unwrap();
    assert_eq!(log.warnings, vec![]);
    assert_eq!(log.start_us, 5_000_000);
    assert_eq!(log.info_text("ver_sw").as_deref(), Some("0.1.0"));
    assert_eq!(log.info["ver_hw_rev"], Value::UInt(3));
    assert_eq!(log.params["NAV_ASPD"], Value::Float(17.0));
    assert_eq!(log.params["SYS_GAIN_SET"], Value::Int(2));
    let att = log.dataset("vehicle_attitude").unwrap();
    assert_eq!(att.timestamps_us(), &[5_010_000]);
    for (i, v) in q.q.iter().enumerate() {
        assert_eq!(att.field(&format!("q[{i}]")).unwrap(), vec![f64::from(*v)]);
    }
    assert_eq!(log.texts[0].level_name(), "warning");
    assert_eq!(log.texts[0].text, "battery low");
    assert_eq!(log.syncs, 1);
    assert_eq!(
        log.dropouts[0].duration_ms,
        u16::MAX,
        "saturated, as written"
    );
}

#[test]
fn malformed_definitions_are_skipped_with_a_warning_naming_the_message() {
    let mut b = header(0);
    b.extend(msg(b'F', b"no_colon_here"));
    b.extend(msg(b'F', b"t:uint64_t timestamp;float[x] bad;"));
    b.extend(keyed(b'I', &[], "nospace", b"v"));
    b.extend(msg(b'I', &[200, b'a']));
    b.extend(keyed(b'P', &[], "float SHORT", &[0, 0]));
    let log = parse(&b).unwrap();
    let text: Vec<String> = log.warnings.iter().map(Warning::to_string).collect();
    assert_eq!(text.len(), 5, "{text:?}");
    assert!(
        text[0].starts_with("byte 16: format message `no_colon_here`"),
        "{text:?}"
    );
    assert!(text[1].contains("not an array length"), "{text:?}");
    assert!(text[2].contains("not `type name`"), "{text:?}");
    assert!(text[3].contains("key longer than the message"), "{text:?}");
    assert!(text[4].contains("value shorter than its type"), "{text:?}");
    assert!(log.formats.is_empty() && log.info.is_empty() && log.params.is_empty());
}

#[test]
fn a_format_after_the_definitions_is_ignored_with_a_warning() {
    let mut b = every_message();
    let late = b.len();
    b.extend(msg(b'F', b"vehicle_attitude:uint64_t timestamp;double x;"));
    b.extend(data(7, &attitude(4_000, [1.0; 4])));
    let log = parse(&b).unwrap();
    assert_eq!(log.dataset("vehicle_attitude").unwrap().len(), 3);
    assert_eq!(log.warnings.len(), 1, "{:?}", log.warnings);
    assert_eq!(log.warnings[0].offset, late);
    assert!(log.warnings[0].what.contains("after the definitions"));
}

#[test]
fn subscribing_many_times_to_a_large_format_lays_it_out_once() {
    let mut b = header(0);
    b.extend(msg(b'F', b"big:uint64_t timestamp;uint8_t[60000] b;"));
    for i in 0..20_000u16 {
        b.extend(add_logged((i % 256) as u8, i, "big"));
    }
    let started = std::time::Instant::now();
    let log = parse(&b).unwrap();
    // Laid out anew each time, 20,000 x 60,000 values would take minutes.
    assert!(started.elapsed().as_secs() < 10, "{:?}", started.elapsed());
    assert_eq!(log.datasets.len(), 256);
    assert_eq!(log.warnings, vec![]);
}

#[test]
fn the_formats_of_one_log_lay_out_a_bounded_number_of_values_in_all() {
    let mut b = header(0);
    for i in 0..40 {
        b.extend(msg(
            b'F',
            format!("big{i}:uint64_t timestamp;uint8_t[60000] b;").as_bytes(),
        ));
    }
    for i in 0..40u16 {
        b.extend(add_logged(0, i, &format!("big{i}")));
    }
    let log = parse(&b).unwrap();
    // 2^21 values in all: 34 formats of 60,001.
    assert_eq!(log.datasets.len(), 34);
    assert_eq!(log.warnings.len(), 6, "{:?}", log.warnings);
    assert!(
        log.warnings[0].what.contains("values in all"),
        "{}",
        log.warnings[0]
    );
}
