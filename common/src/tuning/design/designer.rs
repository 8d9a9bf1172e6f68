//! The design as a state machine that does a bounded share of the work per call, so that the
//! vehicle can run it between control ticks: [`Designer::step`] evaluates at most
//! [`POINTS_PER_STEP`] points of a loop transfer.
//!
//! The loops are designed inner to outer ([`Loop::ALL`]; the sideslip's only on a model that
//! has one). The attitude loops' gains start at
//! their rule's value and are lowered by 1 % steps ([`GAIN_STEP`], at most [`GAIN_STEPS`])
//! until the phase margin with servo and delay is [`DesignInputs::inner_phase_margin_deg`].
//! The host's design walked the steps down one by one (up to 400 margin computations); here
//! the step is found by bisection over the step index, about 11 margin computations, and it
//! is the same step wherever the margin falls as the gain rises (which the delay makes it do:
//! a higher gain crosses over higher, where the delay takes more phase). Each outer loop's
//! gains follow from the loop inside it in closed form at its rule's natural frequency; where
//! that misses the loop's margins (the lags the rules leave out: the inner loop's integrator,
//! the flight path's lag behind the pitch, the feedback filter, the delay), the natural
//! frequency is lowered by the same 1 % steps, found the same way, until they are met, as
//! the thesis widens the bandwidth separation of a loop whose margins are short.
//!
//! A loop that misses its margins ([`judge`]) does not stop the design: the loops outside it
//! are still designed, so that every loop's gains and margins can be shown
//! ([`Designer::loop_design`]); the design then fails naming the first such loop. A
//! coefficient, input or gain that is not finite, or out of range, stops it at once.

use super::inputs::DesignInputs;
use super::margins::{Margins, Sweep};
use super::model::DesignModel;
use super::rules::{Rules, GAIN_STEP, GAIN_STEPS};
use super::transfer::{LoopGains, Transfer};
use super::verdict::{judge, DesignFailure, Loop, Reason};
use crate::control::autopilot::GainSet;

/// The most loop-transfer points one [`Designer::step`] evaluates. The MCU's budget is 150 k
/// instructions per 20 ms control period and the flight tick takes up to some 131 k of it
/// (`docs/PERFORMANCE.md`), which leaves about 19 k. Measured on the MCU's target
/// (`thumbv7em-none-eabihf`, optimised for size as the image is, counted under QEMU's
/// `-icount`), a point of the 25e's design costs 280 to 560 instructions, the most where an
/// outer loop evaluates the inner loop closed through its servo and delay; at 24 points the
/// costliest step took 13.4 k instructions and the mean 8.5 k, which leaves some 5 k of the
/// 19 k (at 32 the costliest took 17.9 k). The step that checks the finished gain set
/// evaluates no point.
pub const POINTS_PER_STEP: u32 = 24;

/// One loop as designed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoopDesign {
    /// Its gains.
    pub gains: LoopGains,
    /// The natural frequency the rules aim at, rad/s.
    pub wn_radps: f32,
    /// Its margins, with servo, delay and feedback filter where the loop has them.
    pub margins: Margins,
}

/// One value per loop.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Loops<T> {
    /// [`Loop::Roll`]'s.
    pub roll: T,
    /// [`Loop::Course`]'s.
    pub course: T,
    /// [`Loop::Sideslip`]'s.
    pub sideslip: T,
    /// [`Loop::Pitch`]'s.
    pub pitch: T,
    /// [`Loop::Altitude`]'s.
    pub altitude: T,
    /// [`Loop::AirspeedPitch`]'s.
    pub airspeed_pitch: T,
    /// [`Loop::AirspeedThrottle`]'s.
    pub airspeed_throttle: T,
}

