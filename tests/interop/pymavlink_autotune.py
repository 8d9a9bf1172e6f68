"""The autotune as a QGroundControl user flies it, by pymavlink (an independent MAVLink
implementation) over the autopilot's UDP ground link: the vehicle is `sim-host sim` on the
runway and the firmware's host build on its simulator link, paced faster than real time.

Arguments: the ground link's port, a JSON file of the mission to fly after the autotune
(MISSION_ITEM_INT fields, as a planner wrote them) and the GPS latency to set (s); optionally
how many times longer every wall-clock bound is (default 1: the host build paced ten times
faster than real time; the MCU image in QEMU answers at about real time) and how many of the
mission's items to watch before stopping (default all, to the landing and the disarm).

Checks, in order: heartbeats of a fixed wing; EKF_GPS_DELAY set; armed once the estimator
has converged; MAV_CMD_NAV_TAKEOFF accepted and the aircraft in the air above 50 m; Hold
(MAV_CMD_DO_SET_MODE) accepted and reported in the heartbeat; MAV_CMD_DO_AUTOTUNE_ENABLE
answered IN_PROGRESS, then polled each second of the vehicle's clock as QGroundControl polls,
its progress never going back, until the final COMMAND_ACK: ACCEPTED with progress 100; the
identified roll model read back (ATUN_A_PHI1, ATUN_A_PHI2) within 15 % of the aircraft file's
linearisation at 17 m/s (docs/AUTOTUNE.md: 16.09 1/s and -156.5 1/s^2); the mission uploaded
with the mission protocol (MISSION_COUNT, MISSION_REQUEST_INT, MISSION_ITEM_INT, MISSION_ACK)
and started (MAV_CMD_MISSION_START); every item reached in order; landed and disarmed (or, with items to watch, those items
reached in order and the aircraft still armed in the air).
"""
import json
import sys
import time

from station import MAV, check, connect, finish

# docs/AUTOTUNE.md, "Identified on board against the aircraft file's linearisation at
# 17.0 m/s": the linearised roll damping and aileron power, and the tolerance the autotune's
# test holds the identified ones to.
A_PHI1, A_PHI2, TOLERANCE = 16.09, -156.5, 0.15
# PX4's main mode POSCTL: the autopilot's Hold.
PX4_POSCTL = 3
SCALE = float(sys.argv[4]) if len(sys.argv) > 4 else 1.0
WATCH = int(sys.argv[5]) if len(sys.argv) > 5 else None
# Wall-clock bounds of each stage, s (the host build's flight is paced ten times faster).
ARM_S, CLIMB_S, TUNE_S, MISSION_S, HOLD_S = (s * SCALE for s in (60.0, 30.0, 55.0, 120.0, 10.0))

m = connect()
# JSON has no NaN: a parameter left unset (NaN) is written null.
mission = [{k: float("nan") if v is None else v for k, v in i.items()}
           for i in json.load(open(sys.argv[2]))]
gps_delay = float(sys.argv[3])

# What the station knows of the vehicle, updated from every message it reads.
seen = {"boot_ms": 0, "armed": None, "mode": None, "rel_alt_m": None, "landed": None,
        "reached": [], "texts": []}
last_heartbeat = [0.0]


def heartbeat():
    """The station's own heartbeat, 20 times a wall second: the autopilot's clock runs faster
    than the wall's, and it calls the station lost after 5 s of its own without one."""
    now = time.time()
    if now - last_heartbeat[0] >= 0.05:
        last_heartbeat[0] = now
        m.mav.heartbeat_send(MAV.MAV_TYPE_GCS, MAV.MAV_AUTOPILOT_INVALID, 0, 0, 0)


