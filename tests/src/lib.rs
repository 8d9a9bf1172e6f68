//! Shared helpers of the system tests in `tests/tests/`.

pub mod station;

use std::path::PathBuf;
use std::process::Command;

/// The workspace root.
pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(PathBuf::from)
        .unwrap_or_default()
}

/// Builds the MCU image (profile `mcu`, thumbv7em-none-eabihf) and returns the ELF's path.
///
/// It builds into `target/cross`, apart from the host build that runs the tests, so the two
/// never wait on each other's lock. A fresh toolchain lacks the target; adding it is
/// idempotent and quick once present.
pub fn build_mcu_firmware() -> PathBuf {
    let _ = Command::new("rustup")
        .args(["target", "add", "thumbv7em-none-eabihf"])
        .status();
    let dir = cargo_build(
        "cross",
        &[
            "--profile",
            "mcu",
            "-p",
            "firmware",
            "--target",
            "thumbv7em-none-eabihf",
        ],
    );
    dir.join("thumbv7em-none-eabihf/mcu/firmware")
}

/// `cargo build ARGS` into `target/DIR` (a target directory of its own, so that the build does
/// not wait for the lock of the one running the tests); returns that directory. The release
/// profile unless ARGS name another.
fn cargo_build(dir: &str, args: &[&str]) -> PathBuf {
    let target_dir = workspace_root().join("target").join(dir);
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(cargo)
        .current_dir(workspace_root())
        .arg("build")
        .args(if args.contains(&"--profile") {
            &[][..]
        } else {
            &["--release"][..]
        })
        .args(args)
        .env("CARGO_TARGET_DIR", &target_dir)
        .status()
        .expect("cargo runs");
    assert!(status.success(), "cargo build {args:?} failed");
    target_dir
}

/// Whether an external tool is installed. Under CI (`CI` set) a missing tool is an error, so a
/// test that needs it can never pass by being skipped there.
pub fn tool_available(name: &str) -> bool {
    let found = Command::new(name)
        .arg("--version")
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    required(found, name, "")
}

/// Whether python3 with pymavlink is here: false (skipped) outside CI, a failure under CI.
pub fn pymavlink_available() -> bool {
    if !tool_available("python3") {
        return false;
    }
    let have = Command::new("python3")
        .args(["-c", "import pymavlink"])
        .status()
        .is_ok_and(|s| s.success());
    required(have, "pymavlink", " (pip install pymavlink)")
}

/// `found`, after failing under CI where `what` is missing, or telling that the test is
/// skipped (with how to install it, `install`) outside it.
fn required(found: bool, what: &str, install: &str) -> bool {
    if !found {
        assert!(
            std::env::var_os("CI").is_none(),
            "{what} is required under CI (.ci/run installs it)"
        );
        eprintln!("SKIPPED: {what} is not installed{install}");
    }
    found
}

/// Builds `sim-host` (release) with its `mcu-libm` feature, the host build computing sines,
/// arctangents and exponentials with the libm crate as the MCU image does, into
/// `target/mcu-libm`; returns the binary's path.
pub fn build_sim_host_with_mcu_libm() -> PathBuf {
    cargo_build("mcu-libm", &["-p", "sim-host", "--features", "mcu-libm"]).join("release/sim-host")
}

/// A child process (QEMU, a station) ended with the test that started it, however the test
/// ends.
pub struct Kill(pub std::process::Child);

impl Drop for Kill {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// QEMU started by `command` (sim-host's `QemuConfig::command`, given the two addresses) with
/// its two USARTs on fresh loopback listeners and its standard streams closed; the listeners
/// (USART1, USART2) wait for it to connect.
pub fn spawn_qemu(
    command: impl FnOnce(std::net::SocketAddr, std::net::SocketAddr) -> Command,
) -> (Kill, std::net::TcpListener, std::net::TcpListener) {
    use std::process::Stdio;
    let sim = std::net::TcpListener::bind("127.0.0.1:0").expect("sim listener");
    let gcs = std::net::TcpListener::bind("127.0.0.1:0").expect("gcs listener");
    let addr = |l: &std::net::TcpListener| l.local_addr().expect("a bound address");
    let child = command(addr(&sim), addr(&gcs))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("qemu starts");
    (Kill(child), sim, gcs)
}

/// The flight logs in an MCU image's storage file (its six log sectors of 128 KiB after the
/// record's two of 16 KiB: `firmware/src/mcu/flash.rs`), as `common::storage::flight_log`
/// finds them, each with its bytes.
pub fn flash_logs(
    storage: &std::path::Path,
) -> Vec<(common::storage::flight_log::LogInfo, Vec<u8>)> {
    use common::storage::flight_log::{read, scan, LogRegion};
    /// The file's log sectors, read only.
    struct Image(Vec<u8>);
    impl common::storage::Flash for Image {
        type Error = ();
        fn erase_sector(&mut self, _: u32) -> Result<(), ()> {
            Err(())
        }
        fn write(&mut self, _: u32, _: &[u8]) -> Result<(), ()> {
            Err(())
        }
        fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), ()> {
            let from = addr as usize;
            let src = self.0.get(from..from + buf.len()).ok_or(())?;
            buf.copy_from_slice(src);
            Ok(())
        }
    }
    let file = std::fs::read(storage).expect("the storage file");
    let mut image = Image(file.get(32 * 1024..).unwrap_or(&[]).to_vec());
    image.0.resize(768 * 1024, 0xff);
    let region = LogRegion {
        start: 0,
        sector_len: 128 * 1024,
        sectors: 6,
    };
    let (logs, _) = scan(&mut image, &region).expect("the log sectors scan");
    logs.iter()
        .map(|l| {
            let mut bytes = vec![0u8; l.bytes as usize];
            let n = read(&mut image, &region, l, 0, &mut bytes).expect("the log reads");
            bytes.truncate(n);
            (*l, bytes)
        })
        .collect()
}
