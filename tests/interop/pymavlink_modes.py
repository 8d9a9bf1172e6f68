"""Mode names and mode changes as pymavlink and MAVProxy see them.

Usage: pymavlink_modes.py PORT. pymavlink names a non-PX4 vehicle's modes from an ArduPilot table
(`Mode(65536)` for this autopilot's words) unless the user gives it a map; the project ships one,
docs/pymavlink/custom_mode_map.json, to be copied to ~/.pymavlink/. This script installs it in a
temporary home, connects as a ground station (255/190) and checks:
  1. the heartbeat's mode is named from the map (MANUAL at boot), and the map lists all nine modes;
  2. `set_mode` with a name from the map (pymavlink sends DO_SET_MODE with the whole custom_mode
     in param2, as MAVProxy's `mode` and QGroundControl's APM-style command do) is ACCEPTED and
     the heartbeat then names the new mode;
  3. PX4's form (main in param2, sub in param3), as MAVSDK sends it, is ACCEPTED too;
  4. an ArduPlane number sent without the map (LOITER = 12) and AUTO without a sub mode are
     FAILED and change nothing;
  5. AVAILABLE_MODES, asked for all at once (param2 0) and one by one (param2 1..9, as
     QGroundControl asks), lists the nine modes with the map's words; Loiter is non-standard
     (the standard's ORBIT is a manual orbit) and Return is SAFE_RECOVERY;
  6. CURRENT_MODE reports the flown mode's word and its standard number;
  7. DO_SET_STANDARD_MODE ORBIT is understood (as Loiter: never FAILED), POSITION_HOLD (which a
     fixed wing must not support) is FAILED.
"""
import json
import os
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
MAP = os.path.join(HERE, "..", "..", "docs", "pymavlink", "custom_mode_map.json")
home = tempfile.mkdtemp()
os.makedirs(os.path.join(home, ".pymavlink"))
shutil.copy(MAP, os.path.join(home, ".pymavlink", "custom_mode_map.json"))
# pymavlink reads the map once, when it is imported, from the user's home.
os.environ["HOME"] = home

from station import MAV, check, connect, finish, wait  # noqa: E402

with open(MAP) as f:
    WORDS = {name: int(word) for word, name in json.load(f)["1"].items()}


def command(m, cmd, *p):
    p = list(p) + [0] * (7 - len(p))
    m.mav.command_long_send(1, 1, cmd, 0, *p)
    return wait(m, "COMMAND_ACK", lambda a: a.command == cmd)


def mode_now(m, name):
    """True once a heartbeat of the vehicle names `name`."""
    hb = wait(m, "HEARTBEAT", lambda h: h.get_srcSystem() == 1 and m.flightmode == name)
    return hb is not None


m = connect()
hb = wait(m, "HEARTBEAT", lambda h: h.get_srcSystem() == 1)
check(hb is not None and m.flightmode == "MANUAL", f"boot mode named MANUAL ({m.flightmode})")
mapping = m.mode_mapping() or {}
check(set(mapping) == set(WORDS), f"pymavlink's mode list is the map's nine ({sorted(mapping)})")

m.set_mode(mapping.get("STABILIZED", 0))
ack = wait(m, "COMMAND_ACK", lambda a: a.command == MAV.MAV_CMD_DO_SET_MODE)
check(ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED, "set_mode(STABILIZED) accepted")
check(mode_now(m, "STABILIZED"), "the heartbeat then names STABILIZED")

ack = command(m, MAV.MAV_CMD_DO_SET_MODE, 1, 2, 0)
check(ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED, "PX4 form main 2 accepted")
check(mode_now(m, "ALTITUDE"), "the heartbeat then names ALTITUDE")

ack = command(m, MAV.MAV_CMD_DO_SET_MODE, 1, 12, 0)
check(ack is not None and ack.result == MAV.MAV_RESULT_FAILED, "ArduPlane LOITER (12) FAILED")
ack = command(m, MAV.MAV_CMD_DO_SET_MODE, 1, 4, 0)
check(ack is not None and ack.result == MAV.MAV_RESULT_FAILED, "AUTO without sub mode FAILED")
check(mode_now(m, "ALTITUDE"), "still ALTITUDE after the refusals")

ack = command(m, MAV.MAV_CMD_REQUEST_MESSAGE, 435, 0)
check(ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED, "AVAILABLE_MODES (all) accepted")
listed = {}
for _ in range(9):
    am = wait(m, "AVAILABLE_MODES", lambda a: a.mode_index not in listed)
    if am is None:
        break
    listed[am.mode_index] = am
check(len(listed) == 9 and all(a.number_modes == 9 for a in listed.values()), "nine modes listed")
by_name = {a.mode_name.upper(): a for a in listed.values()}
check(
    all(by_name.get(n) is not None and by_name[n].custom_mode == w for n, w in WORDS.items()),
    "each listed mode has the map's word",
)
loiter = by_name.get("LOITER")
check(
    loiter is not None and loiter.standard_mode == MAV.MAV_STANDARD_MODE_NON_STANDARD,
    "Loiter is non-standard",
)
ret = by_name.get("RETURN")
check(
    ret is not None and ret.standard_mode == MAV.MAV_STANDARD_MODE_SAFE_RECOVERY,
    "Return is SAFE_RECOVERY",
)
one_by_one = 0
for i in range(1, 10):
    ack = command(m, MAV.MAV_CMD_REQUEST_MESSAGE, 435, i)
    am = wait(m, "AVAILABLE_MODES", lambda a, i=i: a.mode_index == i)
    if ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED and am is not None:
        one_by_one += 1
check(one_by_one == 9, f"AVAILABLE_MODES one by one: {one_by_one} of 9")

command(m, MAV.MAV_CMD_REQUEST_MESSAGE, 436)
cm = wait(m, "CURRENT_MODE")
check(
    cm is not None
    and cm.custom_mode == WORDS["ALTITUDE"]
    and cm.standard_mode == MAV.MAV_STANDARD_MODE_ALTITUDE_HOLD,
    "CURRENT_MODE: ALTITUDE's word, ALTITUDE_HOLD",
)

ack = command(m, MAV.MAV_CMD_DO_SET_STANDARD_MODE, MAV.MAV_STANDARD_MODE_ORBIT)
check(
    ack is not None and ack.result != MAV.MAV_RESULT_FAILED,
    f"standard ORBIT understood as Loiter (result {ack.result if ack else None})",
)
ack = command(m, MAV.MAV_CMD_DO_SET_STANDARD_MODE, MAV.MAV_STANDARD_MODE_POSITION_HOLD)
check(ack is not None and ack.result == MAV.MAV_RESULT_FAILED, "standard POSITION_HOLD FAILED")
finish()