def note(msg):
    t = msg.get_type()
    if hasattr(msg, "time_boot_ms"):
        seen["boot_ms"] = max(seen["boot_ms"], msg.time_boot_ms)
    if t == "HEARTBEAT" and msg.get_srcSystem() == 1:
        seen["armed"] = bool(msg.base_mode & MAV.MAV_MODE_FLAG_SAFETY_ARMED)
        seen["mode"] = (msg.custom_mode >> 16) & 0xFF
        seen["type"] = msg.type
    elif t == "GLOBAL_POSITION_INT":
        seen["rel_alt_m"] = msg.relative_alt / 1000.0
    elif t == "EXTENDED_SYS_STATE":
        seen["landed"] = msg.landed_state
    elif t == "MISSION_ITEM_REACHED":
        if not seen["reached"] or seen["reached"][-1] != msg.seq:
            seen["reached"].append(msg.seq)
    elif t == "STATUSTEXT":
        seen["texts"].append(msg.text)
        print("text", msg.text, flush=True)


def pump(until, secs, kind=None):
    """Reads (and heartbeats) until `until()` holds, or for `secs` of wall time; returns the
    message of `kind` that made it hold, or whether it held."""
    end = time.time() + secs
    while time.time() < end:
        heartbeat()
        msg = m.recv_match(blocking=True, timeout=0.05)
        if msg is None:
            if kind is None and until(None):
                return True
            continue
        note(msg)
        if kind is None:
            if until(msg):
                return True
        elif msg.get_type() == kind and until(msg):
            return msg
    return None if kind else False


def first(kinds, secs, until=lambda: False):
    """The first message of one of `kinds` within `secs` of wall time, or None (also once
    `until()` holds)."""
    box = []

    def hit(msg):
        if msg is not None and msg.get_type() in kinds:
            box.append(msg)
            return True
        return until()

    pump(hit, secs)
    return box[0] if box else None


def command(cmd, *p, secs=5.0):
    p = list(p) + [0] * (7 - len(p))
    m.mav.command_long_send(1, 1, cmd, 0, *p)
    return pump(lambda a: a.command == cmd, secs, "COMMAND_ACK")


def param(name, secs=5.0):
    m.mav.param_request_read_send(1, 1, name.encode(), -1)
    v = pump(lambda v: v.param_id == name, secs, "PARAM_VALUE")
    return None if v is None else v.param_value


def vehicle_s():
    return seen["boot_ms"] / 1000.0


# Heartbeats of the fixed wing.
hb = pump(lambda msg: msg is not None and msg.get_type() == "HEARTBEAT"
          and msg.get_srcSystem() == 1, 20.0)
check(hb and seen.get("type") == MAV.MAV_TYPE_FIXED_WING, "heartbeat of a fixed wing")

# The GPS receiver's latency, as an operator configures the airframe.
m.mav.param_set_send(1, 1, b"EKF_GPS_DELAY", gps_delay, MAV.MAV_PARAM_TYPE_REAL32)
v = pump(lambda v: v.param_id == "EKF_GPS_DELAY", 5.0, "PARAM_VALUE")
check(v is not None and abs(v.param_value - gps_delay) < 1e-6, "EKF_GPS_DELAY set")

