#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| autopilot_fuzz::mission_protocol::run(data));
