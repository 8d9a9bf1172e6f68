//! The modes the vehicle can fly, and what each mode asks of it: one table, [`MODES`], row by
//! mode, that every encoding (PX4's `custom_mode`, the standard modes), the availability
//! check, the heartbeat's flags and the commander read. A new mode is a variant and its row;
//! every `match` over the facts is exhaustive, so nothing else compiles until it decides.

use mavlink::dialects::common::{MavModeProperty, MavStandardMode};

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

/// PX4 main mode numbers (`custom_mode` bits 16..23).
pub mod px4_main {
    /// Manual pass-through.
    pub const MANUAL: u8 = 1;
    /// Altitude control.
    pub const ALTCTL: u8 = 2;
    /// Position control.
    pub const POSCTL: u8 = 3;
    /// Automatic; the sub mode says which.
    pub const AUTO: u8 = 4;
    /// Rate control (not flown by this autopilot).
    pub const ACRO: u8 = 5;
    /// Offboard setpoints (not flown by this autopilot).
    pub const OFFBOARD: u8 = 6;
    /// Attitude stabilised.
    pub const STABILIZED: u8 = 7;
}

/// PX4 AUTO sub mode numbers (`custom_mode` bits 24..31).
pub mod px4_auto {
    /// Armed on the ground, waiting.
    pub const READY: u8 = 1;
    /// Take-off.
    pub const TAKEOFF: u8 = 2;
    /// Loiter (hold) around the current point.
    pub const LOITER: u8 = 3;
    /// Fly the mission.
    pub const MISSION: u8 = 4;
    /// Return to launch.
    pub const RTL: u8 = 5;
    /// Land.
    pub const LAND: u8 = 6;
}

/// What the estimate must offer before a mode may be entered (`AVAILABLE_MODES`, the
/// refusal of a mode change).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Needs {
    /// Nothing: flyable from power-up.
    Nothing,
    /// An attitude estimate (converged, or valid enough to hold the wings level).
    Attitude,
    /// A position estimate (a course over ground to hold).
    Position,
    /// A position estimate and a home (every path the navigator flies is anchored on it).
    PositionAndHome,
}

/// What the navigator flies in a mode, and so how it is started when the mode is entered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum NavTask {
    /// The uploaded mission, from its current item.
    Mission,
    /// A circle around the point where the mode was entered.
    Loiter,
    /// Home, then circle there or land as the parameters say.
    Return,
    /// Home, then land.
    Land,
    /// The take-off item: climb out along the present heading.
    Takeoff,
}

/// What the autopilot is asked in a mode: the commands it stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Commanded {
    /// The sticks straight to the surfaces; no loop closed.
    Surfaces,
    /// Roll and pitch from the sticks, throttle from the stick.
    Attitude,
    /// Wings level, altitude and airspeed held at the set points.
    Altitude,
    /// Course, altitude and airspeed held at the set points.
    Course,
    /// What the navigator's guidance commands for its task.
    Navigator(NavTask),
}

/// Everything a mode is, in one row: how the link names it, what it needs, what it flies.
#[derive(Clone, Copy, Debug)]
pub struct ModeFacts {
    /// The mode the row describes (rows are in [`FlightMode::ALL`]'s order).
    pub mode: FlightMode,
    /// Name shown by ground stations (`AVAILABLE_MODES.mode_name`, STATUSTEXT).
    pub name: &'static str,
    /// PX4 (main, sub) mode numbers of the heartbeat's `custom_mode`.
    pub px4: (u8, u8),
    /// PX4's navigation state (`vehicle_status.nav_state`), which the flight log records and
    /// Flight Review names the mode by.
    pub px4_nav_state: u8,
    /// The standard-modes number, `NON_STANDARD` for modes the standard does not name.
    pub standard: MavStandardMode,
    /// `AVAILABLE_MODES.properties`.
    pub properties: MavModeProperty,
    /// What the estimate must offer for the mode to be available.
    pub needs: Needs,
    /// What the mode asks of the autopilot.
    pub commands: Commanded,
}

