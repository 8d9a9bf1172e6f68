//! The modes the vehicle can fly, and what each mode asks of it.

/// A mode the autopilot can fly.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FlightMode {
    /// Stick inputs straight to the surfaces (PX4 MANUAL).
    #[default]
    Manual,
    /// Roll and pitch held by the inner loops, sticks command attitude (PX4 STABILIZED).
    Stabilized,
    /// Altitude and airspeed held, roll from the stick (PX4 ALTCTL).
    Altitude,
    /// The thesis's heading/altitude/airspeed hold: course, altitude and airspeed held by the
    /// outer loops, sticks nudge the set points (PX4 POSCTL).
    Hold,
    /// Fly the uploaded mission (PX4 AUTO.MISSION).
    Mission,
    /// Circle the current point (PX4 AUTO.LOITER).
    Loiter,
    /// Return to home and circle there (PX4 AUTO.RTL).
    Return,
    /// Climb out to a safe altitude (PX4 AUTO.TAKEOFF).
    Takeoff,
    /// Land (PX4 AUTO.LAND).
    Land,
}

impl FlightMode {
    /// Every mode, in the order `AVAILABLE_MODES` lists them (its `mode_index` is this
    /// position plus one).
    pub const ALL: [FlightMode; 9] = [
        FlightMode::Manual,
        FlightMode::Stabilized,
        FlightMode::Altitude,
        FlightMode::Hold,
        FlightMode::Mission,
        FlightMode::Loiter,
        FlightMode::Return,
        FlightMode::Takeoff,
        FlightMode::Land,
    ];

    /// Name shown by ground stations (`AVAILABLE_MODES.mode_name`, STATUSTEXT).
    pub const fn name(self) -> &'static str {
        match self {
            FlightMode::Manual => "Manual",
            FlightMode::Stabilized => "Stabilized",
            FlightMode::Altitude => "Altitude",
            FlightMode::Hold => "Hold",
            FlightMode::Mission => "Mission",
            FlightMode::Loiter => "Loiter",
            FlightMode::Return => "Return",
            FlightMode::Takeoff => "Takeoff",
            FlightMode::Land => "Land",
        }
    }

    /// Whether the mode needs a position estimate (GPS) to be flown: the navigator's modes
    /// and Hold, which holds a course over ground.
    pub const fn needs_position(self) -> bool {
        self.needs_navigator() || matches!(self, FlightMode::Hold)
    }

    /// Whether the navigator flies this mode (a path, not a set point): the modes in which
    /// the vehicle chooses its own path.
    pub const fn needs_navigator(self) -> bool {
        self.auto()
    }

    /// Whether the outer loops hold the vehicle (heartbeat STABILIZE flag).
    pub const fn stabilized(self) -> bool {
        !matches!(self, FlightMode::Manual)
    }

    /// Whether sticks drive the vehicle (heartbeat MANUAL_INPUT flag).
    pub const fn manual_input(self) -> bool {
        matches!(
            self,
            FlightMode::Manual | FlightMode::Stabilized | FlightMode::Altitude | FlightMode::Hold
        )
    }

    /// Whether the vehicle chooses its own path (heartbeat AUTO flag).
    pub const fn auto(self) -> bool {
        matches!(
            self,
            FlightMode::Mission
                | FlightMode::Loiter
                | FlightMode::Return
                | FlightMode::Takeoff
                | FlightMode::Land
        )
    }

    /// Bit of this mode in a [`ModeSet`].
    const fn bit(self) -> u16 {
        1 << (self as u16)
    }
}

/// A set of modes: which modes the vehicle can fly right now.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ModeSet(pub u16);

impl ModeSet {
    /// No mode.
    pub const EMPTY: ModeSet = ModeSet(0);
    /// Every mode.
    pub const ALL: ModeSet = ModeSet((1 << FlightMode::ALL.len()) - 1);
    /// Modes that need no position estimate.
    pub const WITHOUT_POSITION: ModeSet = ModeSet(
        FlightMode::Manual.bit() | FlightMode::Stabilized.bit() | FlightMode::Altitude.bit(),
    );

    /// Whether `mode` is in the set.
    pub const fn contains(self, mode: FlightMode) -> bool {
        self.0 & mode.bit() != 0
    }

    /// The set with `mode` added.
    pub const fn with(self, mode: FlightMode) -> ModeSet {
        ModeSet(self.0 | mode.bit())
    }

    /// The set with `mode` removed.
    pub const fn without(self, mode: FlightMode) -> ModeSet {
        ModeSet(self.0 & !mode.bit())
    }
}