impl<T> Loops<T> {
    /// `l`'s value.
    pub fn get(&self, l: Loop) -> &T {
        match l {
            Loop::Roll => &self.roll,
            Loop::Course => &self.course,
            Loop::Sideslip => &self.sideslip,
            Loop::Pitch => &self.pitch,
            Loop::Altitude => &self.altitude,
            Loop::AirspeedPitch => &self.airspeed_pitch,
            Loop::AirspeedThrottle => &self.airspeed_throttle,
        }
    }

    fn get_mut(&mut self, l: Loop) -> &mut T {
        match l {
            Loop::Roll => &mut self.roll,
            Loop::Course => &mut self.course,
            Loop::Sideslip => &mut self.sideslip,
            Loop::Pitch => &mut self.pitch,
            Loop::Altitude => &mut self.altitude,
            Loop::AirspeedPitch => &mut self.airspeed_pitch,
            Loop::AirspeedThrottle => &mut self.airspeed_throttle,
        }
    }
}

/// A design that met every target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Designed {
    /// The base set with the designed loops' gains in place (its trims, sideslip loop, yaw
    /// damper and limits as they were), valid by [`GainSet::validate`].
    pub gains: GainSet,
    /// Every loop's gains, natural frequency and margins.
    pub loops: Loops<LoopDesign>,
}

/// What one [`Designer::step`] left.
// Returned by value (no heap to box the designed set in); the caller's one slot for it is
// written once per step, and the pending step writes only the discriminant.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Step {
    /// More steps to go.
    Pending,
    /// Designed.
    Done(Designed),
    /// Failed: the first loop that did, and why.
    Failed(DesignFailure),
}

/// The limit of a loop's gain (an attitude loop's) or natural frequency (an outer loop's, as
/// a share of its rule's): the smallest step index whose design keeps the margin, found by
/// bisection.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Search {
    /// The rule's gain, or 1 (step 0).
    x0: f32,
    /// The highest step known to miss the margin.
    failing: Option<u16>,
    /// The lowest step known to keep it, with its margins.
    passing: Option<(u16, Margins)>,
    /// The step whose margins are being computed.
    probe: u16,
    /// Steps between probes while none has kept the margin: 0 goes straight to the last
    /// step (an attitude loop's margin falls as its gain rises, all the way), an outer loop's
    /// scan walks down by this many (its margins come back only over a band of natural
    /// frequencies: far enough below its rule's, the pole placement's gain changes sign
    /// where the plant's own damping exceeds what it asks for, and the margins fall again).
    scan: u16,
}

/// Steps an outer loop's scan walks down by before its bisection: 10 % of its natural
/// frequency a probe.
const SCAN_STEPS: u16 = 10;

/// Where a search goes next.
enum Next {
    /// Compute the margins of this step.
    Probe(u16),
    /// This step's gain, with its margins where they are known.
    Chosen(u16, Option<Margins>),
}

impl Search {
    fn next(&self) -> Next {
        match (self.failing, self.passing) {
            (None, None) => Next::Probe(0),
            // The rule's own gain keeps the margin.
            (None, Some((n, m))) => Next::Chosen(n, Some(m)),
            // None keeps it: the last step's gain is judged, and fails.
            (Some(f), None) if f.saturating_add(1) >= GAIN_STEPS => Next::Chosen(GAIN_STEPS, None),
            (Some(_), None) if self.scan == 0 => Next::Probe(GAIN_STEPS - 1),
            (Some(f), None) => Next::Probe(f.saturating_add(self.scan).min(GAIN_STEPS - 1)),
            (Some(f), Some((n, m))) if n <= f.saturating_add(1) => Next::Chosen(n, Some(m)),
            (Some(f), Some((n, _))) => Next::Probe(f + (n - f) / 2),
        }
    }

    /// The gain or share `n` steps down.
    fn at(&self, n: u16) -> f32 {
        self.x0 * crate::math::elementary::powf(GAIN_STEP, f32::from(n))
    }
}

