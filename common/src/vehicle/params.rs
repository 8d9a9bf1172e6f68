//! Every parameter the vehicle has, in one registry: each stage's group, in the order a ground
//! station lists them, and the vehicle's own settings.

use crate::control::{autopilot, gains, lateral, longitudinal};
use crate::navigation::{fence, navigator, path_manager, validate};
use crate::param;
use crate::params::declare::Choice;
use crate::params::{independent, Group, ParamDef, Registry};
use crate::{battery, estimator, failsafe, guidance};

/// The vehicle's own settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SystemParams {
    /// Index in [`gains::NAMED`] of the gain set loaded into the control parameters.
    pub gain_set: u8,
    /// What is flown on the simulator's truth instead of the estimate.
    pub use_truth: TruthUse,
}

/// What the vehicle flies on the simulator's truth (HIL_STATE_QUATERNION) instead of its
/// estimate: experiments that measure what estimation costs, never a real aircraft's setting.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TruthUse {
    /// Nothing: everything flies on the estimate.
    Off,
    /// The control loops' measurements (attitude, rates, course, altitude, airspeed).
    Loops,
    /// The landing's flare only: the true height above home and vertical speed, an oracle of
    /// the best any height sensor could give the flare.
    Flare,
}

/// The labels of [`TruthUse`], in its order.
pub const TRUTH_USES: &[&str] = &["Off", "Control loops", "Flare height and sink"];

impl Choice for TruthUse {
    fn from_index(i: u8) -> Option<Self> {
        [Self::Off, Self::Loops, Self::Flare]
            .get(usize::from(i))
            .copied()
    }
    fn index(self) -> u8 {
        self as u8
    }
}

/// Parameters of the vehicle itself.
pub const PARAMS: Group<SystemParams> = Group {
    name: "System",
    params: &[
        param!(
            ParamDef::choice(
                "SYS_GAIN_SET",
                0,
                gains::NAMES,
                "Gain set loaded into the control parameters when this changes",
            ),
            SystemParams => gain_set,
            count
        ),
        param!(
            ParamDef::choice(
                "SIM_USE_TRUTH",
                0,
                TRUTH_USES,
                "Fly on the simulator's truth (HIL_STATE_QUATERNION) instead of the estimator, to measure what estimation costs: the control loops, or the flare's height and sink",
            ),
            SystemParams => use_truth,
            choice
        ),
    ],
    base: || SystemParams {
        gain_set: 0,
        use_truth: TruthUse::Off,
    },
    check: independent,
};

/// Every parameter of the vehicle: the control stages, the estimator, guidance and navigation,
/// the battery monitor, the failsafes, the logger and the vehicle's own settings.
pub const REGISTRY: Registry = &[
    &lateral::PARAMS,
    &longitudinal::PARAMS,
    &longitudinal::tecs::gains::PARAMS,
    &autopilot::PARAMS,
    &estimator::config::PARAMS,
    &estimator::hagl::PARAMS,
    &guidance::PARAMS,
    &path_manager::PARAMS,
    &navigator::params::PARAMS,
    &validate::PARAMS,
    &fence::PARAMS,
    &battery::PARAMS,
    &failsafe::PARAMS,
    &super::land_detector::PARAMS,
    &crate::logger::params::PARAMS,
    &crate::tuning::autotune::params::PARAMS,
    &crate::tuning::autotune::params::IDENTIFIED,
    &PARAMS,
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::ParamStore;

    #[test]
    fn the_registry_is_valid_and_every_name_unique() {
        assert_eq!(ParamStore::validate(REGISTRY), Ok(()));
        let store = ParamStore::new(REGISTRY);
        assert!(store.len() > 100, "{}", store.len());
        assert_eq!(store.load(&PARAMS).gain_set, 0);
    }
}
