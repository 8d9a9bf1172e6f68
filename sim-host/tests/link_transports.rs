//! The simulator link carries the same frames, bit for bit, over every transport.

use common::link::simlink::{encode_hil_gps, encode_hil_sensor, SensorFrame};
use common::math::geodetic::GeoPoint;
use common::sensors::{BaroSample, GpsFix, ImuSample, PitotSample};
use firmware::app::App;
use firmware::sitl::{self, SimEndpoint};
use mavlink::dialects::common::MavMessage;
use nalgebra::Vector3;
use sim_host::link::lockstep::{LinkError, Lockstep};
use sim_host::link::tlog::{read_tlog, TlogWriter};
use sim_host::link::transport::{Inproc, PtyServer, TcpServer, Transport, UdpServer};
use std::time::Duration;

fn frames(k: u64) -> (u64, Vec<MavMessage>) {
    let t = k * 10_000;
    let s = SensorFrame {
        time_us: t,
        imu: Some(ImuSample {
            accel: Vector3::new(0.5, 0.0, -9.79 + k as f32 * 1e-3),
            gyro: Vector3::new(0.0, 0.01, 0.0),
        }),
        baro: k.is_multiple_of(2).then_some(BaroSample {
            pressure_pa: 100_129.0,
            temperature_c: 14.4,
        }),
        pitot: Some(PitotSample {
            diff_pressure_pa: 175.0,
        }),
        ..Default::default()
    };
    let mut m = vec![MavMessage::HIL_SENSOR(encode_hil_sensor(&s, 100.0))];
    if k.is_multiple_of(20) {
        let fix = GpsFix {
            position: GeoPoint::from_deg(44.7258357, -93.07501316),
            alt_amsl_m: 100.0,
            vel_ned: Vector3::new(17.0, 0.0, 0.0),
            fix_type: 3,
            satellites: 10,
            hdop: 0.8,
        };
        m.push(MavMessage::HIL_GPS(encode_hil_gps(t, &fix)));
    }
    (t, m)
}

fn fly<T: Transport>(t: T, log: &std::path::Path) -> Vec<(u64, Vec<u8>)> {
    let tlog = TlogWriter::create(log).expect("tlog");
    let mut link = Lockstep::new(t, Duration::from_secs(5)).with_tlog(tlog);
    link.wait_for_autopilot(Duration::from_secs(5))
        .expect("the autopilot announces itself");
    for k in 0..200 {
        let (time, msgs) = frames(k);
        let a = link.exchange(time, &msgs).expect("answer");
        assert_eq!(a.time_us, time);
    }
    assert_eq!(link.answered(), 200);
    link.finish().expect("flush");
    read_tlog(&std::fs::read(log).expect("read tlog"))
}

fn assert_same(a: &[(u64, Vec<u8>)], b: &[(u64, Vec<u8>)], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: frame count");
    if let Some(i) = a.iter().zip(b).position(|(x, y)| x != y) {
        panic!("{what}: frame {i} differs: {:?} vs {:?}", a[i], b[i]);
    }
}

fn spawn_firmware(endpoint: SimEndpoint) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        let mut link = sitl::connect(&endpoint, Duration::from_secs(5)).expect("connect");
        let mut app = App::new();
        let _ = sitl::run(link.as_mut(), &mut app, Duration::from_secs(2));
    })
}

#[test]
fn inproc_tcp_udp_and_pty_carry_identical_frames() {
    let dir = tempfile::tempdir().expect("tempdir");
    let inproc = fly(Inproc::new(App::new()), &dir.path().join("inproc.tlog"));
    assert_eq!(
        inproc.len(),
        1 + 200 + 10 + 200,
        "heartbeat, sensor, gps, actuator frames"
    );

    let mut fw = None;
    let tcp = TcpServer::listen("127.0.0.1:0", Duration::from_secs(5), |addr| {
        fw = Some(spawn_firmware(SimEndpoint::Tcp(addr.to_string())));
    })
    .expect("tcp");
    let tcp_log = fly(tcp, &dir.path().join("tcp.tlog"));
    assert_same(&tcp_log, &inproc, "tcp");

    let mut udp = UdpServer::bind("127.0.0.1:0").expect("udp");
    let addr = udp.local_addr().expect("addr");
    let fw_udp = spawn_firmware(SimEndpoint::Udp(addr.to_string()));
    udp.wait_for_peer(Duration::from_secs(5)).expect("peer");
    let udp_log = fly(udp, &dir.path().join("udp.tlog"));
    assert_same(&udp_log, &inproc, "udp");

    let pty = PtyServer::open().expect("pty");
    let fw_pty = spawn_firmware(SimEndpoint::Serial(pty.slave_path().to_path_buf()));
    let pty_log = fly(pty, &dir.path().join("pty.tlog"));
    assert_same(&pty_log, &inproc, "pty");

    drop((fw, fw_udp, fw_pty));
}

#[test]
fn a_silent_autopilot_is_reported_not_waited_for_forever() {
    struct Mute;
    impl Transport for Mute {
        fn send(&mut self, _: &[u8]) -> std::io::Result<()> {
            Ok(())
        }
        fn recv(&mut self, _: &mut [u8], t: Duration) -> std::io::Result<usize> {
            std::thread::sleep(t.min(Duration::from_millis(5)));
            Ok(0)
        }
        fn describe(&self) -> String {
            "mute".into()
        }
    }
    let mut link = Lockstep::new(Mute, Duration::from_millis(100));
    let (t, m) = frames(1);
    match link.exchange(t, &m) {
        Err(LinkError::Silent { frames, .. }) => assert_eq!(frames, 0),
        other => panic!("expected a silent-autopilot error, got {other:?}"),
    }
}
