"""Ground-station parity against pymavlink, an implementation independent of this project's.

Usage: pymavlink_parity.py PORT. Talks to the autopilot's ground link on UDP 127.0.0.1:PORT as a
ground station (255/190), asks what QGroundControl asks at connection, and prints one line per
check; exits 0 when every check holds:
  1. PROTOCOL_VERSION, by MAV_CMD_REQUEST_PROTOCOL_VERSION and by REQUEST_MESSAGE 300: MAVLink 2;
  2. a status text longer than 50 characters arrives in STATUSTEXT chunks (one id, chunk_seq 0,
     1, ...) that join into the whole text;
  3. PARAM_ERROR for an unknown name and for an out-of-range value, addressed to the asker;
  4. COMPONENT_METADATA (REQUEST_MESSAGE 397) names an mftp:// general file, and pymavlink's own
     MAVLink FTP client downloads it; its CRC is MAVLink's CRC-32 of the bytes;
  5. the parameter metadata it points to downloads, has the CRC general.json gives, inflates
     as xz and parses as QGroundControl's format (version 1, name and type for each);
  6. every parameter the vehicle lists has metadata of its own type, and its value lies within
     the metadata's bounds and equals the default (a vehicle fresh from boot).
"""
import json
import lzma
import struct
import time

from station import MAV, check, connect, finish, wait
from pymavlink import mavftp


def request_message(m, msg_id):
    m.mav.command_long_send(1, 1, MAV.MAV_CMD_REQUEST_MESSAGE, 0, msg_id, 0, 0, 0, 0, 0, 0)


def ack_of(m, command):
    return wait(m, "COMMAND_ACK", lambda a: a.command == command)


def mavlink_crc32(data):
    """MAVLink's CRC-32: reflected 0x04C11DB7, from 0, no final XOR (the devguide's CRC page)."""
    crc = 0
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ (0xEDB88320 if crc & 1 else 0)
    return crc


def raw_payload(m, msg_id, size):
    """The payload of message `msg_id` from its frame, zero-extended to `size` bytes: pymavlink's
    common dialect lacks PROTOCOL_VERSION and COMPONENT_METADATA, so it passes them on as
    UNKNOWN_<id> with the frame's bytes."""
    end = time.time() + 5
    while time.time() < end:
        msg = m.recv_match(type=f"UNKNOWN_{msg_id}", blocking=True, timeout=0.2)
        if msg is None:
            continue
        raw = bytes(msg.get_msgbuf())
        if len(raw) >= 10 and raw[0] == 0xFD and int.from_bytes(raw[7:10], "little") == msg_id:
            return raw[10 : 10 + raw[1]].ljust(size, b"\0")
    return None


def protocol_version(m):
    """PROTOCOL_VERSION (300): version, min_version, max_version."""
    p = raw_payload(m, 300, 22)
    return None if p is None else struct.unpack("<HHH", p[:6])


def component_metadata(m):
    """COMPONENT_METADATA (397): time_boot_ms, file_crc, uri."""
    p = raw_payload(m, 397, 108)
    if p is None:
        return None
    time_boot_ms, file_crc = struct.unpack("<II", p[:8])
    return time_boot_ms, file_crc, p[8:108].split(b"\0")[0].decode()


def ftp_get(m, path):
    """A whole file by pymavlink's FTP client (OpenFileRO, burst reads, gap reads, terminate)."""
    ftp = mavftp.MAVFTP(m, target_system=1, target_component=1)
    got = {}

    def keep(fh):
        got["data"] = fh.read()

    ftp.cmd_get([path], callback=keep)
    ftp.process_ftp_reply("OpenFileRO", timeout=10)
    return got.get("data")


gcs = connect()
check(wait(gcs, "HEARTBEAT") is not None, "the vehicle's heartbeat arrives")

# 1. PROTOCOL_VERSION both ways.
gcs.mav.command_long_send(1, 1, MAV.MAV_CMD_REQUEST_PROTOCOL_VERSION, 0, 1, 0, 0, 0, 0, 0, 0)
a = ack_of(gcs, MAV.MAV_CMD_REQUEST_PROTOCOL_VERSION)
pv = protocol_version(gcs)
check(
    a is not None and a.result == 0 and pv is not None and pv[2] >= 200,
    f"MAV_CMD_REQUEST_PROTOCOL_VERSION: accepted, (version, min, max) {pv}",
)
request_message(gcs, 300)
pv = protocol_version(gcs)
check(pv is not None and pv[0] == 200, f"REQUEST_MESSAGE 300: PROTOCOL_VERSION {pv}")