/// What the designer is doing.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Stage {
    /// Computing the margins of one step of a loop's gain or natural frequency.
    Limit {
        loop_: Loop,
        search: Search,
        sweep: Sweep,
    },
    /// Computing the margins of a loop whose gains are set.
    Judge {
        loop_: Loop,
        design: LoopDesign,
        sweep: Sweep,
    },
    /// Every loop designed: the gain set to build and check, in a step of its own (the
    /// check of the whole set costs what some ten points do).
    Finish,
    /// Finished (the designed set is built from the loops when asked for: the designer is not
    /// made to hold a second gain set).
    Over(Result<(), DesignFailure>),
}

/// The design in progress.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Designer {
    rules: Rules,
    base: GainSet,
    loops: Loops<LoopDesign>,
    /// The last loop designed (every loop before it is too).
    designed: Option<Loop>,
    /// The first loop that missed its margins.
    missed: Option<DesignFailure>,
    stage: Stage,
    evaluations: u32,
    steps: u32,
}

/// A failure of `loop_`.
fn failure(loop_: Loop, reason: Reason) -> DesignFailure {
    DesignFailure {
        loop_: Some(loop_),
        reason,
    }
}

/// The first of a loop's gains (and natural frequency) that is not finite, named.
fn finite(loop_: Loop, d: &LoopDesign) -> Result<(), DesignFailure> {
    let g = &d.gains;
    let names = loop_.params();
    let bad = [g.kp, g.ki, g.kd]
        .iter()
        .zip(names)
        .find(|(v, _)| !v.is_finite())
        .map(|(_, name)| *name)
        .or((!d.wn_radps.is_finite()).then_some("natural frequency"));
    match bad {
        Some(name) => Err(failure(loop_, Reason::NotFinite(name))),
        None => Ok(()),
    }
}

/// What the rules need of a number.
#[derive(Clone, Copy, PartialEq)]
enum Need {
    Finite,
    Positive,
    NonNegative,
}

/// The model and inputs checked loop by loop, in the order of the design, so that a bad
/// coefficient fails the first loop that uses it.
fn check(model: &DesignModel, inputs: &DesignInputs, lp: f32) -> Result<(), DesignFailure> {
    use Loop::*;
    use Need::*;
    let i = inputs;
    let inputs_finite = [
        i.zeta,
        i.roll_aileron_max_deg,
        i.roll_error_max_deg,
        i.course_separation,
        i.sideslip_separation,
        i.pitch_elevator_max_deg,
        i.pitch_error_max_deg,
        i.altitude_separation,
        i.filter_separation,
        i.altitude_filter_separation,
        i.integrator_zero_fraction,
        i.outer_integrator_fraction,
        i.sample_time_s,
        i.delay_samples,
        i.inner_phase_margin_deg,
    ]
    .iter()
    .all(|v| v.is_finite());
    // The inputs, and the pitch response's six coefficients, each checked as one number in
    // its place in the order: NaN where any is not finite.
    let whole = |finite: bool| if finite { 0.0 } else { f32::NAN };
    let pitch_finite = model.pitch_response().is_finite();
    let numbers = [
        (Roll, "design inputs", whole(inputs_finite), Finite),
        (Roll, "a_phi1", model.a_phi1, Finite),
        (Roll, "a_phi2", model.a_phi2, Finite),
        (
            Roll,
            "servo_bandwidth_hz",
            model.servo_bandwidth_hz,
            Positive,
        ),
        (Roll, "delay", i.delay_s(), NonNegative),
        (Course, "va", model.va, Positive),
        (Course, "g", model.g, Positive),
        (Sideslip, "a_beta1", model.a_beta1, Finite),
        (Sideslip, "a_beta2", model.a_beta2, Finite),
        (Pitch, "a_theta1", model.a_theta1, Finite),
        (Pitch, "a_theta2", model.a_theta2, Finite),
        (Pitch, "a_theta3", model.a_theta3, Finite),
        (Pitch, "pitch_response", whole(pitch_finite), Finite),
        (Altitude, "FB_LPF_POLE", lp, Positive),
        (AirspeedPitch, "a_v1", model.a_v1, Finite),
        (AirspeedThrottle, "a_v2", model.a_v2, Finite),
        (
            AirspeedThrottle,
            "engine_pole",
            model.engine_pole(),
            Positive,
        ),
    ];
    for (loop_, name, v, need) in numbers {
        if !v.is_finite() {
            return Err(failure(loop_, Reason::NotFinite(name)));
        }
        let in_range = match need {
            Finite => true,
            Positive => v > 0.0,
            NonNegative => v >= 0.0,
        };
        if !in_range {
            return Err(failure(loop_, Reason::OutOfRange(name)));
        }
    }
    Ok(())
}

