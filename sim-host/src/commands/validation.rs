//! `sim-host validation`: writes `docs/VALIDATION.md` from the trim, linearize and doublet
//! commands, with the sources of every reference and the known discrepancies in numbers.

use super::doublet::doublet_report;
use super::linearize::linearize_report;
use super::trim::trim_report;
use super::{render, Format};
use crate::aircraft::Aircraft;
use crate::analysis::doublet::{DoubletConfig, Surface};
use crate::analysis::references::{umn_trim, THESIS_TRIM};
use std::path::Path;

/// The whole validation document as Markdown. `out_dir` receives the doublet CSV/PNG files.
pub fn validation_markdown(aircraft: &Aircraft, out_dir: Option<&Path>) -> anyhow::Result<String> {
    let trims = trim_report(aircraft);
    let lin = linearize_report(aircraft, "level")?;
    let cfg = DoubletConfig::default();
    let dbl = doublet_report(aircraft, &cfg, out_dir)?;
    let level = trims.get("level").map(|e| e.result.clone());
    let mut s = String::new();
    s.push_str(include_str!("validation_intro.md"));
    s.push_str("\n## 1. Trim (thesis Table 2.3)\n\n");
    s.push_str(include_str!("validation_trim.md"));
    let worst = trims
        .trims
        .iter()
        .map(|e| e.result.residual_norm)
        .fold(0.0, f64::max);
    let most = trims
        .trims
        .iter()
        .map(|e| e.result.iterations)
        .max()
        .unwrap_or(0);
    let converged = trims.trims.iter().filter(|e| e.result.converged).count();
    s.push_str(&format!(
        "\nConvergence: {converged} of {} targets converged; largest residual {worst:.1e}, at most \
         {most} iterations.\n",
        trims.trims.len()
    ));
    if let Some(turn) = trims.get("turn") {
        s.push_str(&format!(
            "Level-turn rudder: {:.6} rad here, -0.00748 in the thesis.\n",
            turn.result.rudder
        ));
    }
    if let Some(l) = &level {
        let th = THESIS_TRIM[0];
        s.push_str(&format!(
            "\nNumbers: level alpha is {:.6} rad here and {:.6} in the UMN trim ({:+.3} %), against \
             {} in the thesis ({:+.1} %); elevator {:.6} here, {:.6} UMN ({:+.3} %), {} thesis \
             ({:+.1} %). Throttle {:.6} here, {:.7} UMN ({:+.3} %); Omega {:.3} rad/s here, {:.4} UMN \
             ({:+.4} %).\n\n",
            l.alpha,
            umn_trim::ALPHA,
            crate::report::pct(l.alpha, umn_trim::ALPHA),
            th.alpha,
            crate::report::pct(l.alpha, th.alpha),
            l.elevator,
            umn_trim::ELEVATOR,
            crate::report::pct(l.elevator, umn_trim::ELEVATOR),
            th.elevator,
            crate::report::pct(l.elevator, th.elevator),
            l.throttle,
            umn_trim::THROTTLE,
            crate::report::pct(l.throttle, umn_trim::THROTTLE),
            l.engine_speed,
            umn_trim::ENGINE_SPEED,
            crate::report::pct(l.engine_speed, umn_trim::ENGINE_SPEED),
        ));
    }
    s.push_str(&render(&trims.tables, Format::Markdown));
    s.push_str("\n## 2. Poles, transfer functions and linear models at level trim\n\n");
    s.push_str(include_str!("validation_linear.md"));
    let spiral = lin.lat_modes.spiral.re;
    let rdr = &lin.transfer_functions.r_over_dr;
    s.push_str(&format!(
        "\nNumbers: spiral {spiral:.5} here, -0.0090 UMN, -0.0138 thesis. The r/dr denominator \
         constant is the product of the lateral poles, so it follows the spiral pole: {:.3} here \
         against 6.89 in the thesis ({:+.0} %); the numerator constant is {:.0} against -2351 \
         ({:+.1} %). The other r/dr coefficients agree within {:.2} %.\n\n",
        rdr.den[4],
        crate::report::pct(rdr.den[4], 6.89),
        rdr.num[rdr.num.len() - 1],
        crate::report::pct(rdr.num[rdr.num.len() - 1], -2351.0),
        {
            let t = rdr.trimmed(1e-9);
            let mut worst: f64 = 0.0;
            for (o, r) in t
                .num
                .iter()
                .zip(crate::analysis::references::THESIS_R_DR.0)
                .take(3)
            {
                worst = worst.max(crate::report::pct(*o, r).abs());
            }
            for (o, r) in t
                .den
                .iter()
                .zip(crate::analysis::references::THESIS_R_DR.1)
                .take(4)
                .skip(1)
            {
                worst = worst.max(crate::report::pct(*o, r).abs());
            }
            worst
        }
    ));
    s.push_str(&render(&lin.tables, Format::Markdown));
    s.push_str("\n## 3. Linear versus nonlinear doublets (thesis section 3.2)\n\n");
    s.push_str(include_str!("validation_doublet.md"));
    let g = |surf, out| dbl.max_diff(surf, out).unwrap_or(f64::NAN);
    s.push_str(&format!(
        "\nNumbers: after the elevator doublet the largest differences are airspeed {:.3} m/s \
         (thesis 0.20), alpha {:.3} deg (0.05), theta {:.3} deg (0.40), q {:.3} deg/s (1.0). \
         After the aileron doublet: beta {:.3} deg, p {:.3} deg/s, r {:.3} deg/s; after the \
         rudder doublet: beta {:.3} deg, p {:.3} deg/s, r {:.3} deg/s (thesis: no visible \
         error).\n\n",
        g(Surface::Elevator, "airspeed"),
        g(Surface::Elevator, "alpha"),
        g(Surface::Elevator, "theta"),
        g(Surface::Elevator, "q"),
        g(Surface::Aileron, "beta"),
        g(Surface::Aileron, "p"),
        g(Surface::Aileron, "r"),
        g(Surface::Rudder, "beta"),
        g(Surface::Rudder, "p"),
        g(Surface::Rudder, "r"),
    ));
    let mut ratios = Vec::new();
    for run in dbl.runs.iter().filter(|r| r.surface != Surface::Elevator) {
        for i in [2, 6, 8] {
            ratios.push(100.0 * run.max_abs_diff[i] / run.max_abs_response[i].max(1e-12));
        }
    }
    let lo = ratios.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = ratios.iter().copied().fold(0.0, f64::max);
    s.push_str(&format!(
        "Lateral differences in beta, p and r: {lo:.1} % to {hi:.1} % of their response peaks.\n\n"
    ));
    s.push_str(&render(&dbl.tables, Format::Markdown));
    if out_dir.is_some() {
        s.push_str("\nPlots: ");
        let pngs: Vec<String> = dbl
            .files
            .iter()
            .filter(|f| f.extension().is_some_and(|e| e == "png"))
            .filter_map(|f| f.file_name().map(|n| format!("`{}`", n.to_string_lossy())))
            .collect();
        s.push_str(&pngs.join(", "));
        s.push_str(" (with the CSV data beside them) in the directory given by `--out-dir`.\n");
    }
    Ok(s)
}
