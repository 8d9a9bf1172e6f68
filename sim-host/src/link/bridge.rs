//! The ground bridge: a UART's byte stream to UDP, one MAVLink frame per datagram.
//!
//! The MCU image speaks to the ground over USART2, a byte stream. Ground stations on UDP
//! (QGroundControl, MAVSDK, pymavlink, the scripted station) expect what the SITL build's
//! ground link sends: whole frames, one per datagram. The bridge cuts the stream into frames
//! with `common`'s parser and sends each to a fixed remote (QGroundControl listens on
//! 127.0.0.1:14550) and to every station that has sent a datagram, as the SITL build does
//! ([`firmware::sitl::GcsUdp`]); every datagram from a station goes to the UART as it came.
//!
//! Two threads, one per direction, so a station's command reaches the UART while a burst of
//! telemetry is on its way out.

use common::link::framing::{encode_v2, FrameParser, LinkStats};
use firmware::sitl::{timed_out, MAX_GCS_PEERS};
use mavlink::dialects::common::MavMessage;
use mavlink::{MAVLinkV1MessageRaw, MavlinkVersion};
use std::collections::BTreeMap;
use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpStream, UdpSocket};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

/// How often each thread looks at the stop flag.
const POLL: Duration = Duration::from_millis(50);

/// Counters of the bridge.
#[derive(Default)]
struct Counters {
    to_stations: AtomicU64,
    to_uart: AtomicU64,
}

/// What the bridge has carried.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BridgeStats {
    /// Frames from the UART sent to the stations.
    pub frames_to_stations: u64,
    /// Datagrams from stations written to the UART.
    pub datagrams_to_uart: u64,
    /// Framing counters of the UART's stream.
    pub uart: LinkStats,
}

/// A running bridge; it stops when dropped or when the UART's stream closes.
pub struct GroundBridge {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    counters: Arc<Counters>,
    uart_stats: Arc<Mutex<LinkStats>>,
    named: Arc<Mutex<BTreeMap<String, i32>>>,
    threads: Vec<JoinHandle<()>>,
}

impl GroundBridge {
    /// Bridges `uart` and `socket`: frames from the UART to `remote` (if any) and to every
    /// station that speaks to `socket`.
    pub fn start(
        uart: TcpStream,
        socket: UdpSocket,
        remote: Option<SocketAddr>,
    ) -> io::Result<Self> {
        let addr = socket.local_addr()?;
        let stop = Arc::new(AtomicBool::new(false));
        let counters = Arc::new(Counters::default());
        let uart_stats = Arc::new(Mutex::new(LinkStats::default()));
        let peers = Arc::new(Mutex::new(Vec::<SocketAddr>::new()));
        let named = Arc::new(Mutex::new(BTreeMap::new()));
        uart.set_read_timeout(Some(POLL))?;
        socket.set_read_timeout(Some(POLL))?;
        let (uart_in, mut uart_out) = (uart.try_clone()?, uart);
        let (sock_in, sock_out) = (socket.try_clone()?, socket);

        let down = {
            let (stop, counters, stats, peers, named) = (
                stop.clone(),
                counters.clone(),
                uart_stats.clone(),
                peers.clone(),
                named.clone(),
            );
            let mut uart = uart_in;
            std::thread::spawn(move || {
                let mut parser = FrameParser::new();
                let mut buf = [0u8; 4096];
                while !stop.load(Ordering::Relaxed) {
                    let n = match uart.read(&mut buf) {
                        Ok(0) => break,
                        Ok(n) => n,
                        Err(e) if timed_out(&e) || e.kind() == io::ErrorKind::Interrupted => {
                            continue
                        }
                        Err(_) => break,
                    };
                    let to: Vec<SocketAddr> = remote
                        .iter()
                        .copied()
                        .chain(
                            peers
                                .lock()
                                .unwrap_or_else(|p| p.into_inner())
                                .iter()
                                .copied(),
                        )
                        .collect();
                    parser.push(&buf[..n], |f| {
                        if let MavMessage::NAMED_VALUE_INT(v) = &f.message {
                            if let Ok(name) = v.name.to_str() {
                                named
                                    .lock()
                                    .unwrap_or_else(|p| p.into_inner())
                                    .insert(name.to_string(), v.value);
                            }
                        }
                        let frame = match f.version {
                            MavlinkVersion::V2 => {
                                encode_v2(f.header, &f.message).raw_bytes().to_vec()
                            }
                            MavlinkVersion::V1 => {
                                let mut raw = MAVLinkV1MessageRaw::new();
                                raw.serialize_message(f.header, &f.message);
                                raw.raw_bytes().to_vec()
                            }
                        };
                        counters.to_stations.fetch_add(1, Ordering::Relaxed);
                        for a in &to {
                            // A station that went away is not the bridge's concern.
                            let _ = sock_out.send_to(&frame, a);
                        }
                    });
                    *stats.lock().unwrap_or_else(|p| p.into_inner()) = parser.stats();
                }
            })
        };
        let up = {
            let (stop, counters) = (stop.clone(), counters.clone());
            std::thread::spawn(move || {
                let mut buf = [0u8; 2048];
                while !stop.load(Ordering::Relaxed) {
                    let (n, from) = match sock_in.recv_from(&mut buf) {
                        Ok(r) => r,
                        Err(e) if timed_out(&e) || e.kind() == io::ErrorKind::Interrupted => {
                            continue
                        }
                        // ICMP from an earlier send to a station that has gone.
                        Err(e) if e.kind() == io::ErrorKind::ConnectionRefused => continue,
                        Err(_) => break,
                    };
                    {
                        let mut p = peers.lock().unwrap_or_else(|p| p.into_inner());
                        if Some(from) != remote && !p.contains(&from) && p.len() < MAX_GCS_PEERS {
                            p.push(from);
                        }
                    }
                    counters.to_uart.fetch_add(1, Ordering::Relaxed);
                    if uart_out.write_all(&buf[..n]).is_err() {
                        break;
                    }
                }
            })
        };
        Ok(Self {
            addr,
            stop,
            counters,
            uart_stats,
            named,
            threads: vec![down, up],
        })
    }

