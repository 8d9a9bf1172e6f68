//! What the control stages read: the measured state, and the flags that say which of its
//! values (or the command, or the time step) a tick refused.

/// The measured state the autopilot flies on. SI units, radians; body rates in the body frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Measurements {
    /// Roll angle phi, rad.
    pub roll: f32,
    /// Pitch angle theta, rad.
    pub pitch: f32,
    /// Course over ground chi, rad (the heading psi in still air, as the thesis assumes).
    pub course: f32,
    /// Roll rate p, rad/s.
    pub roll_rate: f32,
    /// Pitch rate q, rad/s.
    pub pitch_rate: f32,
    /// Yaw rate r, rad/s.
    pub yaw_rate: f32,
    /// Altitude h, m (any datum, the same as the altitude commands').
    pub altitude: f32,
    /// Airspeed Va, m/s.
    pub airspeed: f32,
    /// Sideslip beta, rad.
    pub sideslip: f32,
}

impl Measurements {
    /// Wings-level, straight flight at this airspeed and altitude, heading north.
    pub fn level(airspeed: f32, altitude: f32) -> Self {
        Self {
            airspeed,
            altitude,
            ..Self::default()
        }
    }
}

/// A set of inputs, as bits: which measurements (or the command, or the time step) were refused.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InputFlags(pub u16);

impl InputFlags {
    /// Roll angle.
    pub const ROLL: Self = Self(1 << 0);
    /// Pitch angle.
    pub const PITCH: Self = Self(1 << 1);
    /// Course.
    pub const COURSE: Self = Self(1 << 2);
    /// Roll rate.
    pub const ROLL_RATE: Self = Self(1 << 3);
    /// Pitch rate.
    pub const PITCH_RATE: Self = Self(1 << 4);
    /// Yaw rate.
    pub const YAW_RATE: Self = Self(1 << 5);
    /// Altitude.
    pub const ALTITUDE: Self = Self(1 << 6);
    /// Airspeed.
    pub const AIRSPEED: Self = Self(1 << 7);
    /// Sideslip.
    pub const SIDESLIP: Self = Self(1 << 8);
    /// A setpoint of the commands.
    pub const COMMAND: Self = Self(1 << 9);
    /// The time step.
    pub const DT: Self = Self(1 << 10);

    /// No flag.
    pub const fn empty() -> Self {
        Self(0)
    }

    /// No flag set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// All flags of `other` are set.
    pub const fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// Sets (`on`) or clears the flags of `other`.
    pub fn set(&mut self, other: Self, on: bool) {
        if on {
            self.0 |= other.0;
        } else {
            self.0 &= !other.0;
        }
    }
}

impl core::ops::BitOr for InputFlags {
    type Output = Self;
    fn bitor(self, rhs: Self) -> Self {
        Self(self.0 | rhs.0)
    }
}

impl core::ops::BitOrAssign for InputFlags {
    fn bitor_assign(&mut self, rhs: Self) {
        self.0 |= rhs.0;
    }
}
