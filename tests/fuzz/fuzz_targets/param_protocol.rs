#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| autopilot_fuzz::param_protocol::run(data));
