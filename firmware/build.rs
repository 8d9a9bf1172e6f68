//! Build-time work of the firmware:
//! - puts the workspace's `memory.x` (the STM32F405RG map) on the linker's search path for the
//!   MCU build;
//! - writes the component metadata the image serves over MAVLink FTP: the parameter metadata
//!   generated from the registry the firmware flies with, xz-compressed as QGroundControl
//!   accepts it, and the `general.json` that points to it with its CRC. Generating them here
//!   keeps float formatting and JSON out of the image: it carries only the compressed bytes.
use std::io::Write;
use std::{env, fs, path::PathBuf};

use common::gcs::ftp::file_crc;
use common::params::metadata;
use common::vehicle::params::REGISTRY;
use lzma_rust2::{XzOptions, XzWriter};

/// The name the parameter metadata is served under (`.xz`: ground stations inflate by suffix).
const PARAMETERS: &str = "parameters.json.xz";

fn main() {
    println!("cargo:rerun-if-changed=../memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    write_metadata(&out);
    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }
    fs::copy("../memory.x", out.join("memory.x")).expect("memory.x at the workspace root");
    // cortex-m-rt's `device` feature includes a `device.x` of the device's handler names; the
    // image's interrupts all go to `DefaultHandler` (`mcu::__INTERRUPTS`): it names none.
    fs::write(
        out.join("device.x"),
        "/* Every interrupt vector is DefaultHandler (firmware::mcu's __INTERRUPTS). */\n",
    )
    .expect("OUT_DIR is writable");
    println!("cargo:rustc-link-search={}", out.display());
}

fn write_metadata(out: &std::path::Path) {
    let mut json = String::new();
    metadata::write_json(REGISTRY, &mut json).expect("a String takes any text");
    // Preset 9 as PX4's metadata build; one block, CRC-64 check, what `xz` writes by default.
    let mut xz = XzWriter::new(Vec::new(), XzOptions::with_preset(9)).expect("xz options");
    xz.write_all(json.as_bytes())
        .expect("compressing into memory");
    let xz = xz.finish().expect("compressing into memory");
    let general = format!(
        "{{\"version\":1,\"vendorName\":\"{vendor}\",\"modelName\":\"{model}\",\
         \"firmwareVersion\":\"{version}\",\"metadataTypes\":[{{\"type\":1,\
         \"uri\":\"mftp://{PARAMETERS}\",\"fileCrc\":{crc}}}]}}",
        vendor = env!("CARGO_PKG_NAME"),
        // The firmware's build, not an airframe: the aircraft is what its parameters make it.
        model = if env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("none") {
            "STM32F405"
        } else {
            "SITL"
        },
        version = env!("CARGO_PKG_VERSION"),
        crc = file_crc(&xz),
    );
    fs::write(out.join(PARAMETERS), xz).expect("OUT_DIR is writable");
    fs::write(out.join("general.json"), general).expect("OUT_DIR is writable");
}