/// The one table of mode facts, in [`FlightMode::ALL`]'s order.
pub const MODES: [ModeFacts; 9] = [
    ModeFacts {
        mode: FlightMode::Manual,
        name: "Manual",
        px4: (px4_main::MANUAL, 0),
        px4_nav_state: 0,
        standard: MavStandardMode::MAV_STANDARD_MODE_NON_STANDARD,
        properties: MavModeProperty::empty(),
        needs: Needs::Nothing,
        commands: Commanded::Surfaces,
    },
    ModeFacts {
        mode: FlightMode::Stabilized,
        name: "Stabilized",
        px4: (px4_main::STABILIZED, 0),
        px4_nav_state: 15,
        standard: MavStandardMode::MAV_STANDARD_MODE_NON_STANDARD,
        properties: MavModeProperty::empty(),
        needs: Needs::Nothing,
        commands: Commanded::Attitude,
    },
    ModeFacts {
        mode: FlightMode::Altitude,
        name: "Altitude",
        px4: (px4_main::ALTCTL, 0),
        px4_nav_state: 1,
        standard: MavStandardMode::MAV_STANDARD_MODE_ALTITUDE_HOLD,
        properties: MavModeProperty::empty(),
        needs: Needs::Attitude,
        commands: Commanded::Altitude,
    },
    ModeFacts {
        mode: FlightMode::Hold,
        name: "Hold",
        px4: (px4_main::POSCTL, 0),
        px4_nav_state: 2,
        // The standard reserves POSITION_HOLD for vehicles that can stop; a fixed wing
        // holding its track and altitude is CRUISE.
        standard: MavStandardMode::MAV_STANDARD_MODE_CRUISE,
        properties: MavModeProperty::empty(),
        needs: Needs::Position,
        commands: Commanded::Course,
    },
    ModeFacts {
        mode: FlightMode::Mission,
        name: "Mission",
        px4: (px4_main::AUTO, px4_auto::MISSION),
        px4_nav_state: 3,
        standard: MavStandardMode::MAV_STANDARD_MODE_MISSION,
        properties: MavModeProperty::MAV_MODE_PROPERTY_AUTO_MODE,
        needs: Needs::PositionAndHome,
        commands: Commanded::Navigator(NavTask::Mission),
    },
    ModeFacts {
        mode: FlightMode::Loiter,
        name: "Loiter",
        px4: (px4_main::AUTO, px4_auto::LOITER),
        px4_nav_state: 4,
        // The standard's ORBIT is a manual, stick-adjusted orbit, and QGroundControl never
        // offers it in its mode menu; PX4 reports its fixed-wing Hold (this Loiter) as
        // non-standard too and takes ORBIT only as an alias (`from_standard`).
        standard: MavStandardMode::MAV_STANDARD_MODE_NON_STANDARD,
        properties: MavModeProperty::MAV_MODE_PROPERTY_AUTO_MODE,
        needs: Needs::PositionAndHome,
        commands: Commanded::Navigator(NavTask::Loiter),
    },
    ModeFacts {
        mode: FlightMode::Return,
        name: "Return",
        px4: (px4_main::AUTO, px4_auto::RTL),
        px4_nav_state: 5,
        standard: MavStandardMode::MAV_STANDARD_MODE_SAFE_RECOVERY,
        properties: MavModeProperty::MAV_MODE_PROPERTY_AUTO_MODE,
        needs: Needs::PositionAndHome,
        commands: Commanded::Navigator(NavTask::Return),
    },
    ModeFacts {
        mode: FlightMode::Takeoff,
        name: "Takeoff",
        px4: (px4_main::AUTO, px4_auto::TAKEOFF),
        px4_nav_state: 17,
        standard: MavStandardMode::MAV_STANDARD_MODE_TAKEOFF,
        properties: MavModeProperty::MAV_MODE_PROPERTY_AUTO_MODE,
        needs: Needs::PositionAndHome,
        commands: Commanded::Navigator(NavTask::Takeoff),
    },
    ModeFacts {
        mode: FlightMode::Land,
        name: "Land",
        px4: (px4_main::AUTO, px4_auto::LAND),
        px4_nav_state: 18,
        standard: MavStandardMode::MAV_STANDARD_MODE_LAND,
        properties: MavModeProperty::MAV_MODE_PROPERTY_AUTO_MODE,
        needs: Needs::PositionAndHome,
        commands: Commanded::Navigator(NavTask::Land),
    },
];

/// Whether each mode's row describes that mode (checked as the crate compiles).
const fn rows_in_place(modes: &[FlightMode]) -> bool {
    match modes.split_first() {
        Some((m, rest)) => m.facts().mode as u8 == *m as u8 && rows_in_place(rest),
        None => true,
    }
}

const _: () = assert!(rows_in_place(&FlightMode::ALL));

