//! Classical stability margins of a loop transfer `L(jw)` (closed loop `1 / (1 + L)`), read off a
//! log-spaced sweep one point at a time, so that the work can be spread over control periods.
//!
//! The sweep runs from [`W_MIN_RADPS`] to [`W_MAX_RADPS`] at [`POINTS_PER_DECADE`]. Between two
//! samples where `|L|` crosses 1, or the phase crosses -180 deg (mod 360), the crossing is
//! bracketed by [`REFINE_STEPS`] bisections (geometric midpoints), then placed by linear
//! interpolation in `ln w` inside the last bracket. At several crossings the worst margin is
//! reported. The same reading as the host's `margins` (a 4,000-point sweep with 60 bisections),
//! on some 270 points: the phase is followed from sample to sample without the delay's
//! `-w tau` (added in closed form: the module `transfer`), which alone turns by up to 170 deg
//! between two samples near 1000 rad/s, too near the half turn beyond which a sampled phase
//! cannot be followed.

use super::transfer::{Plant, Transfer};
use core::f32::consts::{LN_10, PI, TAU};

/// Lowest frequency of the sweep, rad/s: below every loop's crossover (the slowest, altitude,
/// crosses near 0.1 rad/s).
pub const W_MIN_RADPS: f32 = 1e-3;

/// Highest frequency of the sweep, rad/s: above the servo (50 rad/s) and every crossing that
/// can set a margin.
pub const W_MAX_RADPS: f32 = 1e3;

/// Decades from [`W_MIN_RADPS`] to [`W_MAX_RADPS`].
const DECADES: u16 = 6;

/// Sweep samples per decade (6 % apart): enough to follow the phase of a loop whose closed
/// inner loop peaks, and to find each crossing between two samples.
pub const POINTS_PER_DECADE: u16 = 40;

/// Intervals of the sweep (its samples are one more).
const INTERVALS: u16 = DECADES * POINTS_PER_DECADE;

/// Bisections that bracket one crossing: the bracket shrinks to 1/64 of a sample interval
/// (0.1 % in `w`), inside which the interpolation is exact to far below the 1 deg and 0.5 dB
/// a margin is judged by.
pub const REFINE_STEPS: u8 = 6;

/// The most points one margin computation evaluates: every sweep sample, and two crossings
/// refined in each interval (a bound; the loops here have a few crossings in all).
pub const MAX_POINTS: u32 = (INTERVALS as u32 + 1) + INTERVALS as u32 * 2 * REFINE_STEPS as u32;

/// Gain and phase margins of one loop, with the frequencies they are read at.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Margins {
    /// Gain margin, dB (`None`: the phase never crosses -180 deg in the band, unbounded).
    pub gain_margin_db: Option<f32>,
    /// Frequency where the phase crosses -180 deg, rad/s.
    pub phase_crossover_radps: Option<f32>,
    /// Phase margin, deg (`None`: `|L|` never crosses 1 in the band).
    pub phase_margin_deg: Option<f32>,
    /// Frequency where `|L|` = 1, rad/s.
    pub gain_crossover_radps: Option<f32>,
}

/// `L` at one frequency.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Sample {
    /// Frequency, rad/s.
    w: f32,
    /// `|L|^2` (its logarithm is taken only where a crossing is placed).
    mag2: f32,
    /// The phase of `L e^{jw tau}`, unwrapped along the sweep, rad.
    residual: f32,
    /// The phase of `L`, unwrapped, rad.
    phase: f32,
}

/// A crossing being bracketed.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Crossing {
    /// `|L|` = 1.
    Gain,
    /// The phase at `-pi + 2 pi k`, rad.
    Phase(f32),
}

impl Crossing {
    /// Where `s` is on the crossing's scale (the crossing is at 0).
    fn level(self, s: &Sample) -> f32 {
        match self {
            Crossing::Gain => s.mag2 - 1.0,
            Crossing::Phase(target) => s.phase - target,
        }
    }
}

/// A crossing bracketed between `lo` and `hi`, with bisections left.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Bracket {
    crossing: Crossing,
    lo: Sample,
    hi: Sample,
    left: u8,
}

/// One margin computation in progress.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Sweep {
    transfer: Transfer,
    /// Index of the next sweep sample.
    next: u16,
    /// Its frequency, rad/s: each sample's times the sweep's ratio (a product, not a power:
    /// the 240 roundings of `f32` move the last sample by some 1e-5 of itself).
    w_next: f32,
    /// The ratio of one sample's frequency to the last's, `10^(1 / POINTS_PER_DECADE)`.
    ratio: f32,
    /// The last sweep sample.
    last: Option<Sample>,
    /// The crossing being bracketed.
    bracket: Option<Bracket>,
    /// A phase crossing in the same interval as the gain crossing being bracketed: next.
    queued: Option<Bracket>,
    margins: Margins,
}

/// `x` wrapped into `[-pi, pi)`.
fn wrap(x: f32) -> f32 {
    x - TAU * libm::floorf((x + PI) / TAU)
}

impl Sweep {
    /// The margins of `transfer`, not yet swept.
    pub fn new(transfer: Transfer) -> Self {
        Self {
            transfer,
            next: 0,
            w_next: W_MIN_RADPS,
            ratio: crate::math::elementary::powf(10.0, 1.0 / f32::from(POINTS_PER_DECADE)),
            last: None,
            bracket: None,
            queued: None,
            margins: Margins::default(),
        }
    }

