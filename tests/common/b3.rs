//! The hub schedule of B3 (docs/benchmarks.md) and a driver of a B3 slave: shared by the B3 tests
//! and examples.
#![allow(dead_code)]

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

/// Drives B3 through a slave: the motion interface `hub` follows [`hub`], the result is the tip
/// deflection in the hub frame (force interface `tip`). Value references are looked up once.
pub struct HubDrive {
    rotation: [u32; 9],
    rate: u32,
    tip: [u32; 3],
}

impl HubDrive {
    pub fn new(slave: &flexbody::slave::Slave) -> HubDrive {
        let vr = |name: String| {
            slave
                .variables()
                .by_name(&name)
                .unwrap_or_else(|| panic!("B3 has no variable {name}"))
                .value_reference
        };
        HubDrive {
            rotation: std::array::from_fn(|k| vr(format!("hub.rotation[{}]", k + 1))),
            rate: vr("hub.angularVelocity[3]".into()),
            tip: std::array::from_fn(|k| vr(format!("tip.position[{}]", k + 1))),
        }
    }

    /// The hub inputs of the schedule at `t`, one step of `h`, and the tip deflection in the hub
    /// frame at `t + h` (m).
    pub fn step(
        &self,
        slave: &mut flexbody::slave::Slave,
        t: f64,
        h: f64,
    ) -> flexbody::error::Result<f64> {
        self.set_hub(slave, t)?;
        slave.do_step(t, h)?;
        self.tip_deflection(slave, t + h)
    }

    /// Sets the hub inputs (rotation and rate) of the schedule at `t`.
    pub fn set_hub(
        &self,
        slave: &mut flexbody::slave::Slave,
        t: f64,
    ) -> flexbody::error::Result<()> {
        use nalgebra::{Rotation3, Vector3};
        let (theta, rate) = hub(t);
        let q = Rotation3::from_axis_angle(&Vector3::z_axis(), theta);
        for (c, &r) in self.rotation.iter().enumerate() {
            slave.set_real(r, q.matrix()[(c / 3, c % 3)])?;
        }
        slave.set_real(self.rate, rate)
    }

    /// The tip deflection in the hub frame of the schedule at `t` (m), `t` the slave's time.
    pub fn tip_deflection(
        &self,
        slave: &mut flexbody::slave::Slave,
        t: f64,
    ) -> flexbody::error::Result<f64> {
        use nalgebra::{Rotation3, Vector3};
        let mut p = Vector3::zeros();
        for (c, &r) in self.tip.iter().enumerate() {
            p[c] = slave.get_real(r)?;
        }
        let back = Rotation3::from_axis_angle(&Vector3::z_axis(), hub(t).0).inverse();
        Ok((back * p).y)
    }
}
