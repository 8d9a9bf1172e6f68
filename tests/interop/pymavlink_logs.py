"""The flight log downloaded as MAVProxy's `log` module and QGroundControl's Log Download page do.

Usage: pymavlink_logs.py PORT LOGDIR | image:STORAGE. The vehicle sits on the runway with a GPS
fix and writes its logs into LOGDIR (the SITL build), or into the log sectors of its flash,
which QEMU keeps in the file STORAGE (the MCU image: read here by a reader of this script's own
from the block layout of common/src/storage/flight_log.rs). Connected as a ground station
(255/190), the script arms it (a log starts) and, while it is armed:
  1. LOG_REQUEST_LIST lists the log being written;
  2. LOG_REQUEST_DATA downloads it as MAVProxy does (everything, then each gap asked for again)
     and its bytes are the file's first bytes; telemetry (ATTITUDE) keeps its rate meanwhile;
then disarmed (the log is closed):
  3. the list names every log kept with its size, oldest first, ids from 1;
  4. the last log downloads whole and is the file byte for byte (a ULog file);
  5. pymavlink's MAVLink FTP client (MAVProxy's `ftp` module) lists `/logs` with the same logs
     and sizes, and gets the last log as a file, byte for byte the same;
  6. LOG_ERASE empties the list and the folder (the log sectors).
The download rates are printed as "rate armed|ground: N bytes/s".
"""
import os
import struct
import sys
import time
import zlib

from pymavlink import mavftp
from station import MAV, arm, check, command, connect, finish, wait

WHERE = sys.argv[2]


def image_logs(path):
    """The logs in an MCU storage file: six sectors of 128 KiB after the record's 32 KiB, each
    log from a sector's start in blocks of 512 bytes (magic, log, index, length, spare, CRC-32
    of bytes 4..16 and the payload), oldest (lowest number) first."""
    with open(path, "rb") as f:
        data = f.read()[32 * 1024:].ljust(768 * 1024, b"\xff")
    per_sector, total = 256, 6 * 256

    def block(i):
        b = data[i * 512:(i + 1) * 512]
        magic, log, index, length = struct.unpack_from("<IIIH", b, 0)
        (crc,) = struct.unpack_from("<I", b, 16)
        if magic != 0x4C4F4731 or not 0 < length <= 492:
            return None
        if zlib.crc32(b[4:16] + b[20:20 + length]) != crc:
            return None
        return log, index, b[20:20 + length]

    logs = []
    for sector in range(6):
        first = block(sector * per_sector)
        if first is None or first[1] != 0:
            continue
        out, k = b"", 0
        while k < total:
            b = block((sector * per_sector + k) % total)
            if b is None or b[0] != first[0] or b[1] != k:
                break
            out += b[2]
            k += 1
        logs.append((first[0], out))
    return [b for _, b in sorted(logs)]


def kept():
    """Every log the vehicle keeps, oldest first, as bytes."""
    if WHERE.startswith("image:"):
        return image_logs(WHERE[len("image:"):])
    if not os.path.isdir(WHERE):
        return []
    out = []
    for name in sorted(f for f in os.listdir(WHERE) if f.endswith(".ulg")):
        with open(os.path.join(WHERE, name), "rb") as f:
            out.append(f.read())
    return out



def log_list(m):
    m.mav.log_request_list_send(1, 1, 0, 0xFFFF)
    entries, end = {}, time.time() + 5
    while time.time() < end:
        e = m.recv_match(type="LOG_ENTRY", blocking=True, timeout=0.5)
        if e is None:
            continue
        if e.num_logs == 0:
            return []
        entries[e.id] = e
        if len(entries) == e.num_logs:
            break
    return [entries[k] for k in sorted(entries)]


def download(m, entry):
    """The log's bytes, MAVProxy's way; the seconds it took and the ATTITUDE times meanwhile."""
    got, end_at, attitudes = {}, None, []
    t0 = time.time()
    m.mav.log_request_data_send(1, 1, entry.id, 0, 0xFFFFFFFF)
    last_rx = time.time()
    deadline = t0 + 120
    while time.time() < deadline:
        msg = m.recv_match(type=["LOG_DATA", "ATTITUDE"], blocking=True, timeout=0.2)
        if msg is not None and msg.get_type() == "ATTITUDE":
            attitudes.append(msg.time_boot_ms)
            continue
        if msg is not None and msg.id == entry.id:
            last_rx = time.time()
            got[msg.ofs] = bytes(msg.data[: msg.count])
            if msg.count < 90:
                end_at = msg.ofs + msg.count
        # The first gap, asked for again once the stream has paused.
        at = 0
        while at in got and len(got[at]) > 0:
            at += len(got[at])
        if end_at is not None and at >= end_at:
            break
        if time.time() - last_rx > 0.3:
            m.mav.log_request_data_send(1, 1, entry.id, at, 90 * 50)
            m.mav.heartbeat_send(MAV.MAV_TYPE_GCS, MAV.MAV_AUTOPILOT_INVALID, 0, 0, 0)
            last_rx = time.time()
    secs = time.time() - t0
    m.mav.log_request_end_send(1, 1)
    data, at = b"", 0
    while at in got and len(got[at]) > 0:
        data += got[at]
        at += len(got[at])
    return data, secs, attitudes