/// The modes of `modes` that need no position estimate.
const fn without_position(modes: &[FlightMode]) -> ModeSet {
    match modes.split_first() {
        Some((m, rest)) if m.needs_position() => without_position(rest),
        Some((m, rest)) => without_position(rest).with(*m),
        None => ModeSet::EMPTY,
    }
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

    /// This mode's row of [`MODES`].
    pub const fn facts(self) -> &'static ModeFacts {
        let [manual, stabilized, altitude, hold, mission, loiter, ret, takeoff, land] = &MODES;
        match self {
            FlightMode::Manual => manual,
            FlightMode::Stabilized => stabilized,
            FlightMode::Altitude => altitude,
            FlightMode::Hold => hold,
            FlightMode::Mission => mission,
            FlightMode::Loiter => loiter,
            FlightMode::Return => ret,
            FlightMode::Takeoff => takeoff,
            FlightMode::Land => land,
        }
    }

    /// Name shown by ground stations (`AVAILABLE_MODES.mode_name`, STATUSTEXT).
    pub const fn name(self) -> &'static str {
        self.facts().name
    }

    /// PX4 (main, sub) mode numbers.
    pub const fn px4(self) -> (u8, u8) {
        self.facts().px4
    }

    /// PX4's navigation state of the mode.
    pub const fn px4_nav_state(self) -> u8 {
        self.facts().px4_nav_state
    }

    /// The heartbeat's `custom_mode` in PX4's encoding.
    pub const fn custom_mode(self) -> u32 {
        let (main, sub) = self.px4();
        ((main as u32) << 16) | ((sub as u32) << 24)
    }

    /// The mode a PX4 (main, sub) pair names, if this autopilot flies it.
    pub fn from_px4(main: u8, sub: u8) -> Option<Self> {
        MODES.iter().find(|f| f.px4 == (main, sub)).map(|f| f.mode)
    }

    /// The mode a `custom_mode` word names (PX4 encoding), if this autopilot flies it. The
    /// low 16 bits are unused by the encoding and must be zero.
    pub fn from_custom_mode(custom_mode: u32) -> Option<Self> {
        if custom_mode & 0xffff != 0 {
            return None;
        }
        let main = ((custom_mode >> 16) & 0xff) as u8;
        let sub = ((custom_mode >> 24) & 0xff) as u8;
        Self::from_px4(main, sub)
    }

    /// The standard-modes number, `NON_STANDARD` for modes the standard does not name.
    pub const fn standard(self) -> MavStandardMode {
        self.facts().standard
    }

    /// The mode a standard-mode number names, if this autopilot flies it. ORBIT, which
    /// no mode advertises, is taken as Loiter, as PX4 takes it for its fixed-wing Hold.
    pub fn from_standard(mode: MavStandardMode) -> Option<Self> {
        match mode {
            MavStandardMode::MAV_STANDARD_MODE_NON_STANDARD => None,
            MavStandardMode::MAV_STANDARD_MODE_ORBIT => Some(FlightMode::Loiter),
            _ => MODES.iter().find(|f| f.standard == mode).map(|f| f.mode),
        }
    }

    /// `AVAILABLE_MODES.properties`.
    pub const fn properties(self) -> MavModeProperty {
        self.facts().properties
    }

    /// What the estimate must offer for this mode to be available.
    pub const fn needs(self) -> Needs {
        self.facts().needs
    }

    /// What this mode asks of the autopilot.
    pub const fn commands(self) -> Commanded {
        self.facts().commands
    }

    /// What the navigator flies in this mode, `None` when it does not fly it.
    pub const fn nav_task(self) -> Option<NavTask> {
        match self.commands() {
            Commanded::Navigator(task) => Some(task),
            Commanded::Surfaces | Commanded::Attitude | Commanded::Altitude | Commanded::Course => {
                None
            }
        }
    }

    /// Whether the mode needs a position estimate (GPS) to be flown: the navigator's modes
    /// and Hold, which holds a course over ground.
    pub const fn needs_position(self) -> bool {
        match self.needs() {
            Needs::Position | Needs::PositionAndHome => true,
            Needs::Nothing | Needs::Attitude => false,
        }
    }

    /// Whether the navigator flies this mode (a path, not a set point): the modes in which
    /// the vehicle chooses its own path.
    pub const fn needs_navigator(self) -> bool {
        self.nav_task().is_some()
    }

    /// Whether the mode holds set points the commander keeps (course, altitude, airspeed):
    /// entering one from another mode starts them from where the aircraft is.
    pub const fn holds_setpoints(self) -> bool {
        match self.commands() {
            Commanded::Altitude | Commanded::Course => true,
            Commanded::Surfaces | Commanded::Attitude | Commanded::Navigator(_) => false,
        }
    }

    /// Whether the outer loops hold the vehicle (heartbeat STABILIZE flag).
    pub const fn stabilized(self) -> bool {
        match self.commands() {
            Commanded::Surfaces => false,
            Commanded::Attitude
            | Commanded::Altitude
            | Commanded::Course
            | Commanded::Navigator(_) => true,
        }
    }

    /// Whether sticks drive the vehicle (heartbeat MANUAL_INPUT flag).
    pub const fn manual_input(self) -> bool {
        !self.needs_navigator()
    }

    /// Whether the vehicle chooses its own path (heartbeat AUTO flag).
    pub const fn auto(self) -> bool {
        self.needs_navigator()
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
    pub const WITHOUT_POSITION: ModeSet = without_position(&FlightMode::ALL);

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
