"""A flight's .tlog as a ground station's log, read by pymavlink's own log reader.

Usage: pymavlink_tlog.py PATH. QGroundControl's replay, MAVExplorer and mavlogdump read a .tlog
through the same format: each frame after its time. Checks:
  1. every record parses (no bad data) and the times never go backwards;
  2. the vehicle (system 1) is there: its heartbeats, a fixed wing, about one a second;
  3. the station (system 255) is there too: its heartbeats and its arming command, and the
     vehicle's COMMAND_ACK accepting it;
  4. the vehicle's telemetry a replay draws: ATTITUDE and GLOBAL_POSITION_INT.
"""
import sys

from station import MAV, check, finish
from pymavlink import mavutil

log = mavutil.mavlink_connection(sys.argv[1], dialect="common")
counts, times, bad = {}, [], 0
arm_sent = arm_acked = fixed_wing = False
while True:
    m = log.recv_match()
    if m is None:
        break
    if m.get_type() == "BAD_DATA":
        bad += 1
        continue
    times.append(m._timestamp)
    key = (m.get_srcSystem(), m.get_type())
    counts[key] = counts.get(key, 0) + 1
    if key == (1, "HEARTBEAT"):
        fixed_wing |= m.type == MAV.MAV_TYPE_FIXED_WING
    if key == (255, "COMMAND_LONG") and m.command == MAV.MAV_CMD_COMPONENT_ARM_DISARM:
        arm_sent = True
    if key == (1, "COMMAND_ACK") and m.command == MAV.MAV_CMD_COMPONENT_ARM_DISARM:
        arm_acked |= m.result == MAV.MAV_RESULT_ACCEPTED
span = times[-1] - times[0] if times else 0.0
check(bad == 0 and len(times) > 100, f"{len(times)} frames, {bad} bad")
check(all(a <= b for a, b in zip(times, times[1:])), "times in order")
hb = counts.get((1, "HEARTBEAT"), 0)
check(fixed_wing and hb >= span - 2, f"vehicle heartbeats (a fixed wing): {hb} over {span:.0f} s")
check(counts.get((255, "HEARTBEAT"), 0) >= span - 2, f"station heartbeats: {counts.get((255, 'HEARTBEAT'), 0)}")
check(arm_sent and arm_acked, "the station's arming command and its ACCEPTED")
check(counts.get((1, "ATTITUDE"), 0) > span and counts.get((1, "GLOBAL_POSITION_INT"), 0) > span / 2,
      f"telemetry: {counts.get((1, 'ATTITUDE'), 0)} ATTITUDE, {counts.get((1, 'GLOBAL_POSITION_INT'), 0)} GLOBAL_POSITION_INT")
finish()