def per_second(times_ms):
    """Messages a second of the vehicle's clock, from their time_boot_ms (a backlog read at
    once does not count as a burst)."""
    span = (times_ms[-1] - times_ms[0]) / 1000.0 if len(times_ms) > 1 else 0.0
    return (len(times_ms) - 1) / span if span > 0 else 0.0


def attitude_rate(m, secs):
    times, end = [], time.time() + secs
    while time.time() < end:
        a = m.recv_match(type="ATTITUDE", blocking=True, timeout=0.2)
        if a is not None:
            times.append(a.time_boot_ms)
    return per_second(times)


m = connect()
check(wait(m, "HEARTBEAT", lambda h: h.get_srcSystem() == 1) is not None, "vehicle heard")
ack = arm(m)
check(ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED, "armed on the ground")
time.sleep(4.0)
before = attitude_rate(m, 3.0)

entries = log_list(m)
check(len(entries) == 1 and entries[0].id == 1 and entries[0].size > 0,
      f"armed: the log being written is listed ({[(e.id, e.size) for e in entries]})")
if entries:
    data, secs, times = download(m, entries[0])
    on_disk = (kept() or [b""])[-1]
    # A download of a few seconds at least, to see the telemetry's rate through it: again and
    # again while the first took less (every ATTITUDE is read, by the vehicle's clock).
    spent = secs
    while spent < 3.0:
        _, more, t = download(m, entries[0])
        spent += more
        times += t
    during = per_second(times)
    check(len(data) >= entries[0].size and on_disk[: len(data)] == data,
          f"armed: {len(data)} bytes downloaded, the log's first bytes ({len(on_disk)} kept now)")
    check(during >= 0.8 * before,
          f"armed: ATTITUDE at {during:.1f}/s during the download, {before:.1f}/s before")
    print(f"rate armed: {len(data) / secs:.0f} bytes/s", flush=True)

command(m, MAV.MAV_CMD_COMPONENT_ARM_DISARM, 0)
time.sleep(2.0)
entries = log_list(m)
logs = kept()
sizes = [len(b) for b in logs]
check([e.id for e in entries] == list(range(1, len(logs) + 1)) and [e.size for e in entries] == sizes,
      f"disarmed: {len(entries)} logs listed with the sizes of the logs kept {sizes}")
if entries:
    data, secs, _ = download(m, entries[-1])
    whole = logs[-1]
    check(data == whole and whole[:7] == b"ULog\x01\x12\x35",
          f"disarmed: the last log downloaded whole, {len(data)} bytes, equal to the one kept")
    print(f"rate ground: {len(data) / secs:.0f} bytes/s", flush=True)
    if len(sys.argv) > 3:
        with open(sys.argv[3], "wb") as f:
            f.write(data)

    ftp = mavftp.MAVFTP(m, target_system=1, target_component=1)
    listed = ftp.cmd_list(["/logs"])
    names = [(e.name, e.size_b) for e in (listed.directory_listing or []) if not e.is_dir]
    want = [(f"log_{k + 1}.ulg", n) for k, n in enumerate(sizes)]
    check(sorted(names) == sorted(want), f"FTP: /logs lists {names}")
    got = {}

    def keep(fh):
        got["data"] = fh.read()

    t0 = time.time()
    ftp.cmd_get([f"/logs/log_{len(logs)}.ulg"], callback=keep)
    ftp.process_ftp_reply("OpenFileRO", timeout=30)
    secs = time.time() - t0
    check(got.get("data") == whole, f"FTP: /logs/log_{len(logs)}.ulg is the log, {len(got.get('data') or b'')} bytes")
    print(f"rate ftp: {len(got.get('data') or b'') / secs:.0f} bytes/s", flush=True)

m.mav.log_erase_send(1, 1)
time.sleep(2.0)
entries = log_list(m)
check(entries == [] and kept() == [], f"erased: {len(entries)} listed, {len(kept())} logs left")
finish()