impl Designer {
    /// A design of `model` with `inputs`, its gains to replace those of `base` (whose feedback
    /// low-pass, `FB_LPF_POLE`, the altitude and airspeed loops are designed with). Nothing is
    /// evaluated until [`Designer::step`].
    pub fn new(model: &DesignModel, inputs: &DesignInputs, base: &GainSet) -> Self {
        let lp = base.longitudinal.feedback_lpf_pole;
        let rules = Rules::new(model, inputs, base);
        let mut designer = Self {
            rules,
            base: *base,
            loops: Loops::default(),
            designed: None,
            missed: None,
            stage: Stage::Finish,
            evaluations: 0,
            steps: 0,
        };
        designer.stage = match check(model, inputs, lp) {
            Ok(()) => designer.limit(Loop::Roll),
            Err(f) => Stage::Over(Err(f)),
        };
        designer
    }

    /// Does at most [`POINTS_PER_STEP`] points' worth of the design.
    pub fn step(&mut self) -> Step {
        self.steps = self.steps.saturating_add(1);
        if matches!(self.stage, Stage::Finish) {
            self.stage = Stage::Over(self.finish());
        }
        let plant = self.rules.plant;
        for _ in 0..POINTS_PER_STEP {
            let margins = match &mut self.stage {
                Stage::Over(_) | Stage::Finish => break,
                Stage::Limit { sweep, .. } | Stage::Judge { sweep, .. } => sweep.advance(&plant),
            };
            self.evaluations = self.evaluations.saturating_add(1);
            if let Some(m) = margins {
                self.stage = self.swept(m);
            }
        }
        match self.stage {
            Stage::Over(Ok(())) => Step::Done(self.designed_set()),
            Stage::Over(Err(f)) => Step::Failed(f),
            _ => Step::Pending,
        }
    }

    /// `l` as designed, once it is (whether or not it met its margins).
    pub fn loop_design(&self, l: Loop) -> Option<&LoopDesign> {
        let skipped = l == Loop::Sideslip && !self.rules.plant.model.has_sideslip();
        self.designed
            .is_some_and(|last| l <= last && !skipped)
            .then(|| self.loops.get(l))
    }

    /// Loop-transfer points evaluated so far.
    pub fn evaluations(&self) -> u32 {
        self.evaluations
    }

    /// Calls of [`Designer::step`] so far.
    pub fn steps(&self) -> u32 {
        self.steps
    }

    /// `loop_`'s design at `x`: an attitude loop's at the gain `x`, an outer loop's at `x`
    /// times its rule's natural frequency, from the loops inside it as designed.
    fn candidate(&self, loop_: Loop, x: f32) -> LoopDesign {
        let (r, l) = (&self.rules, &self.loops);
        let (gains, wn_radps) = match loop_ {
            Loop::Roll => (r.roll(x), r.roll_wn(x)),
            Loop::Pitch => (r.pitch(x), r.pitch_wn(x)),
            Loop::Course => r.course(l.roll.wn_radps, x),
            Loop::Sideslip => r.sideslip(l.roll.wn_radps, x),
            Loop::Altitude => r.altitude(l.pitch.wn_radps, x),
            Loop::AirspeedPitch => r.airspeed_pitch(l.pitch.wn_radps, x),
            Loop::AirspeedThrottle => r.airspeed_throttle(x),
        };
        LoopDesign {
            gains,
            wn_radps,
            margins: Margins::default(),
        }
    }

