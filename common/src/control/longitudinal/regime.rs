//! The regimes of Figure 3-16 and the state machine that picks one from the altitude error,
//! with hysteresis on the band.

/// Flight regime of Figure 3-16.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Regime {
    /// Full throttle, fixed pitch.
    TakeOff,
    /// Full throttle, airspeed by pitch.
    Climb,
    /// Altitude by pitch, airspeed by throttle.
    AltitudeHold,
    /// Zero throttle, airspeed by pitch.
    Descent,
}

/// The regime state machine with hysteresis on the altitude band.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RegimeMachine {
    regime: Option<Regime>,
}

impl RegimeMachine {
    /// A machine with no regime yet; the first update picks one from scratch.
    pub fn new() -> Self {
        Self { regime: None }
    }

    /// The present regime.
    pub fn regime(&self) -> Option<Regime> {
        self.regime
    }

    /// Forgets the regime.
    pub fn reset(&mut self) {
        self.regime = None;
    }

    /// Next regime from the altitude error `error = h_c - h` (m), the altitude `altitude` (m),
    /// the take-off clear altitude (when taking off), the band and its hysteresis (m).
    ///
    /// Take-off is a phase, not a zone: it is entered only when the machine starts below the
    /// clear altitude, and left for good once above it.
    pub fn update(
        &mut self,
        error: f32,
        altitude: f32,
        clear_altitude: Option<f32>,
        band: f32,
        hysteresis: f32,
    ) -> Regime {
        let leave = band + hysteresis.max(0.0);
        let fresh = if error > band {
            Regime::Climb
        } else if error < -band {
            Regime::Descent
        } else {
            Regime::AltitudeHold
        };
        let below_clear = matches!(clear_altitude, Some(c) if altitude < c);
        let next = match self.regime {
            None if below_clear => Regime::TakeOff,
            None => fresh,
            Some(Regime::TakeOff) if below_clear => Regime::TakeOff,
            Some(Regime::TakeOff) => fresh,
            Some(Regime::Climb) => {
                if error < -leave {
                    Regime::Descent
                } else if error < band {
                    Regime::AltitudeHold
                } else {
                    Regime::Climb
                }
            }
            Some(Regime::AltitudeHold) => {
                if error > leave {
                    Regime::Climb
                } else if error < -leave {
                    Regime::Descent
                } else {
                    Regime::AltitudeHold
                }
            }
            Some(Regime::Descent) => {
                if error > leave {
                    Regime::Climb
                } else if error > -band {
                    Regime::AltitudeHold
                } else {
                    Regime::Descent
                }
            }
        };
        self.regime = Some(next);
        next
    }
}
