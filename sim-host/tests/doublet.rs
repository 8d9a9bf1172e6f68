//! The linear-versus-nonlinear doublet check of thesis section 3.2.

use sim_host::aircraft::Aircraft;
use sim_host::analysis::doublet::{DoubletConfig, Surface};
use sim_host::analysis::references::THESIS_DOUBLET_LON;
use sim_host::commands::doublet::doublet_report;

#[test]
fn linear_and_nonlinear_agree_as_in_tables_3_1_and_3_2() {
    let a = Aircraft::ultrastick25e().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let r = doublet_report(&a, &DoubletConfig::default(), Some(dir.path())).unwrap();
    // Table 3.1: every longitudinal difference below the thesis's.
    for (name, thesis, _) in THESIS_DOUBLET_LON {
        let d = r.max_diff(Surface::Elevator, name).unwrap();
        assert!(
            d < thesis,
            "elevator doublet {name}: {d} >= thesis {thesis}"
        );
    }
    // Table 3.2 ("no visible error"): each lateral difference below 3 % of its response peak.
    for run in r.runs.iter().filter(|x| x.surface != Surface::Elevator) {
        for (i, name) in [(2, "beta"), (6, "p"), (8, "r")] {
            let (d, peak) = (run.max_abs_diff[i], run.max_abs_response[i]);
            assert!(peak > 1.0, "{:?} {name} response {peak}", run.surface);
            assert!(
                d < 0.03 * peak,
                "{:?} {name}: diff {d} peak {peak}",
                run.surface
            );
        }
    }
    // The doublet really moved the aircraft: q responds to the elevator.
    assert!(r.runs[0].max_abs_response[7] > 5.0);
    // A CSV and a PNG per doublet.
    assert_eq!(r.files.len(), 6);
    for f in &r.files {
        assert!(
            std::fs::metadata(f).unwrap().len() > 1000,
            "{}",
            f.display()
        );
    }
    let mut csv = csv::Reader::from_path(&r.files[0]).unwrap();
    assert!(csv
        .headers()
        .unwrap()
        .iter()
        .any(|h| h == "nonlinear_q_degps"));
    assert_eq!(csv.records().count(), 2001);
}