    /// The limit of `loop_`'s gain or natural frequency begun: its rule's probed first.
    fn limit(&self, loop_: Loop) -> Stage {
        let (x0, scan) = match loop_ {
            Loop::Roll => (self.rules.roll_kp_appendix_c(), 0),
            Loop::Pitch => (self.rules.pitch_kp_nominal(), 0),
            // An outer loop's share of its rule's natural frequency.
            _ => (1.0, SCAN_STEPS),
        };
        let search = Search {
            x0,
            failing: None,
            passing: None,
            probe: 0,
            scan,
        };
        self.probe(loop_, search, 0)
    }

    /// The margins of step `n` of `loop_`'s search begun.
    fn probe(&self, loop_: Loop, mut search: Search, n: u16) -> Stage {
        search.probe = n;
        let d = self.candidate(loop_, search.at(n));
        if let Err(f) = finite(loop_, &d) {
            return Stage::Over(Err(f));
        }
        Stage::Limit {
            loop_,
            search,
            sweep: Sweep::new(self.transfer(loop_, &d)),
        }
    }

    /// Whether `margins` keep `loop_`'s search going down: an attitude loop's phase margin
    /// under [`DesignInputs::inner_phase_margin_deg`], an outer loop's targets missed.
    fn keeps(&self, loop_: Loop, margins: &Margins) -> bool {
        if loop_.is_inner() {
            let pm_min = self.rules.inputs.inner_phase_margin_deg;
            margins.phase_margin_deg.is_some_and(|pm| pm >= pm_min)
        } else {
            judge(loop_, margins).is_ok()
        }
    }

    /// Where the design goes once a sweep has given `margins`.
    fn swept(&mut self, margins: Margins) -> Stage {
        match self.stage {
            Stage::Limit {
                loop_, mut search, ..
            } => {
                if self.keeps(loop_, &margins) {
                    search.passing = Some((search.probe, margins));
                } else {
                    search.failing = Some(search.probe);
                }
                match search.next() {
                    Next::Probe(n) => self.probe(loop_, search, n),
                    Next::Chosen(n, known) => {
                        let design = self.candidate(loop_, search.at(n));
                        match known {
                            Some(margins) => self.designed_loop(loop_, design, margins),
                            None => self.judge(loop_, design),
                        }
                    }
                }
            }
            Stage::Judge { loop_, design, .. } => self.designed_loop(loop_, design, margins),
            done @ (Stage::Finish | Stage::Over(_)) => done,
        }
    }

    /// The margins of `loop_` with its gains set, begun.
    fn judge(&self, loop_: Loop, design: LoopDesign) -> Stage {
        if let Err(f) = finite(loop_, &design) {
            return Stage::Over(Err(f));
        }
        Stage::Judge {
            loop_,
            design,
            sweep: Sweep::new(self.transfer(loop_, &design)),
        }
    }

    /// `loop_`'s transfer with `design`'s gains, inside it the loops as designed.
    fn transfer(&self, loop_: Loop, design: &LoopDesign) -> Transfer {
        let l = &self.loops;
        match loop_ {
            Loop::Roll => Transfer::Roll(design.gains),
            Loop::Course => Transfer::Course {
                course: design.gains,
                roll: l.roll.gains,
            },
            Loop::Sideslip => Transfer::Sideslip(design.gains),
            Loop::Pitch => Transfer::Pitch(design.gains),
            Loop::Altitude => Transfer::Altitude {
                altitude: design.gains,
                pitch: l.pitch.gains,
            },
            Loop::AirspeedPitch => Transfer::AirspeedPitch {
                airspeed: design.gains,
                pitch: l.pitch.gains,
            },
            Loop::AirspeedThrottle => Transfer::AirspeedThrottle(design.gains),
        }
    }

