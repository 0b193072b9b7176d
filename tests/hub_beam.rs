//! B3 (Kane, Ryan & Banerjee 1987): spin-up of a beam on a hub driven through a motion interface.
//! Without stiffening a linear floating-frame model predicts a tip deflection (in the hub frame)
//! that grows without bound; the absolute coordinates with the co-rotated strain stay bounded,
//! lag during the spin-up and return to a small oscillation about zero at constant speed.

mod common;
use common::*;

#[test]
fn b3_spin_up_stays_bounded_and_returns_to_the_hub_frame() {
    let mut s = initialized(example_body("hub_beam"), &[]);
    let drive = common::b3::HubDrive::new(&s);
    let h = 1e-2;
    let mut history = Vec::new();
    for k in 0..2000 {
        let t = k as f64 * h;
        history.push((t + h, drive.step(&mut s, t, h).unwrap()));
    }
    for (t, y) in history.iter().step_by(100) {
        println!("t = {t:5.2} s: tip deflection in the hub frame {y:+.4} m");
    }
    // Measured (hex20 40×1×1, h = 1e-2): peak −0.572 m at t ≈ 7 s, then |y| < 3e-3 m after
    // 17 s. The assertions are the known qualitative behaviour, not these figures: bounded (a
    // linear floating frame passes metres here), lagging (negative, peak during the spin-up) and
    // back to a small oscillation about zero once the rate is constant; the quantitative
    // comparison with the full nonlinear reference is issue 4's.
    let (t_peak, y_peak) = history
        .iter()
        .copied()
        .fold((0.0, 0.0), |(tp, yp), (t, y)| {
            if y.abs() > f64::abs(yp) {
                (t, y)
            } else {
                (tp, yp)
            }
        });
    assert!(
        y_peak < 0.0 && y_peak > -1.0,
        "peak tip deflection {y_peak} m"
    );
    assert!((4.0..10.0).contains(&t_peak), "peak at t = {t_peak} s");
    let late = history
        .iter()
        .filter(|(t, _)| *t > 17.0)
        .map(|(_, y)| y.abs())
        .fold(0.0, f64::max);
    assert!(late < 0.02 * y_peak.abs(), "late oscillation {late} m");
}
