//! Linear models, poles and transfer functions against the UMN Simulink linearisation and the
//! thesis.

use sim_host::aircraft::Aircraft;
use sim_host::analysis::linearize::{lat_modes, linearize, lon_modes, Mode};
use sim_host::analysis::references as refs;
use sim_host::analysis::transfer::thesis_transfer_functions;
use sim_host::analysis::trim::{trim, TrimTarget};
use sim_host::plant::ModelParams;

fn within_1pct(m: &Mode, (re, im): (f64, f64), name: &str) {
    let d = ((m.re - re).powi(2) + (m.im - im).powi(2)).sqrt();
    let mag = (re * re + im * im).sqrt();
    assert!(
        d / mag < 0.01,
        "{name}: ours {} ± {}i, UMN {re} ± {im}i",
        m.re,
        m.im
    );
}

fn close(ours: f64, reference: f64, rel_tol: f64, what: &str) {
    assert!(
        ((ours - reference) / reference).abs() < rel_tol,
        "{what}: ours {ours}, reference {reference}"
    );
}

#[test]
fn poles_tfs_and_matrices_at_level_trim() {
    let a = Aircraft::ultrastick25e().unwrap();
    let p = ModelParams::new(&a);
    let t = trim(&a, &TrimTarget::level());
    let lin = linearize(&p, &t);

    let lm = lon_modes(&lin.lon).unwrap();
    let am = lat_modes(&lin.lat).unwrap();
    within_1pct(&lm.phugoid, (-0.159, 0.641), "phugoid");
    within_1pct(&lm.short_period, (-11.7, 10.0), "short period");
    within_1pct(&lm.engine_speed, (-6.18, 0.0), "engine speed");
    within_1pct(&am.roll, (-16.1, 0.0), "roll");
    within_1pct(&am.dutch_roll, (-1.84, 5.29), "dutch roll");
    assert!(
        (am.spiral.re - (-0.0090)).abs() < 0.005,
        "spiral {}",
        am.spiral.re
    );
    assert!(am.heading.re.abs() < 1e-9);
    // Thesis damping and frequency (Tables 2.4, 2.5).
    assert!((lm.phugoid.damping - 0.241).abs() < 0.005);
    assert!((lm.short_period.damping - 0.759).abs() < 0.005);
    assert!((lm.short_period.wn_radps - 15.4).abs() < 0.1);
    assert!((am.dutch_roll.damping - 0.329).abs() < 0.005);

    let tf = thesis_transfer_functions(&lin);
    // Eq. 20: p/da = -156.5 / (s + 16.09).
    close(tf.p_over_da.num[0], -156.5, 0.01, "p/da gain");
    close(tf.p_over_da.den[1], 16.09, 0.01, "p/da pole");
    // Eq. 27: q/de = (-133.7 s - 990.7) / (s^2 + 23.37 s + 235.9).
    let q = tf.q_over_de.trimmed(1e-9);
    for (o, r) in q.num.iter().zip(refs::THESIS_Q_DE.0) {
        close(*o, r, 0.01, "q/de numerator");
    }
    for (o, r) in q.den.iter().zip(refs::THESIS_Q_DE.1) {
        close(*o, r, 0.01, "q/de denominator");
    }
    // Eq. 26: every r/dr coefficient but the two constants within 1 %; the constants follow
    // the spiral pole (-0.0090 here, -0.0138 in the thesis), see docs/VALIDATION.md.
    let r = tf.r_over_dr.trimmed(1e-9);
    assert_eq!(r.num.len(), 4);
    for k in 0..3 {
        close(r.num[k], refs::THESIS_R_DR.0[k], 0.01, "r/dr numerator");
    }
    for k in 1..4 {
        close(r.den[k], refs::THESIS_R_DR.1[k], 0.01, "r/dr denominator");
    }
    close(r.num[3], -2351.0, 0.05, "r/dr numerator constant");
    // Denominator constant = product of the poles; with the UMN spiral it is ~4.5, not 6.89.
    close(
        r.den[4],
        16.05 * 0.0090 * (1.840f64.powi(2) + 5.286f64.powi(2)),
        0.02,
        "r/dr den constant",
    );

    // Entry by entry against ValidatedDynamics.txt (printed to 4 significant digits).
    let check = |ours: &nalgebra::DMatrix<f64>, umn: &[&[f64]], what: &str| {
        for (i, row) in umn.iter().enumerate() {
            for (j, u) in row.iter().enumerate() {
                let o = ours[(i, j)];
                assert!(
                    (o - u).abs() <= 0.005 * u.abs() + 1e-5,
                    "{what}[{i},{j}]: ours {o}, UMN {u}"
                );
            }
        }
    };
    let rows = |m: &[[f64; 6]]| m.iter().map(|r| r.to_vec()).collect::<Vec<_>>();
    let a_lon = rows(&refs::UMN_A_LON);
    check(
        &lin.lon.a,
        &a_lon.iter().map(|r| &r[..]).collect::<Vec<_>>(),
        "A_lon",
    );
    check(
        &lin.lon.b,
        &refs::UMN_B_LON.iter().map(|r| &r[..]).collect::<Vec<_>>(),
        "B_lon",
    );
    check(
        &lin.lat.a,
        &refs::UMN_A_LAT.iter().map(|r| &r[..]).collect::<Vec<_>>(),
        "A_lat",
    );
    check(
        &lin.lat.b,
        &refs::UMN_B_LAT.iter().map(|r| &r[..]).collect::<Vec<_>>(),
        "B_lat",
    );
}
