//! The encoder against the byte layout of PX4's "ULog File Format" specification.

use super::*;

const ATTITUDE: Format = Format {
    name: "vehicle_attitude",
    fields: &[
        Field::array("q", Ty::F32, 4),
        Field::array("delta_q_reset", Ty::F32, 4),
        Field::scalar("quat_reset_counter", Ty::U8),
        Field::array("_padding0", Ty::U8, 7),
    ],
};

#[test]
fn the_header_is_the_seven_magic_bytes_version_one_and_the_start_time() {
    let mut b = [0u8; 32];
    let n = header(&mut b, 0x0102_0304_0506_0708).unwrap();
    assert_eq!(n, 16);
    assert_eq!(
        b[..16],
        [0x55, 0x4c, 0x6f, 0x67, 0x01, 0x12, 0x35, 0x01, 8, 7, 6, 5, 4, 3, 2, 1]
    );
}

#[test]
fn the_flag_bits_are_forty_bytes_of_no_flag_and_no_appended_data() {
    let mut b = [0xAAu8; 64];
    let n = flag_bits(&mut b).unwrap();
    assert_eq!(n, 43);
    assert_eq!(b[..3], [40, 0, b'B']);
    assert!(b[3..43].iter().all(|&x| x == 0));
}

#[test]
fn a_format_starts_with_the_timestamp_and_writes_arrays_with_their_length() {
    let mut b = [0u8; 256];
    let n = format(&mut b, &ATTITUDE).unwrap();
    let text = "vehicle_attitude:uint64_t timestamp;float[4] q;float[4] delta_q_reset;\
                uint8_t quat_reset_counter;uint8_t[7] _padding0;";
    assert_eq!(n, 3 + text.len());
    assert_eq!(u16::from_le_bytes([b[0], b[1]]) as usize, text.len());
    assert_eq!(b[2], b'F');
    assert_eq!(&b[3..n], text.as_bytes());
}

#[test]
fn a_sample_is_the_message_id_then_as_many_bytes_as_its_format_says() {
    // PX4's vehicle_attitude: 8 + 16 + 16 + 1 + 7 bytes.
    assert_eq!(ATTITUDE.size(), 48);
    let mut b = [0u8; 128];
    let n = data(&mut b, 3, 1_000_000, |c| {
        c.f32s(&[1.0, 0.0, 0.0, 0.0])
            .f32s(&[0.0; 4])
            .u8(0)
            .put(&[0; 7]);
    })
    .unwrap();
    assert_eq!(n, 3 + 2 + ATTITUDE.size());
    assert_eq!(b[..5], [50, 0, b'D', 3, 0]);
    assert_eq!(u64::from_le_bytes(b[5..13].try_into().unwrap()), 1_000_000);
    assert_eq!(f32::from_le_bytes(b[13..17].try_into().unwrap()), 1.0);
}

#[test]
fn a_sample_encoded_in_place_is_the_same_message() {
    let fields = |c: &mut Cursor<'_>| {
        c.f32s(&[1.0, 0.0, 0.0, 0.5]).u8(7).f64(-2.5);
    };
    for len in [0, 12, 13, 24, 25, 26, 40, 128] {
        let mut whole = [0u8; 128];
        let mut buf = [0u8; 128];
        let whole = &mut whole[..len];
        let buf = &mut buf[..len];
        let expected = data(whole, 3, 1_000_000, fields);
        let encoded = data_fields(buf, fields);
        let n = data_in_place(buf, 3, 1_000_000, encoded);
        assert_eq!(n, expected, "buffer of {len}");
        if let Ok(n) = n {
            assert_eq!(buf[..n], whole[..n]);
        }
    }
}

#[test]
fn an_information_text_names_its_length_in_the_key() {
    let mut b = [0u8; 64];
    let n = info_str(&mut b, "sys_name", "Ultra").unwrap();
    let key = b"char[5] sys_name";
    assert_eq!(b[2], b'I');
    assert_eq!(b[3] as usize, key.len());
    assert_eq!(&b[4..4 + key.len()], key);
    assert_eq!(&b[4 + key.len()..n], b"Ultra");
    assert_eq!(u16::from_le_bytes([b[0], b[1]]) as usize, n - 3);
}

#[test]
fn parameters_carry_their_c_type_in_the_key() {
    let mut b = [0u8; 64];
    let n = parameter_f32(&mut b, "FW_AIRSPD_TRIM", 17.0).unwrap();
    assert_eq!(b[2], b'P');
    assert_eq!(&b[4..4 + b[3] as usize], b"float FW_AIRSPD_TRIM");
    assert_eq!(b[n - 4..n], 17.0f32.to_le_bytes());
    let n = parameter_i32(&mut b, "NAV_DLL_ACT", -2).unwrap();
    assert_eq!(&b[4..4 + b[3] as usize], b"int32_t NAV_DLL_ACT");
    assert_eq!(b[n - 4..n], (-2i32).to_le_bytes());
}

#[test]
fn a_subscription_a_text_a_sync_and_a_dropout_have_the_specified_layout() {
    let mut b = [0u8; 64];
    let n = add_logged(&mut b, 1, 0x0203, "actuator_outputs").unwrap();
    assert_eq!(b[2..6], [b'A', 1, 3, 2]);
    assert_eq!(&b[6..n], b"actuator_outputs");

    let n = logging(&mut b, Level::Warning, 5, "low battery").unwrap();
    assert_eq!(b[2..4], [b'L', b'4']);
    assert_eq!(b[4..12], 5u64.to_le_bytes());
    assert_eq!(&b[12..n], b"low battery");

    let n = sync(&mut b).unwrap();
    assert_eq!(
        b[..n],
        [8, 0, b'S', 0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12]
    );

    let n = dropout(&mut b, 70_000).unwrap();
    assert_eq!(b[..n], [2, 0, b'O', 0xFF, 0xFF]);
}

#[test]
fn a_message_too_long_for_its_buffer_is_refused_whole() {
    let mut b = [0u8; 20];
    assert_eq!(format(&mut b, &ATTITUDE), Err(TooLong));
    let mut b43 = [0u8; 43];
    assert_eq!(flag_bits(&mut b43[..42]), Err(TooLong));
    assert_eq!(flag_bits(&mut b43), Ok(43));
    assert_eq!(header(&mut b[..15], 0), Err(TooLong));
    assert_eq!(message(&mut b[..2], MsgType::Sync, |_| {}), Err(TooLong));
    // A key over 255 bytes cannot be written at all.
    let long = core::str::from_utf8(&[b'x'; 300]).unwrap();
    let mut big = [0u8; 1024];
    assert_eq!(info_u32(&mut big, long, 1), Err(TooLong));
}

#[test]
fn decimals_are_written_without_leading_zeros() {
    for (v, text) in [(0usize, "0"), (7, "7"), (10, "10"), (65_535, "65535")] {
        let mut b = [0u8; 8];
        let mut c = Cursor::new(&mut b);
        c.decimal(v);
        let n = c.finish().unwrap();
        assert_eq!(&b[..n], text.as_bytes());
    }
}
