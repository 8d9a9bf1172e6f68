"""MAVLink 2 signing against pymavlink, an implementation independent of this project's.

Usage: pymavlink_signing.py PORT. Talks to the autopilot's ground link on UDP 127.0.0.1:PORT as
a ground station (255/190) and prints one line per check; exits 0 when every check holds:
  1. SETUP_SIGNING (unsigned, while the vehicle has no key) turns signing on;
  2. the vehicle's frames are then signed with the key (pymavlink verifies them);
  3. a signed PARAM_SET is taken (the echo carries the new value);
  4. an unsigned PARAM_SET from a second station is refused (the value stays);
  5. a signed PARAM_SET replayed byte for byte is refused (the value stays).
"""
import time

from station import MAV, check, connect, finish, wait

NAME = b"NAV_LOIT_RAD"
KEY = bytes(range(32))


def drain(m, secs=0.5):
    """Reads what is on its way (echoes of earlier sets), so the next read is a fresh one."""
    end = time.time() + secs
    while time.time() < end:
        m.recv_match(blocking=True, timeout=0.05)


def param_value(m, secs=3.0):
    drain(m)
    m.mav.param_request_read_send(1, 1, NAME, -1)
    v = wait(m, "PARAM_VALUE", lambda p: p.param_id == NAME.decode(), secs)
    return None if v is None else v.param_value


def param_set(m, value):
    m.mav.param_set_send(1, 1, NAME, value, MAV.MAV_PARAM_TYPE_REAL32)


gcs = connect()
check(wait(gcs, "HEARTBEAT") is not None, "the vehicle's heartbeat arrives")
before = param_value(gcs)
check(before is not None, f"{NAME.decode()} reads {before}")

now_10us = int((time.time() - 1420070400) * 100000)
gcs.mav.setup_signing_send(1, 1, list(KEY), now_10us)
gcs.setup_signing(KEY, sign_outgoing=True, initial_timestamp=now_10us)
text = wait(gcs, "STATUSTEXT", lambda t: "Signing on" in t.text)
check(text is not None, "SETUP_SIGNING turns signing on")

hb = wait(gcs, "HEARTBEAT")
check(hb is not None and hb.get_signed(), "the vehicle's frames are signed with the key")

param_set(gcs, 61.0)
check(param_value(gcs) == 61.0, "a signed PARAM_SET is taken")

intruder = connect()
intruder.mav.param_set_send(1, 1, NAME, 77.0, MAV.MAV_PARAM_TYPE_REAL32)
check(param_value(gcs) == 61.0, "an unsigned PARAM_SET is refused")

# A signed frame recorded on the wire and sent again later.
recorded = gcs.mav.param_set_encode(
    1, 1, NAME, 62.0, MAV.MAV_PARAM_TYPE_REAL32
).pack(gcs.mav)
gcs.write(recorded)
check(param_value(gcs) == 62.0, "the recorded frame is taken the first time")
param_set(gcs, 63.0)
check(param_value(gcs) == 63.0, "a newer signed PARAM_SET is taken")
gcs.write(recorded)
check(param_value(gcs) == 63.0, "the replayed frame is refused")

finish()
