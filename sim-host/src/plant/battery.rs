//! The flight battery: a LiPo pack as an equivalent circuit, stepped beside the rigid body.
//!
//! Not part of the University of Minnesota model, which has no battery (the aircraft file's
//! `[battery]` table says where each value comes from). The pack is `n` cells in series, each
//! an open-circuit voltage that follows its state of charge
//! ([`common::battery::LIPO_OCV`]: a typical LiPo discharge curve, linear between its 5 %
//! points), behind the pack's internal resistance `R`:
//!
//! ```text
//! V = n OCV(soc) - I R
//! ```
//!
//! The load is a power: the motor's electrical power (the UMN shaft power
//! [`super::propulsion::motor_power_w`] over the motor and ESC's efficiency) plus the
//! avionics' constant draw. `P = V I` makes `R I^2 - E I + P = 0` with `E = n OCV(soc)`, whose
//! smaller root is the current, `I = (E - sqrt(E^2 - 4 R P)) / (2 R)` (`P / E` without a
//! resistance; beyond `E^2 / 4R` no current delivers the power, and the pack gives its most,
//! `E / 2R`). The charge drawn integrates `I dt` in f64, and `soc = soc0 - drawn / capacity`
//! (below empty the open-circuit voltage holds the table's last value).
//!
//! The pack's voltage does not feed back into thrust: the UMN power curve is throttle only,
//! so an emptying pack flies as a full one. What the battery changes is what the autopilot's
//! monitor measures.

use crate::aircraft::Battery as BatteryParams;
use common::battery::cell_ocv;

/// The pack's terminals at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BatteryOutput {
    /// Terminal voltage, V.
    pub voltage_v: f64,
    /// Current drawn, A.
    pub current_a: f64,
    /// Power delivered, W.
    pub power_w: f64,
}

/// The flight battery.
#[derive(Clone, Debug, PartialEq)]
pub struct Battery {
    params: BatteryParams,
    /// Charge drawn since power-up, A s.
    drawn_as: f64,
    /// Energy delivered since power-up, J.
    energy_j: f64,
    /// Lowest terminal voltage so far, V.
    min_voltage_v: f64,
    out: BatteryOutput,
}

impl Battery {
    /// A pack at its initial state of charge, unloaded.
    pub fn new(params: &BatteryParams) -> Self {
        let mut b = Self {
            params: params.clone(),
            drawn_as: 0.0,
            energy_j: 0.0,
            min_voltage_v: f64::INFINITY,
            out: BatteryOutput::default(),
        };
        b.out = b.load(0.0);
        b.min_voltage_v = b.out.voltage_v;
        b
    }

    /// State of charge, 0..1 (negative once the pack is drawn beyond empty).
    pub fn soc(&self) -> f64 {
        self.params.initial_soc - self.drawn_as / (self.params.capacity_mAh * 3.6)
    }

    /// Open-circuit voltage of the pack, V.
    pub fn open_circuit_v(&self) -> f64 {
        f64::from(self.params.cells) * f64::from(cell_ocv(self.soc() as f32))
    }

    /// Electrical power the aircraft draws with the motor delivering `shaft_w` on its shaft,
    /// W.
    pub fn electrical_power_w(&self, shaft_w: f64) -> f64 {
        shaft_w.max(0.0) / self.params.motor_esc_efficiency + self.params.avionics_power_W
    }

    /// The terminals at the present charge when `power_w` is drawn (nothing is integrated).
    pub fn load(&self, power_w: f64) -> BatteryOutput {
        let e = self.open_circuit_v();
        let r = self.params.internal_resistance_ohm;
        let p = power_w.max(0.0);
        let current_a = if r <= 0.0 {
            p / e
        } else {
            let disc = e * e - 4.0 * r * p;
            (e - disc.max(0.0).sqrt()) / (2.0 * r)
        };
        let voltage_v = e - current_a * r;
        BatteryOutput {
            voltage_v,
            current_a,
            power_w: voltage_v * current_a,
        }
    }

