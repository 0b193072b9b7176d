//! The hub schedule of B3 (BENCHMARKS.md): shared by `tests/hub_beam.rs` and the B3 examples.

/// Hub angle (rad) and rate (rad/s) at `t`:
/// `θ = Ω/T (t²/2 + (T/2π)² (cos(2πt/T) − 1))` for t < T = 15 s, then `Ω (t − T/2)`,
/// Ω = 6 rad/s.
pub fn hub(t: f64) -> (f64, f64) {
    let (omega, ts) = (6.0, 15.0);
    let k = 2.0 * std::f64::consts::PI / ts;
    if t < ts {
        (
            omega / ts * (t * t / 2.0 + ((k * t).cos() - 1.0) / (k * k)),
            omega / ts * (t - (k * t).sin() / k),
        )
    } else {
        (omega * (t - ts / 2.0), omega)
    }
}