    /// `loop_` designed with `margins`: judged, and the next loop begun.
    fn designed_loop(&mut self, loop_: Loop, mut design: LoopDesign, margins: Margins) -> Stage {
        design.margins = margins;
        *self.loops.get_mut(loop_) = design;
        self.designed = Some(loop_);
        if let Err(reason) = judge(loop_, &margins) {
            self.missed = self.missed.or(Some(failure(loop_, reason)));
        }
        // The next loop in the design's order (the sideslip's only where the model has
        // one), or the finish after the last.
        let has_sideslip = self.rules.plant.model.has_sideslip();
        let mut next = Loop::ALL
            .iter()
            .skip_while(|l| **l != loop_)
            .skip(1)
            .filter(|l| has_sideslip || **l != Loop::Sideslip);
        match next.next() {
            Some(&next) => self.limit(next),
            None => Stage::Finish,
        }
    }

    /// The base set with the designed gains in place, once every loop is designed (whether or
    /// not each met its margins: [`Step::Done`] gives it only when all did).
    pub fn designed(&self) -> Option<Designed> {
        (self.designed == Some(Loop::AirspeedThrottle)).then(|| self.designed_set())
    }

    /// The base set with the designed gains in place.
    fn designed_set(&self) -> Designed {
        let l = &self.loops;
        let mut gains = self.base;
        let lat = &mut gains.lateral;
        lat.roll_kp = l.roll.gains.kp;
        lat.roll_ki = l.roll.gains.ki;
        lat.roll_rate_kd = l.roll.gains.kd;
        lat.course_kp = l.course.gains.kp;
        lat.course_ki = l.course.gains.ki;
        if self.rules.plant.model.has_sideslip() {
            lat.slip_kp = l.sideslip.gains.kp;
            lat.slip_ki = l.sideslip.gains.ki;
        }
        let lon = &mut gains.longitudinal;
        lon.pitch_kp = l.pitch.gains.kp;
        lon.pitch_ki = l.pitch.gains.ki;
        lon.pitch_rate_kd = l.pitch.gains.kd;
        lon.alt_kp = l.altitude.gains.kp;
        lon.alt_ki = l.altitude.gains.ki;
        lon.aspd_pitch_kp = l.airspeed_pitch.gains.kp;
        lon.aspd_pitch_ki = l.airspeed_pitch.gains.ki;
        lon.aspd_thr_kp = l.airspeed_throttle.gains.kp;
        lon.aspd_thr_ki = l.airspeed_throttle.gains.ki;
        Designed { gains, loops: *l }
    }

    /// The verdict once every loop is designed: the first loop that missed its margins, else
    /// the designed set checked whole.
    fn finish(&self) -> Result<(), DesignFailure> {
        if let Some(f) = self.missed {
            return Err(f);
        }
        self.designed_set()
            .gains
            .validate()
            .map_err(|e| DesignFailure {
                loop_: Loop::of_param(e.name()),
                reason: Reason::GainSet(e),
            })
    }
}

/// Runs a [`Designer`] to its end: the designed gain set, or the first loop that failed and
/// why. On the vehicle, call [`Designer::step`] once per control period instead.
pub fn design(
    model: &DesignModel,
    inputs: &DesignInputs,
    base: &GainSet,
) -> Result<Designed, DesignFailure> {
    let mut d = Designer::new(model, inputs, base);
    // Ends: every step evaluates points or finishes, every sweep has a bounded count of
    // points (`margins::MAX_POINTS`), and the stages are a finite sequence.
    loop {
        match d.step() {
            Step::Pending => {}
            Step::Done(designed) => return Ok(designed),
            Step::Failed(f) => return Err(f),
        }
    }
}
