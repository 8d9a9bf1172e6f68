//! Empty on purpose: the build-dependency on `mavlink-bindgen` in Cargo.toml exists only to
//! switch on the MAVLink 2 extension fields without pulling a std crate into the MCU build.
fn main() {}