    /// Where ground stations send their frames.
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// The last value of each NAMED_VALUE_INT the image has sent (its figures of itself:
    /// `firmware`'s `mcu/budget.rs`).
    pub fn named_values(&self) -> BTreeMap<String, i32> {
        self.named.lock().unwrap_or_else(|p| p.into_inner()).clone()
    }

    /// What the bridge has carried so far.
    pub fn stats(&self) -> BridgeStats {
        BridgeStats {
            frames_to_stations: self.counters.to_stations.load(Ordering::Relaxed),
            datagrams_to_uart: self.counters.to_uart.load(Ordering::Relaxed),
            uart: *self.uart_stats.lock().unwrap_or_else(|p| p.into_inner()),
        }
    }
}

impl Drop for GroundBridge {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use common::link::framing::Sender;
    use mavlink::dialects::common::{MavMessage, HEARTBEAT_DATA, STATUSTEXT_DATA};
    use std::net::TcpListener;

    #[test]
    fn each_frame_of_the_uart_goes_out_in_a_datagram_of_its_own_and_each_datagram_to_the_uart() {
        let listener = TcpListener::bind("127.0.0.1:0").expect("listener");
        let mut uart = TcpStream::connect(listener.local_addr().expect("addr")).expect("uart");
        let (bridged, _) = listener.accept().expect("accept");
        let socket = UdpSocket::bind("127.0.0.1:0").expect("socket");
        let bridge = GroundBridge::start(bridged, socket, None).expect("bridge");
        let station = UdpSocket::bind("127.0.0.1:0").expect("station");
        station
            .set_read_timeout(Some(Duration::from_secs(2)))
            .expect("timeout");

        // The station speaks first (so the bridge knows it); its datagram reaches the UART.
        let mut gcs = Sender::new(255, 190);
        let hello = gcs.encode(&MavMessage::HEARTBEAT(HEARTBEAT_DATA::default()));
        station
            .send_to(hello.raw_bytes(), bridge.local_addr())
            .expect("send");
        let mut got = vec![0u8; hello.raw_bytes().len()];
        uart.read_exact(&mut got)
            .expect("the UART hears the station");
        assert_eq!(got, hello.raw_bytes());

        // Three frames from the autopilot, cut anywhere, with noise between two of them.
        let mut ap = Sender::new(common::gcs::SYSTEM_ID, common::gcs::COMPONENT_ID);
        let frames: Vec<Vec<u8>> = ["one", "two", "three"]
            .iter()
            .map(|t| {
                let m = MavMessage::STATUSTEXT(STATUSTEXT_DATA {
                    text: (*t).into(),
                    ..Default::default()
                });
                ap.encode(&m).raw_bytes().to_vec()
            })
            .collect();
        let mut stream = frames[0].clone();
        stream.extend_from_slice(&[0x00, 0x42]);
        stream.extend(frames[1..].concat());
        for chunk in [&stream[..1], &stream[1..9], &stream[9..40], &stream[40..]] {
            uart.write_all(chunk).expect("uart write");
            std::thread::sleep(Duration::from_millis(5));
        }
        let mut buf = [0u8; 1024];
        for f in &frames {
            let (n, from) = station.recv_from(&mut buf).expect("a datagram");
            assert_eq!(from, bridge.local_addr());
            assert_eq!(&buf[..n], &f[..], "one whole frame per datagram");
        }
        // The counters follow the datagrams by a moment.
        let end = std::time::Instant::now() + Duration::from_secs(2);
        let mut s = bridge.stats();
        while s.uart.frames_ok < 3 && std::time::Instant::now() < end {
            std::thread::sleep(Duration::from_millis(5));
            s = bridge.stats();
        }
        assert_eq!((s.frames_to_stations, s.datagrams_to_uart), (3, 1));
        assert_eq!(s.uart.bytes_skipped, 2);
    }
}
