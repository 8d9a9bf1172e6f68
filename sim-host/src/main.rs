//! `sim-host`: the Ultra Stick 25e simulator and the thesis's analysis commands.
fn main() {
    println!("sim-host");
}
