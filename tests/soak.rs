//! The soak run of `examples/soak.rs` (issue 6), shortened to 10⁴ steps of 1 ms (10 s of
//! simulated time, 160 periods of the first bending mode) with the energy after every step: no
//! energy drift beyond the integrator's and a flat resident set. The 10⁶-step run is
//! `cargo run --release --example soak`.

#[path = "../examples/soak.rs"]
#[allow(dead_code)]
mod soak;

#[test]
fn ten_thousand_steps_without_drift_or_growth() {
    let report = soak::soak(10_000, 1);
    soak::print(&report);
    soak::check(&report);
}
