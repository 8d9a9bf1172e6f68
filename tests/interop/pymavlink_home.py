"""Home as a ground station reads it: set once on the ground, held in the datum it was set in.

Usage: pymavlink_home.py PORT. The vehicle sits on the runway with a GPS fix. Connected as a
ground station (255/190), the script arms it (which sets home where it stands, as PX4 does) and
then reads HOME_POSITION and GLOBAL_POSITION_INT for 20 s while the estimator keeps learning its
barometer's offset from GPS. Checks:
  1. HOME_POSITION arrives once armed, and every HOME_POSITION after it is the same point and
     the same altitude, to the millimetre;
  2. GLOBAL_POSITION_INT's altitude above sea level less its height above home is home's
     altitude (one datum for the aircraft and for home), within a millimetre of rounding;
  3. its height above home stays within the barometer's noise of zero (the aircraft is at rest).
"""
import time

from station import MAV, arm, check, command, connect, finish, wait



def home(m):
    command(m, MAV.MAV_CMD_REQUEST_MESSAGE, 242)
    return wait(m, "HOME_POSITION")


m = connect()
check(wait(m, "HEARTBEAT", lambda h: h.get_srcSystem() == 1) is not None, "vehicle heard")
ack = arm(m)
check(ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED, "armed on the ground")
first = home(m)
check(first is not None, "HOME_POSITION once armed")
if first is not None:
    homes, offsets, heights = [], [], []
    end = time.time() + 20
    while time.time() < end:
        h = home(m)
        if h is not None:
            homes.append(h)
        g = wait(m, "GLOBAL_POSITION_INT", secs=1.0)
        if g is not None:
            offsets.append(g.alt - g.relative_alt - first.altitude)
            heights.append(g.relative_alt)
    moved = [
        (h.latitude - first.latitude, h.longitude - first.longitude, h.altitude - first.altitude)
        for h in homes
    ]
    check(
        len(homes) >= 10 and all(d == (0, 0, 0) for d in moved),
        f"home held: {len(homes)} reads, largest change {max((abs(d[2]) for d in moved), default=None)} mm",
    )
    check(
        len(offsets) >= 10 and all(abs(o) <= 1 for o in offsets),
        f"alt - relative_alt is home's altitude (offsets {min(offsets, default=0)}..{max(offsets, default=0)} mm)",
    )
    check(
        len(heights) >= 10 and all(abs(z) < 300 for z in heights),
        f"height above home within 0.3 m at rest ({min(heights, default=0)}..{max(heights, default=0)} mm)",
    )
command(m, MAV.MAV_CMD_COMPONENT_ARM_DISARM, 0)
finish()
