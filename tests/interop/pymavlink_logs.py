"""The flight log downloaded as MAVProxy's `log` module and QGroundControl's Log Download page do.

Usage: pymavlink_logs.py PORT LOGDIR. The vehicle sits on the runway with a GPS fix and writes
its logs into LOGDIR. Connected as a ground station (255/190), the script arms it (a log starts)
and, while it is armed:
  1. LOG_REQUEST_LIST lists the log being written;
  2. LOG_REQUEST_DATA downloads it as MAVProxy does (everything, then each gap asked for again)
     and its bytes are the file's first bytes; telemetry (ATTITUDE) keeps its rate meanwhile;
then disarmed (the log is closed):
  3. the list names every log of LOGDIR with its size, oldest first, ids from 1;
  4. the last log downloads whole and is the file byte for byte (a ULog file);
  5. LOG_ERASE empties the list and the folder.
The download rates are printed as "rate armed|ground: N bytes/s".
"""
import os
import sys
import time

from station import MAV, check, connect, finish, wait

LOGDIR = sys.argv[2]


def command(m, cmd, *p):
    p = list(p) + [0] * (7 - len(p))
    m.mav.command_long_send(1, 1, cmd, 0, *p)
    return wait(m, "COMMAND_ACK", lambda a: a.command == cmd)


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
    """The log's bytes, MAVProxy's way; the seconds it took and the ATTITUDE rate meanwhile."""
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
    return data, secs, per_second(attitudes)


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


def files():
    return sorted(f for f in os.listdir(LOGDIR) if f.endswith(".ulg")) if os.path.isdir(LOGDIR) else []


m = connect()
check(wait(m, "HEARTBEAT", lambda h: h.get_srcSystem() == 1) is not None, "vehicle heard")
ack, end = None, time.time() + 30
while time.time() < end:
    ack = command(m, MAV.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    if ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED:
        break
    time.sleep(1.0)
check(ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED, "armed on the ground")
time.sleep(4.0)
before = attitude_rate(m, 3.0)

entries = log_list(m)
check(len(entries) == 1 and entries[0].id == 1 and entries[0].size > 0,
      f"armed: the log being written is listed ({[(e.id, e.size) for e in entries]})")
if entries:
    data, secs, during = download(m, entries[0])
    path = os.path.join(LOGDIR, files()[-1])
    with open(path, "rb") as f:
        on_disk = f.read()
    check(len(data) >= entries[0].size and on_disk[: len(data)] == data,
          f"armed: {len(data)} bytes downloaded, the file's first bytes ({len(on_disk)} on disk now)")
    check(during >= 0.8 * before,
          f"armed: ATTITUDE at {during:.1f}/s during the download, {before:.1f}/s before")
    print(f"rate armed: {len(data) / secs:.0f} bytes/s", flush=True)

command(m, MAV.MAV_CMD_COMPONENT_ARM_DISARM, 0)
time.sleep(1.0)
entries = log_list(m)
on_disk = files()
sizes = [os.path.getsize(os.path.join(LOGDIR, f)) for f in on_disk]
check([e.id for e in entries] == list(range(1, len(on_disk) + 1)) and [e.size for e in entries] == sizes,
      f"disarmed: {len(entries)} logs listed with the sizes of the files {sizes}")
if entries:
    data, secs, _ = download(m, entries[-1])
    with open(os.path.join(LOGDIR, on_disk[-1]), "rb") as f:
        whole = f.read()
    check(data == whole and whole[:7] == b"ULog\x01\x12\x35",
          f"disarmed: the last log downloaded whole, {len(data)} bytes, equal to the file")
    print(f"rate ground: {len(data) / secs:.0f} bytes/s", flush=True)

m.mav.log_erase_send(1, 1)
time.sleep(1.0)
entries = log_list(m)
check(entries == [] and files() == [], f"erased: {len(entries)} listed, {len(files())} files left")
finish()
