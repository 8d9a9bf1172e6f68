//! `sim-host linearize`: linear models, poles and transfer functions at a trim, with the
//! thesis's and the Minnesota references for the Ultra Stick 25e at 17 m/s, and Beard and
//! McLain's reduced-model coefficients for any other aircraft or airspeed.

use crate::aircraft::Aircraft;
use crate::analysis::linearize::StateSpace;
use crate::analysis::linearize::{lat_modes, linearize, lon_modes, LatModes, LonModes, Mode};
use crate::analysis::reduced::{closed_form, from_linearization, ReducedCoefficients};
use crate::analysis::references as refs;
use crate::analysis::transfer::{
    thesis_transfer_functions, ThesisTransferFunctions, TransferFunction,
};
use crate::analysis::trim::{not_trimmed, trim_with, TrimResult, TrimTarget};
use crate::plant::params::ModelParams;
use crate::report::table::Table;
use crate::report::{pct, sig};
use anyhow::{anyhow, bail};
use serde::Serialize;

/// Everything `linearize` computes.
#[derive(Clone, Debug, Serialize)]
pub struct LinearizeReport {
    /// The trim linearised about.
    pub trim: TrimResult,
    /// Longitudinal model.
    pub lon: StateSpace,
    /// Lateral model.
    pub lat: StateSpace,
    /// Longitudinal modes.
    pub lon_modes: LonModes,
    /// Lateral modes.
    pub lat_modes: LatModes,
    /// Thesis transfer functions.
    pub transfer_functions: ThesisTransferFunctions,
    /// Beard and McLain's reduced-model coefficients read off the linear model.
    pub reduced: ReducedCoefficients,
    /// The same from their closed-form expressions with the aircraft file's values.
    pub reduced_closed_form: ReducedCoefficients,
    /// Printed tables.
    pub tables: Vec<Table>,
}

fn pole(m: &Mode) -> String {
    if m.im > 0.0 {
        format!("{} ± {}i", sig(m.re, 4), sig(m.im, 4))
    } else {
        sig(m.re, 4)
    }
}

fn entry_table(
    title: &str,
    ours: &nalgebra::DMatrix<f64>,
    umn: &[&[f64]],
    rows: &[String],
    cols: &[String],
) -> Table {
    let mut t = Table::new(
        title,
        &["entry", "ours", "UMN Simulink", "ours - UMN", "rel"],
    );
    for (i, r) in rows.iter().enumerate() {
        for (j, c) in cols.iter().enumerate() {
            let (o, u) = (ours[(i, j)], umn[i][j]);
            if o.abs() < 1e-6 && u.abs() < 1e-6 {
                continue;
            }
            let rel = if u.abs() > 1e-9 {
                format!("{:+.2} %", pct(o, u))
            } else {
                "-".into()
            };
            t.row([
                format!("[{r}, {c}]"),
                sig(o, 5),
                sig(u, 4),
                sig(o - u, 2),
                rel,
            ]);
        }
    }
    t
}

/// The rows of one transfer function's coefficients, beside the thesis's when it applies.
fn tf_rows(
    t: &mut Table,
    name: &str,
    ours: &TransferFunction,
    reference: Option<(&[f64], &[f64])>,
) {
    let ours = ours.trimmed(1e-9);
    let (n, m) = (ours.num.len(), ours.den.len());
    let Some((num, den)) = reference else {
        for (k, o) in ours.num.iter().enumerate() {
            let label = format!("{name} num s^{}", n - 1 - k);
            t.row([label, sig(*o, 5), "-".into(), "-".into()]);
        }
        for (k, o) in ours.den.iter().enumerate().skip(1) {
            let label = format!("{name} den s^{}", m - 1 - k);
            t.row([label, sig(*o, 5), "-".into(), "-".into()]);
        }
        return;
    };
    for (k, (o, r)) in ours.num.iter().zip(num).enumerate() {
        t.row([
            format!("{name} num s^{}", n - 1 - k),
            sig(*o, 5),
            sig(*r, 4),
            format!("{:+.2} %", pct(*o, *r)),
        ]);
    }
    for (k, (o, r)) in ours.den.iter().zip(den).enumerate().skip(1) {
        t.row([
            format!("{name} den s^{}", m - 1 - k),
            sig(*o, 5),
            sig(*r, 4),
            format!("{:+.2} %", pct(*o, *r)),
        ]);
    }
}