    /// `L` at `w`, its residual phase taken on the branch nearest `near` (the previous
    /// sample's, or the bracket's end); the sweep's first sample's in `(-360, 0]` deg, where a
    /// loop's phase starts at low frequency (0 for a proportional loop, -90 deg per
    /// integrator), so that the phase followed from there is the Bode plot's.
    fn sample(&self, p: &Plant, w: f32, near: Option<f32>) -> Sample {
        let l = self.transfer.eval(p, w);
        let arg = libm::atan2f(l.im, l.re);
        let residual = match near {
            Some(r) => r + wrap(arg - r),
            None if arg > 0.0 => arg - TAU,
            None => arg,
        };
        Sample {
            w,
            mag2: l.re * l.re + l.im * l.im,
            residual,
            phase: residual - w * p.tau,
        }
    }

    /// Evaluates exactly one point of `L`: `Some` margins once the sweep is complete.
    pub fn advance(&mut self, p: &Plant) -> Option<Margins> {
        match self.bracket {
            Some(b) => self.bisect(p, b),
            None => self.sweep(p),
        }
        (self.next > INTERVALS && self.bracket.is_none()).then_some(self.margins)
    }

    /// The next sample of the sweep, and any crossing since the last.
    fn sweep(&mut self, p: &Plant) {
        let w = self.w_next;
        let s = self.sample(p, w, self.last.map(|l| l.residual));
        self.next = self.next.saturating_add(1);
        self.w_next = w * self.ratio;
        if let Some(a) = self.last {
            let bracket = |crossing| Bracket {
                crossing,
                lo: a,
                hi: s,
                left: REFINE_STEPS,
            };
            // `|L|` crosses 1 (as the host reads it: touching counts, a flat stretch not).
            let gain = (a.mag2 - 1.0) * (s.mag2 - 1.0) <= 0.0 && a.mag2 != s.mag2;
            // The phase crosses -180 deg + k 360 deg.
            let (ka, ks) = (
                libm::floorf((a.phase + PI) / TAU),
                libm::floorf((s.phase + PI) / TAU),
            );
            let phase = (ka != ks).then(|| Crossing::Phase(TAU * ka.max(ks) - PI));
            match (gain, phase) {
                (true, phase) => {
                    self.bracket = Some(bracket(Crossing::Gain));
                    self.queued = phase.map(bracket);
                }
                (false, Some(phase)) => self.bracket = Some(bracket(phase)),
                (false, None) => {}
            }
        }
        self.last = Some(s);
    }

    /// One bisection of the bracket; the crossing placed when none is left.
    fn bisect(&mut self, p: &Plant, mut b: Bracket) {
        let mid = libm::sqrtf(b.lo.w * b.hi.w);
        let m = self.sample(p, mid, Some(b.lo.residual));
        let level = b.crossing.level(&m);
        if (level > 0.0) == (b.crossing.level(&b.lo) > 0.0) {
            b.lo = m;
        } else {
            b.hi = m;
        }
        b.left = b.left.saturating_sub(1);
        if b.left > 0 {
            self.bracket = Some(b);
            return;
        }
        self.place(&b);
        self.bracket = self.queued.take();
    }

    /// The crossing inside the last bracket, by linear interpolation in `ln w`, and its margin
    /// kept where it is the worst so far.
    fn place(&mut self, b: &Bracket) {
        // `ln |L|^2` is nearer a straight line in `ln w` than `|L|^2`.
        let (ln_lo, ln_hi) = (libm::logf(b.lo.mag2), libm::logf(b.hi.mag2));
        let (ya, yb) = match b.crossing {
            Crossing::Gain => (ln_lo, ln_hi),
            phase => (phase.level(&b.lo), phase.level(&b.hi)),
        };
        let t = ya / (ya - yb);
        let t = if t.is_finite() {
            t.clamp(0.0, 1.0)
        } else {
            0.5
        };
        let w = b.lo.w * crate::math::elementary::powf(b.hi.w / b.lo.w, t);
        let at = |a: f32, b: f32| a + t * (b - a);
        let m = &mut self.margins;
        match b.crossing {
            Crossing::Gain => {
                // The phase above -180 deg as followed from low frequency, not wrapped: a
                // crossing where a damper's lead has taken the phase above 0 (a lightly
                // damped short period's resonance crossed twice) has more than 180 deg of
                // margin, not a negative one; one where a delay has taken it below -540 deg
                // has a negative margin, not a positive one.
                let pm = (at(b.lo.phase, b.hi.phase) + PI).to_degrees();
                if m.phase_margin_deg.is_none_or(|worst| pm < worst) {
                    m.phase_margin_deg = Some(pm);
                    m.gain_crossover_radps = Some(w);
                }
            }
            Crossing::Phase(_) => {
                // -20 log10 |L| = -10 log10 |L|^2.
                let gm = -10.0 / LN_10 * at(ln_lo, ln_hi);
                if m.gain_margin_db.is_none_or(|worst| gm < worst) {
                    m.gain_margin_db = Some(gm);
                    m.phase_crossover_radps = Some(w);
                }
            }
        }
    }
}
