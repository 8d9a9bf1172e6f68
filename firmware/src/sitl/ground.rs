//! The ground port: the ground-station link over UDP, one channel per station.

use crate::app::App;
use common::gcs::Dest;
use std::io;
use std::net::{SocketAddr, ToSocketAddrs, UdpSocket};
use std::time::{Duration, Instant};

/// The ground-station link over UDP: telemetry to a fixed remote (QGroundControl listens on
/// 14550) and to every station that has sent us a frame lately (MAVSDK, pymavlink, test
/// clients). Each station has its own channel: the fixed remote 0, the others 1 to
/// [`MAX_GCS_PEERS`]; answers go back only to the station that asked, telemetry to all.
pub struct GcsUdp {
    socket: UdpSocket,
    remote: Option<SocketAddr>,
    /// Stations that spoke first, with when each was last heard.
    peers: [Option<(SocketAddr, Instant)>; MAX_GCS_PEERS],
}

/// Most stations besides the fixed remote a SITL link serves at once; a new one takes the
/// place of the one heard longest ago.
pub const MAX_GCS_PEERS: usize = 8;
/// A station silent this long is forgotten (QGroundControl sends a heartbeat every second).
pub const PEER_TIMEOUT: Duration = Duration::from_secs(10);

impl GcsUdp {
    /// Binds `bind` and sends to `remote` as well as to whoever speaks.
    pub fn open(bind: &str, remote: Option<&str>) -> io::Result<Self> {
        let socket = UdpSocket::bind(bind)?;
        socket.set_nonblocking(true)?;
        let remote = match remote {
            Some(r) => r.to_socket_addrs()?.next(),
            None => None,
        };
        Ok(Self {
            socket,
            remote,
            peers: [None; MAX_GCS_PEERS],
        })
    }

    /// The bound address.
    pub fn local_addr(&self) -> io::Result<SocketAddr> {
        self.socket.local_addr()
    }

    /// The channel of a station that sent a datagram at `now`: the fixed remote's, its own,
    /// a free one, or the one of the station heard longest ago.
    fn channel_of(&mut self, from: SocketAddr, now: Instant) -> u8 {
        if Some(from) == self.remote {
            return 0;
        }
        let slot = self
            .peers
            .iter()
            .position(|p| p.is_some_and(|(a, _)| a == from))
            .or_else(|| {
                self.peers.iter().position(|p| {
                    p.is_none_or(|(_, heard)| now.duration_since(heard) > PEER_TIMEOUT)
                })
            })
            .unwrap_or_else(|| {
                let heard = |i: &usize| self.peers.get(*i).copied().flatten().map(|(_, h)| h);
                (0..MAX_GCS_PEERS).min_by_key(heard).unwrap_or(0)
            });
        if let Some(p) = self.peers.get_mut(slot) {
            *p = Some((from, now));
        }
        slot as u8 + 1
    }

    /// Takes every waiting datagram into the autopilot, then sends its answers.
    pub fn service(&mut self, app: &mut App) -> io::Result<()> {
        self.receive(app)?;
        self.flush(app);
        Ok(())
    }

    /// Hands every datagram waiting to the autopilot, each on its station's channel.
    pub fn receive(&mut self, app: &mut App) -> io::Result<()> {
        let mut buf = [0u8; 2048];
        loop {
            match self.socket.recv_from(&mut buf) {
                Ok((n, from)) => {
                    let channel = self.channel_of(from, Instant::now());
                    app.on_gcs_datagram(channel, buf.get(..n).unwrap_or(&[]));
                }
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => return Ok(()),
                // A peer that went away makes the next recv report it (ICMP); keep going.
                Err(e) if e.kind() == io::ErrorKind::ConnectionRefused => continue,
                Err(e) => return Err(e),
            }
        }
    }

    /// Sends what the autopilot has for the ground stations, one frame per datagram: to
    /// everyone, or back to the station it answers.
    pub fn flush(&mut self, app: &mut App) {
        app.drain_gcs_to(&mut |dest, frame| self.send(dest, frame));
    }

    /// Sends one frame the autopilot addressed to `dest`: to everyone (the remote and every
    /// station heard lately), or to the stations of one channel (0: the remote).
    pub fn send(&self, dest: Dest, frame: &[u8]) {
        let now = Instant::now();
        let live = |c: usize| {
            self.peers
                .get(c)
                .copied()
                .flatten()
                .filter(|(_, heard)| now.duration_since(*heard) <= PEER_TIMEOUT)
                .map(|(a, _)| a)
        };
        match dest {
            Dest::All => {
                for to in self
                    .remote
                    .into_iter()
                    .chain((0..MAX_GCS_PEERS).filter_map(live))
                {
                    let _ = self.socket.send_to(frame, to);
                }
            }
            Dest::Channel(0) => {
                if let Some(to) = self.remote {
                    let _ = self.socket.send_to(frame, to);
                }
            }
            Dest::Channel(c) => {
                if let Some(to) = live(usize::from(c) - 1) {
                    let _ = self.socket.send_to(frame, to);
                }
            }
        }
    }
}