# Armed once the pre-arm checks pass, asked every half second of wall time.
end, ack = time.time() + ARM_S, None
while time.time() < end:
    ack = command(MAV.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    if ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED:
        break
    pump(lambda _: False, 0.5)
check(ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED, "armed")

# QGroundControl's Takeoff action: the runway take-off, then a circle at NAV_RTL_ALT (60 m).
ack = command(MAV.MAV_CMD_NAV_TAKEOFF)
check(ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED, "takeoff accepted")
up = pump(lambda _: seen["landed"] == MAV.MAV_LANDED_STATE_IN_AIR
          and (seen["rel_alt_m"] or 0.0) > 50.0, CLIMB_S)
check(up, f"in the air, {seen['rel_alt_m']} m above home")

# Hold, then a few seconds of the vehicle's clock to level the wings out of the circle.
ack = command(MAV.MAV_CMD_DO_SET_MODE, MAV.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, PX4_POSCTL)
check(ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED, "Hold accepted")
t0 = vehicle_s()
held = pump(lambda _: seen["mode"] == PX4_POSCTL and vehicle_s() > t0 + 5.0, HOLD_S)
check(held, "Hold in the heartbeat")

# The autotune button: the command, then the same command each second of the vehicle's clock
# (QGroundControl polls each second) until a final answer.
ack = command(MAV.MAV_CMD_DO_AUTOTUNE_ENABLE, 1)
check(ack is not None and ack.result == MAV.MAV_RESULT_IN_PROGRESS,
      f"autotune started: {ack and ack.result}")
progress, final, polls = [0], None, 0
end = time.time() + TUNE_S
while time.time() < end and final is None:
    t_poll = vehicle_s() + 1.0
    # An unsolicited final answer may come before the next poll is due.
    a = first(("COMMAND_ACK",), TUNE_S, lambda: vehicle_s() >= t_poll)
    if a is None or a.command != MAV.MAV_CMD_DO_AUTOTUNE_ENABLE:
        polls += 1
        a = command(MAV.MAV_CMD_DO_AUTOTUNE_ENABLE, 1)
    if a is None:
        continue
    if a.result == MAV.MAV_RESULT_IN_PROGRESS:
        progress.append(a.progress)
    else:
        final = a
print(f"autotune: {polls} polls, progress {progress[:3]}...{progress[-3:]}", flush=True)
check(all(b >= a for a, b in zip(progress, progress[1:])), "progress never goes back")
check(final is not None and final.result == MAV.MAV_RESULT_ACCEPTED and final.progress == 100,
      f"autotune ACCEPTED with progress 100: {final}")
# The vehicle's word on it, which may follow the answer.
applied = pump(lambda _: any(t.startswith("Autotune: gains applied") for t in seen["texts"]),
               5.0)
check(applied, "Autotune: gains applied")

# The identified roll model, as QGroundControl's parameter editor reads it.
for name, ref in (("ATUN_A_PHI1", A_PHI1), ("ATUN_A_PHI2", A_PHI2)):
    v = param(name)
    ok = v is not None and abs(v - ref) <= TOLERANCE * abs(ref)
    check(ok, f"{name} {v} within {TOLERANCE:.0%} of the linearisation's {ref}")
for name in ("ATUN_A_THT1", "ATUN_A_THT2", "ATUN_A_THT3", "ATUN_A_V1", "ATUN_A_V2", "RLL_KP"):
    print(name, param(name), flush=True)

# The mission protocol's upload: the count, each item as the vehicle asks for it, its ACK.
m.mav.mission_count_send(1, 1, len(mission), MAV.MAV_MISSION_TYPE_MISSION)
ack, sent = None, set()
end = time.time() + 20.0
while time.time() < end and ack is None:
    msg = first(("MISSION_REQUEST_INT", "MISSION_ACK"), 5.0)
    if msg is None:
        break
    if msg.mission_type != MAV.MAV_MISSION_TYPE_MISSION:
        continue
    if msg.get_type() == "MISSION_ACK":
        ack = msg
    elif msg.seq < len(mission):
        i = mission[msg.seq]
        m.mav.mission_item_int_send(
            1, 1, msg.seq, i["frame"], i["command"], 0, i["autocontinue"],
            i["param1"], i["param2"], i["param3"], i["param4"], i["x"], i["y"], i["z"],
            MAV.MAV_MISSION_TYPE_MISSION)
        sent.add(msg.seq)
check(ack is not None and ack.type == MAV.MAV_MISSION_ACCEPTED and len(sent) == len(mission),
      f"mission of {len(mission)} items uploaded: {ack}")

ack = command(MAV.MAV_CMD_MISSION_START)
check(ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED, "mission started")
if WATCH is None:
    landed = pump(lambda _: seen["armed"] is False
                  and seen["landed"] == MAV.MAV_LANDED_STATE_ON_GROUND, MISSION_S)
    check(seen["reached"] == list(range(len(mission))), f"every item reached: {seen['reached']}")
    check(landed, "landed and disarmed")
else:
    pump(lambda _: len(seen["reached"]) >= WATCH, MISSION_S)
    check(seen["reached"] == list(range(WATCH)), f"items 0 to {WATCH - 1} reached: {seen['reached']}")
    check(seen["armed"] and seen["landed"] == MAV.MAV_LANDED_STATE_IN_AIR, "armed in the air")
print(f"vehicle clock at the end: {vehicle_s():.1f} s", flush=True)
finish()
