use sim_host::analysis::*;
fn main() {
    let a = sim_host::aircraft::Aircraft::ultrastick25e().unwrap();
    let p = sim_host::plant::ModelParams::new(&a);
    let t = trim::trim(&a, &trim::TrimTarget::level());
    let l = linearize::linearize(&p, &t);
    let tf = transfer::thesis_transfer_functions(&l);
    println!(
        "{}\n{}\n{}",
        tf.p_over_da.format(4),
        tf.q_over_de.format(4),
        tf.r_over_dr.format(4)
    );
    for s in [
        doublet::Surface::Elevator,
        doublet::Surface::Aileron,
        doublet::Surface::Rudder,
    ] {
        let r = doublet::run(&a, &t, &l, s, &Default::default());
        println!(
            "{:?} diff {:?}\n resp {:?}",
            s,
            r.max_abs_diff
                .iter()
                .map(|x| format!("{x:.4}"))
                .collect::<Vec<_>>(),
            r.max_abs_response
                .iter()
                .map(|x| format!("{x:.3}"))
                .collect::<Vec<_>>()
        );
    }
}