/// Linearises about the named trim (`level` by default) at the aircraft's cruise airspeed and
/// tabulates the comparison.
pub fn linearize_report(aircraft: &Aircraft, trim_name: &str) -> anyhow::Result<LinearizeReport> {
    linearize_report_at(aircraft, trim_name, aircraft.cruise_airspeed_mps())
}

/// [`linearize_report`] at airspeed `va_mps`.
pub fn linearize_report_at(
    aircraft: &Aircraft,
    trim_name: &str,
    va_mps: f64,
) -> anyhow::Result<LinearizeReport> {
    let target = TrimTarget::by_name(trim_name).ok_or_else(|| {
        anyhow!(
            "unknown trim `{trim_name}`; known: {}",
            TrimTarget::all()
                .iter()
                .map(|t| t.name.clone())
                .collect::<Vec<_>>()
                .join(", ")
        )
    })?;
    let target = target.at_airspeed(va_mps);
    let p = ModelParams::new(aircraft);
    let trim = trim_with(&p, &target);
    if !trim.converged {
        bail!("{}; cannot linearise", not_trimmed(&trim));
    }
    let lin = linearize(&p, &trim);
    let lm = lon_modes(&lin.lon).ok_or_else(|| {
        anyhow!(
            "unexpected longitudinal pole pattern: {:?}",
            lin.lon.eigenvalues()
        )
    })?;
    let am = lat_modes(&lin.lat).ok_or_else(|| {
        anyhow!(
            "unexpected lateral pole pattern: {:?}",
            lin.lat.eigenvalues()
        )
    })?;
    let tfs = thesis_transfer_functions(&lin);
    let references = refs::apply_to(aircraft, va_mps);
    let level = target.name == "level" && references;
    let mut tables = Vec::new();

    let mut poles = Table::new(
        format!("Poles at trim `{}`", target.name),
        &[
            "mode",
            "ours",
            "damping",
            "wn (rad/s)",
            "UMN Simulink",
            "ours vs UMN",
            "thesis",
        ],
    );
    let ours_modes: [(&str, &Mode); 7] = [
        ("phugoid", &lm.phugoid),
        ("short period", &lm.short_period),
        ("engine speed", &lm.engine_speed),
        ("altitude", &lm.altitude),
        ("roll", &am.roll),
        ("dutch roll", &am.dutch_roll),
        ("spiral", &am.spiral),
    ];
    for (name, m) in ours_modes {
        let r = refs::POLES.iter().find(|x| x.mode == name);
        // Reference values keep at least one decimal, as printed in their sources.
        let num = |x: f64| {
            if x.fract() == 0.0 {
                format!("{x:.1}")
            } else {
                format!("{x}")
            }
        };
        let fmt = |(re, im): (f64, f64)| {
            if im > 0.0 {
                format!("{} ± {}i", num(re), num(im))
            } else {
                num(re)
            }
        };
        let (umn, cmp, thesis) = match (level, r) {
            (true, Some(r)) => {
                let d = ((m.re - r.umn.0).powi(2) + (m.im - r.umn.1).powi(2)).sqrt();
                let mag = (r.umn.0.powi(2) + r.umn.1.powi(2)).sqrt();
                (
                    fmt(r.umn),
                    format!("|d| = {} ({:.2} %)", sig(d, 2), 100.0 * d / mag),
                    r.thesis.map(fmt).unwrap_or_else(|| "-".into()),
                )
            }
            _ => ("-".into(), "-".into(), "-".into()),
        };
        let (zeta, wn) = if m.wn_radps > 1e-9 && m.im > 0.0 {
            (format!("{:.3}", m.damping), format!("{:.3}", m.wn_radps))
        } else {
            let kind = if m.re < 0.0 {
                "1 (real)"
            } else {
                "-1 (real, unstable)"
            };
            (kind.into(), sig(m.wn_radps, 3))
        };
        poles.row([name.to_string(), pole(m), zeta, wn, umn, cmp, thesis]);
    }
    poles.row([
        "heading".to_string(),
        sig(am.heading.re, 2),
        "-".into(),
        "-".into(),
        "0".into(),
        "-".into(),
        "0".into(),
    ]);
    tables.push(poles);

    let mut tf = Table::new(
        format!(
            "Transfer functions at trim `{}` (ours beside THESIS eqs. 20, 27, 26)",
            target.name
        ),
        &["coefficient", "ours", "thesis", "ours vs thesis"],
    );
    tf_rows(
        &mut tf,
        "p/da",
        &tfs.p_over_da,
        references.then_some((&refs::THESIS_P_DA.0[..], &refs::THESIS_P_DA.1[..])),
    );
    tf_rows(
        &mut tf,
        "q/de",
        &tfs.q_over_de,
        references.then_some((&refs::THESIS_Q_DE.0[..], &refs::THESIS_Q_DE.1[..])),
    );
    tf_rows(
        &mut tf,
        "r/dr",
        &tfs.r_over_dr,
        references.then_some((&refs::THESIS_R_DR.0[..], &refs::THESIS_R_DR.1[..])),
    );
    if references {
        let p_dar = lin.lat.b[(1, 1)];
        tf.row([
            "p/da_R (right aileron, UMN B_lat)".to_string(),
            sig(p_dar, 5),
            format!("{} (UMN)", refs::UMN_P_DA_RIGHT),
            format!("{:+.2} %", pct(p_dar, refs::UMN_P_DA_RIGHT)),
        ]);
    }
    tables.push(tf);
    let mut forms = Table::new("Transfer functions in full", &["tf", "ours"]);
    forms.row(["p/da".to_string(), tfs.p_over_da.format(4)]);
    forms.row(["q/de".to_string(), tfs.q_over_de.trimmed(1e-9).format(4)]);
    forms.row(["r/dr".to_string(), tfs.r_over_dr.trimmed(1e-9).format(4)]);
    tables.push(forms);

    if level {
        let umn_lon: Vec<&[f64]> = refs::UMN_A_LON.iter().map(|r| &r[..]).collect();
        let umn_blon: Vec<&[f64]> = refs::UMN_B_LON.iter().map(|r| &r[..]).collect();
        let umn_lat: Vec<&[f64]> = refs::UMN_A_LAT.iter().map(|r| &r[..]).collect();
        let umn_blat: Vec<&[f64]> = refs::UMN_B_LAT.iter().map(|r| &r[..]).collect();
        tables.push(entry_table(
            "A_lon, states [u, w, q, theta, Ze, Omega]",
            &lin.lon.a,
            &umn_lon,
            &lin.lon.states,
            &lin.lon.states,
        ));
        tables.push(entry_table(
            "B_lon, inputs [elevator, throttle]",
            &lin.lon.b,
            &umn_blon,
            &lin.lon.states,
            &lin.lon.inputs,
        ));
        tables.push(entry_table(
            "A_lat, states [v, p, r, phi, psi]",
            &lin.lat.a,
            &umn_lat,
            &lin.lat.states,
            &lin.lat.states,
        ));
        tables.push(entry_table(
            "B_lat, inputs [left_aileron, right_aileron, rudder]",
            &lin.lat.b,
            &umn_blat,
            &lin.lat.states,
            &lin.lat.inputs,
        ));
    } else {
        let mut m = Table::new("A_lon and A_lat rows", &["row", "values"]);
        for (name, ss) in [("lon", &lin.lon), ("lat", &lin.lat)] {
            for (i, s) in ss.states.iter().enumerate() {
                let vals: Vec<String> = ss.a.row(i).iter().map(|x| sig(*x, 4)).collect();
                m.row([format!("A_{name}[{s}]"), vals.join(", ")]);
            }
        }
        tables.push(m);
    }
    let reduced = from_linearization(&lin, &trim);
    let reduced_closed_form = closed_form(aircraft, &trim);
    if !references {
        tables.push(reduced_table(&trim, &reduced, &reduced_closed_form));
    }
    Ok(LinearizeReport {
        trim,
        lon: lin.lon,
        lat: lin.lat,
        lon_modes: lm,
        lat_modes: am,
        transfer_functions: tfs,
        reduced,
        reduced_closed_form,
        tables,
    })
}

/// Beard and McLain's reduced-model coefficients, from the linear model and from their
/// closed forms.
pub fn reduced_table(
    trim: &TrimResult,
    linear: &ReducedCoefficients,
    closed: &ReducedCoefficients,
) -> Table {
    let mut t = Table::new(
        format!(
            "Beard and McLain's reduced models at trim `{}` (Va {} m/s, h {} m)",
            trim.target.name, trim.target.va_mps, trim.target.alt_msl_m
        ),
        &[
            "coefficient",
            "linear model",
            "closed form",
            "linear vs closed",
        ],
    );
    for ((name, l), (_, c)) in linear.named().into_iter().zip(closed.named()) {
        t.row([
            name.to_string(),
            sig(l, 5),
            sig(c, 5),
            format!("{:+.2} %", pct(l, c)),
        ]);
    }
    t
}
