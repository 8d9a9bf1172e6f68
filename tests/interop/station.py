"""What the pymavlink scripts of this folder share: a ground station (255/190) on the autopilot's
UDP ground link, the checks and the verdict.

Each script takes the port of the ground link (or, for a log, its path) as its one argument,
prints one line per check and exits 0 when every check holds.
"""
import os
import sys
import time

os.environ["MAVLINK20"] = "1"
from pymavlink import mavutil  # noqa: E402

MAV = mavutil.mavlink
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def connect():
    """A new station (its own UDP port, so its own channel on the vehicle), heard once."""
    m = mavutil.mavlink_connection(
        f"udpout:127.0.0.1:{int(sys.argv[1])}", source_system=255, source_component=190
    )
    m.mav.heartbeat_send(MAV.MAV_TYPE_GCS, MAV.MAV_AUTOPILOT_INVALID, 0, 0, 0)
    return m


def wait(m, kind, cond=lambda msg: True, secs=5.0):
    """The first `kind` message that meets `cond` within `secs`, heartbeats sent meanwhile."""
    end = time.time() + secs
    while time.time() < end:
        msg = m.recv_match(type=kind, blocking=True, timeout=0.2)
        if msg is not None and cond(msg):
            return msg
        m.mav.heartbeat_send(MAV.MAV_TYPE_GCS, MAV.MAV_AUTOPILOT_INVALID, 0, 0, 0)
    return None


def command(m, cmd, *p):
    """COMMAND_LONG to the vehicle; its COMMAND_ACK, or None."""
    p = list(p) + [0] * (7 - len(p))
    m.mav.command_long_send(1, 1, cmd, 0, *p)
    return wait(m, "COMMAND_ACK", lambda a: a.command == cmd)


def arm(m, secs=30.0):
    """Asks to arm once a second until accepted (the pre-arm checks pass as the estimator
    converges) or `secs` pass; the last COMMAND_ACK."""
    ack, end = None, time.time() + secs
    while time.time() < end:
        ack = command(m, MAV.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        if ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED:
            break
        time.sleep(1.0)
    return ack


def finish():
    sys.exit(1 if failures else 0)
