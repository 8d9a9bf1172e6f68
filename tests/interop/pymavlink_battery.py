"""The battery as pymavlink decodes it, an implementation independent of this project's.

Usage: pymavlink_battery.py PORT. Talks to the autopilot's ground link on UDP 127.0.0.1:PORT as
a ground station (255/190) and prints one line per check; exits 0 when every check holds.

The simulator of the test (tests/tests/ground_station.rs) sends BATTERY_STATUS at 10 Hz for a 3S
LiPo resting at 80 % of its charge: 3 x 4.02 V of open-circuit voltage less 0.35 A through the
pack's 24 mOhm, 12.0516 V at the terminals. What a station must then see:
  1. SYS_STATUS: voltage_battery 12052 mV, current_battery 35 cA, battery_remaining 80 %, the
     battery sensor present, enabled and healthy;
  2. BATTERY_STATUS (asked at 2 Hz with SET_MESSAGE_INTERVAL): the pack voltage in voltages[0]
     and the other cells unknown (UINT16_MAX), a LiPo for every function, the same current and
     charge, state OK, the charge used counting up (0.35 A is 0.1 mAh a second) and a time
     remaining of the charge left over the current (0.8 x 3200 mAh / 0.35 A = 7.3 h).
"""
import time

from station import MAV, check, connect, finish, wait

VOLTAGE_MV = 12052
CURRENT_CA = 35
REMAINING_PCT = 80
TIME_REMAINING_S = 0.8 * 3200 * 3.6 / 0.35

gcs = connect()
check(wait(gcs, "HEARTBEAT") is not None, "the vehicle's heartbeat arrives")

# The monitor averages its first 2 s of readings: take a SYS_STATUS once the pack is known.
s = wait(gcs, "SYS_STATUS", lambda m: m.battery_remaining >= 0, secs=10.0)
check(s is not None, "SYS_STATUS reports a battery")
if s is not None:
    check(
        abs(s.voltage_battery - VOLTAGE_MV) <= 2,
        f"SYS_STATUS voltage_battery {s.voltage_battery} mV, expected {VOLTAGE_MV}",
    )
    check(
        s.current_battery == CURRENT_CA,
        f"SYS_STATUS current_battery {s.current_battery} cA, expected {CURRENT_CA}",
    )
    check(
        abs(s.battery_remaining - REMAINING_PCT) <= 1,
        f"SYS_STATUS battery_remaining {s.battery_remaining} %, expected {REMAINING_PCT}",
    )
    bit = MAV.MAV_SYS_STATUS_SENSOR_BATTERY
    check(
        s.onboard_control_sensors_present & bit
        and s.onboard_control_sensors_enabled & bit
        and s.onboard_control_sensors_health & bit,
        "SYS_STATUS: battery sensor present, enabled and healthy",
    )

gcs.mav.command_long_send(
    1, 1, MAV.MAV_CMD_SET_MESSAGE_INTERVAL, 0, 147, 500_000, 0, 0, 0, 0, 0
)
ack = wait(
    gcs,
    "COMMAND_ACK",
    lambda a: a.command == MAV.MAV_CMD_SET_MESSAGE_INTERVAL,
)
check(
    ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED,
    "BATTERY_STATUS at 2 Hz accepted",
)

first = wait(gcs, "BATTERY_STATUS")
check(first is not None, "BATTERY_STATUS arrives")
if first is not None:
    check(
        abs(first.voltages[0] - VOLTAGE_MV) <= 2
        and all(v == 65535 for v in first.voltages[1:]),
        f"BATTERY_STATUS voltages {list(first.voltages)}: the pack, cells unknown",
    )
    check(
        first.type == MAV.MAV_BATTERY_TYPE_LIPO
        and first.battery_function == MAV.MAV_BATTERY_FUNCTION_ALL,
        "BATTERY_STATUS: a LiPo for every function",
    )
    check(
        first.current_battery == CURRENT_CA,
        f"BATTERY_STATUS current_battery {first.current_battery} cA",
    )
    check(
        abs(first.battery_remaining - REMAINING_PCT) <= 1,
        f"BATTERY_STATUS battery_remaining {first.battery_remaining} %",
    )
    check(
        first.charge_state == MAV.MAV_BATTERY_CHARGE_STATE_OK,
        f"BATTERY_STATUS charge_state {first.charge_state} (OK)",
    )
    check(
        first.current_consumed >= 0 and first.energy_consumed >= 0,
        f"BATTERY_STATUS consumed {first.current_consumed} mAh, {first.energy_consumed} hJ",
    )
    check(
        abs(first.time_remaining - TIME_REMAINING_S) < 0.05 * TIME_REMAINING_S,
        f"BATTERY_STATUS time_remaining {first.time_remaining} s, "
        f"expected {TIME_REMAINING_S:.0f}",
    )
    # 0.35 A for 12 s is 1.2 mAh: the count moves on.
    t0 = time.time()
    later = wait(
        gcs,
        "BATTERY_STATUS",
        lambda b: b.current_consumed > first.current_consumed,
        secs=20.0,
    )
    check(
        later is not None,
        f"the charge used counts up ({first.current_consumed} mAh, then "
        f"{None if later is None else later.current_consumed} mAh "
        f"after {time.time() - t0:.1f} s)",
    )

finish()
