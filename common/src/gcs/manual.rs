//! `MANUAL_CONTROL`: a ground station's sticks as the vehicle's manual input.

use crate::sensors::ManualInput;
use mavlink::dialects::common::MANUAL_CONTROL_DATA;

/// The sticks of a `MANUAL_CONTROL` received at `now_us`, in the vehicle's signs: axes are
/// -1000..1000 on the wire (throttle 0..1000), and `INT16_MAX` marks an axis as unused (read
/// as centred, throttle closed).
pub fn manual_input(d: &MANUAL_CONTROL_DATA, now_us: u64) -> ManualInput {
    let axis = |v: i16| {
        if v == i16::MAX {
            0.0
        } else {
            (f32::from(v) / 1000.0).clamp(-1.0, 1.0)
        }
    };
    ManualInput {
        roll: axis(d.y),
        pitch: -axis(d.x),
        yaw: axis(d.r),
        throttle: axis(d.z).clamp(0.0, 1.0),
        time_us: now_us,
    }
}