    /// Draws `power_w` for `dt` s: the terminals at the start of the step, their current
    /// held over it.
    pub fn step(&mut self, power_w: f64, dt: f64) -> BatteryOutput {
        self.out = self.load(power_w);
        self.drawn_as += self.out.current_a * dt;
        self.energy_j += self.out.power_w * dt;
        self.min_voltage_v = self.min_voltage_v.min(self.out.voltage_v);
        self.out
    }

    /// The terminals at the last step.
    pub fn output(&self) -> BatteryOutput {
        self.out
    }

    /// Charge drawn since power-up, mAh.
    pub fn drawn_mah(&self) -> f64 {
        self.drawn_as / 3.6
    }

    /// Energy delivered since power-up, Wh.
    pub fn energy_wh(&self) -> f64 {
        self.energy_j / 3600.0
    }

    /// Lowest terminal voltage so far, V.
    pub fn min_voltage_v(&self) -> f64 {
        self.min_voltage_v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aircraft::Aircraft;
    use crate::plant::{propulsion::motor_power_w, ModelParams};

    fn pack() -> BatteryParams {
        Aircraft::ultrastick25e().expect("built-in").battery
    }

    #[test]
    fn terminal_voltage_and_current_match_the_equivalent_circuit_by_hand() {
        // A full 3S pack rests at 3 x 4.20 = 12.6 V. Drawing 100 W through 0.024 ohm:
        // I = (12.6 - sqrt(12.6^2 - 4 x 0.024 x 100)) / (2 x 0.024)
        //   = (12.6 - sqrt(149.16)) / 0.048 = (12.6 - 12.21311) / 0.048 = 8.0602 A,
        // V = 12.6 - 8.0602 x 0.024 = 12.4066 V, and V I = 100 W.
        let b = Battery::new(&pack());
        assert!((b.open_circuit_v() - 12.6).abs() < 1e-5);
        let o = b.load(100.0);
        assert!((o.current_a - 8.0602).abs() < 1e-4, "{o:?}");
        assert!((o.voltage_v - 12.4066).abs() < 1e-4, "{o:?}");
        assert!((o.power_w - 100.0).abs() < 1e-9, "{o:?}");
        // Half charged it rests at 3 x 3.84 V; unloaded, no sag.
        let half = Battery::new(&BatteryParams {
            initial_soc: 0.5,
            ..pack()
        });
        let o = half.load(0.0);
        assert!(
            (o.voltage_v - 11.52).abs() < 1e-5 && o.current_a == 0.0,
            "{o:?}"
        );
        // The motor's 240 W at full throttle over 75 % plus the avionics' 4 W.
        let p = ModelParams::new(&Aircraft::ultrastick25e().expect("built-in"));
        let shaft = motor_power_w(&p, 1.0, 1000.0);
        assert!((shaft - (174.46 + 70.135 - 4.39)).abs() < 1e-9);
        assert!((b.electrical_power_w(shaft) - (shaft / 0.75 + 4.0)).abs() < 1e-9);
        // Asked for more than E^2 / 4R, it gives its most: half its voltage.
        let o = b.load(1e4);
        assert!((o.voltage_v - 6.3).abs() < 1e-5, "{o:?}");
    }

    #[test]
    fn a_full_throttle_minute_drains_the_power_over_the_voltage_it_sags_to() {
        // 324.3 W for 60 s is 5.40 Wh whatever the voltage; the charge is the integral of
        // P / V, so it lies between P t / V at the start and P t / V at the end: the voltage
        // falls from 12.0 V (12.6 V less 26 A through 0.024 ohm) as the charge goes.
        let p = ModelParams::new(&Aircraft::ultrastick25e().expect("built-in"));
        let mut b = Battery::new(&pack());
        let power = b.electrical_power_w(motor_power_w(&p, 1.0, 1000.0));
        let start = b.load(power);
        let dt = 0.001;
        for _ in 0..60_000 {
            b.step(power, dt);
        }
        let end = b.output();
        let (lo, hi) = (
            power * 60.0 / start.voltage_v / 3.6,
            power * 60.0 / end.voltage_v / 3.6,
        );
        eprintln!(
            "{power:.1} W: {:.2} -> {:.2} V, {:.1} mAh (between {lo:.1} and {hi:.1}), soc {:.3}",
            start.voltage_v,
            end.voltage_v,
            b.drawn_mah(),
            b.soc()
        );
        assert!((power - 324.27).abs() < 0.01, "{power}");
        assert!((b.energy_wh() - power * 60.0 / 3600.0).abs() < 1e-3);
        assert!(b.drawn_mah() > lo && b.drawn_mah() < hi);
        // About 450 mAh: 14 % of the 3200 mAh pack.
        assert!((b.soc() - (1.0 - b.drawn_mah() / 3200.0)).abs() < 1e-12);
        assert!((0.85..0.87).contains(&b.soc()), "{}", b.soc());
        assert_eq!(b.min_voltage_v(), end.voltage_v);
    }

    #[test]
    fn cruise_at_the_trim_throttle_draws_11_a_and_empties_the_full_pack_in_about_17_minutes() {
        // By hand from the aircraft file: the level trim at 17 m/s has throttle 0.569484
        // (docs/VALIDATION.md), so the shaft takes 174.46 x 0.3243 + 70.135 x 0.5695 - 4.39 =
        // 92.13 W, the pack 92.13 / 0.75 + 4 = 126.84 W. Half charged (3 x 3.84 = 11.52 V at
        // rest) that is I = (11.52 - sqrt(11.52^2 - 4 x 0.024 x 126.84)) / 0.048 = 11.275 A,
        // 188 mAh a minute, at 11.25 V. The curve holds 3.2 Ah x 3 x 3.8582 V = 37.04 Wh (the
        // mean of its 5 % points, by trapezoids); at 126.84 W that is 17.52 min, less what the
        // resistance burns (I^2 R = 3 W of 127 at 11 A, 2.4 %): 17.1 min.
        let a = Aircraft::ultrastick25e().expect("built-in");
        let p = ModelParams::new(&a);
        let power = Battery::new(&pack()).electrical_power_w(motor_power_w(&p, 0.569484, 1000.0));
        assert!((power - 126.84).abs() < 0.01, "{power}");
        let half = Battery::new(&BatteryParams {
            initial_soc: 0.5,
            ..pack()
        })
        .load(power);
        assert!((half.current_a - 11.275).abs() < 0.001, "{half:?}");
        assert!((half.voltage_v - 11.249).abs() < 0.001, "{half:?}");
        let mut b = Battery::new(&pack());
        let dt = 0.1;
        let mut t = 0.0;
        let mut first_minute_mah = 0.0;
        while b.soc() > 0.0 {
            b.step(power, dt);
            t += dt;
            if (t - 60.0).abs() < dt / 2.0 {
                first_minute_mah = b.drawn_mah();
            }
        }
        eprintln!(
            "{power:.2} W: empty after {:.2} min, {:.2} Wh, {first_minute_mah:.0} mAh in the first minute, lowest {:.2} V",
            t / 60.0,
            b.energy_wh(),
            b.min_voltage_v()
        );
        // Full: 12.6 V at rest, 10.27 A under the load: 171 mAh in the first minute.
        assert!((first_minute_mah - 171.0).abs() < 2.0, "{first_minute_mah}");
        assert!((t / 60.0 - 17.1).abs() < 0.2, "{} min", t / 60.0);
        // The energy delivered is the load's power for that time.
        assert!((b.energy_wh() - power * t / 3600.0).abs() < 0.01);
    }
}