# 2 and 3. An out-of-range value: PARAM_ERROR, and the reason in a text of several chunks.
gcs.mav.param_set_send(1, 1, b"NAV_LOIT_RAD", 1.0e6, MAV.MAV_PARAM_TYPE_REAL32)
err = wait(gcs, "PARAM_ERROR", lambda e: e.param_id == "NAV_LOIT_RAD")
check(
    err is not None
    and err.error == MAV.MAV_PARAM_ERROR_VALUE_OUT_OF_RANGE
    and (err.target_system, err.target_component) == (255, 190),
    "PARAM_SET out of range: PARAM_ERROR VALUE_OUT_OF_RANGE to the asker",
)
chunks = {}
end = time.time() + 3
while time.time() < end:
    t = gcs.recv_match(type="STATUSTEXT", blocking=True, timeout=0.2)
    if t is None or t.id == 0:
        continue
    chunks.setdefault(t.id, {})[t.chunk_seq] = t.text
    parts = chunks[t.id]
    if len(t.text) < 50:  # the chunk that ends the text
        break
joined = "".join(parts[i] for i in sorted(parts)) if chunks else ""
check(
    chunks and sorted(parts) == list(range(len(parts))) and len(joined) > 50
    and "NAV_LOIT_RAD" in joined,
    f"a long status text arrives in {len(parts) if chunks else 0} chunks: {joined!r}",
)
gcs.mav.param_request_read_send(1, 1, b"NO_SUCH_PARAM", -1)
err = wait(gcs, "PARAM_ERROR", lambda e: e.param_id == "NO_SUCH_PARAM")
check(
    err is not None and err.error == MAV.MAV_PARAM_ERROR_DOES_NOT_EXIST,
    "PARAM_REQUEST_READ of an unknown name: PARAM_ERROR DOES_NOT_EXIST",
)

# 4. Component metadata.
request_message(gcs, 397)
a = ack_of(gcs, MAV.MAV_CMD_REQUEST_MESSAGE)
meta = component_metadata(gcs)
check(a is not None and a.result == 0 and meta is not None, f"COMPONENT_METADATA: {meta}")
request_message(gcs, 148)
av = wait(gcs, "AUTOPILOT_VERSION")
check(
    av is not None and av.capabilities & MAV.MAV_PROTOCOL_CAPABILITY_FTP,
    "AUTOPILOT_VERSION claims MAVLink FTP",
)
general = None
if meta is not None and meta[2].startswith("mftp://"):
    general = ftp_get(gcs, "/" + meta[2][len("mftp://") :].lstrip("/"))
check(
    general is not None and mavlink_crc32(general) == meta[1],
    f"general.json by pymavlink's FTP client, {len(general or b'')} bytes, CRC as announced",
)
entry = None
if general is not None:
    g = json.loads(general)
    entry = next((t for t in g.get("metadataTypes", []) if t.get("type") == 1), None)
    check(g.get("version") == 1 and entry is not None, "general.json lists parameter metadata")

# 5. Parameter metadata.
params_meta = {}
if entry is not None:
    uri = entry["uri"]
    data = ftp_get(gcs, "/" + uri[len("mftp://") :].lstrip("/"))
    check(
        data is not None and mavlink_crc32(data) == entry.get("fileCrc"),
        f"{uri}: {len(data or b'')} bytes, CRC as general.json gives",
    )
    if data is not None:
        doc = json.loads(lzma.decompress(data) if uri.endswith(".xz") else data)
        check(
            doc.get("version") == 1
            and all("name" in p and p.get("type") in ("Float", "Int32") for p in doc["parameters"]),
            f"{len(doc['parameters'])} parameters in QGroundControl's format",
        )
        params_meta = {p["name"]: p for p in doc["parameters"]}

# 6. The vehicle's parameters against their metadata.
gcs.mav.param_request_list_send(1, 1)
values = {}
count = None
end = time.time() + 10
while time.time() < end and (count is None or len(values) < count):
    p = gcs.recv_match(type="PARAM_VALUE", blocking=True, timeout=0.5)
    if p is not None:
        count = p.param_count
        values[p.param_id] = p
problems = []
for name, p in values.items():
    md = params_meta.get(name)
    want = "Float" if p.param_type == MAV.MAV_PARAM_TYPE_REAL32 else "Int32"
    value = p.param_value
    if want == "Int32":
        # The vehicle claims PARAM_ENCODE_BYTEWISE: an integer's bytes travel in the float.
        value = struct.unpack("<i", struct.pack("<f", value))[0]
    if md is None:
        problems.append(f"{name}: no metadata")
    elif md["type"] != want:
        problems.append(f"{name}: type {md['type']}, sent as {want}")
    elif not (md["min"] <= value <= md["max"]):
        problems.append(f"{name}: {value} outside [{md['min']}, {md['max']}]")
    elif abs(value - md["default"]) > 1e-6 * max(1.0, abs(md["default"])):
        problems.append(f"{name}: {value}, default {md['default']}")
check(
    count is not None and len(values) == count and len(params_meta) == count and not problems,
    f"{len(values)} of {count} parameters match their metadata {problems[:3]}",
)

finish()
