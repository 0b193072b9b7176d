//! The portable byte form of a [`SlaveState`] (the payload of `fmi2SerializeFMUstate`; the FMI
//! layer adds the header with the magic, the format version and the GUID).
//!
//! Layout, all little-endian, no padding, no pointers (so the bytes of equal states are equal):
//!
//! | field | encoding |
//! | --- | --- |
//! | payload format | u32 = [`PAYLOAD_FORMAT`] |
//! | interfaces `n` | u32 |
//! | parameters | E, ν, ρ, α, β, gravity[3], initial position[3], rotation[9], velocity[3], angular velocity[3], step size, ρ∞, tolerance, accuracy: f64; max iterations, formulation, stiffening, frames, Anderson depth, integrator, modes: i32; nonlinear forces, auto: u8 |
//! | inputs | `n × 30` f64 (value-reference slot order) |
//! | input derivatives | `n × 2 × 30` f64 (order 1, then order 2) |
//! | input sample times | `n` f64 (the time each interface's inputs describe) |
//! | driving frames | `n ×` (position[3], rotation[9] row-major, velocity[3], angular velocity[3], acceleration[3], angular acceleration[3], time of the last change, rate span, time of the last update, offset[12], whether it sheds it (1) or not (0)) f64: each motion interface's frame as given at its last change (zeros and the identity for other interfaces), with its velocities' mean rates between their last two changes, the time between them when the frame follows them (0: not), when its inputs were last given, and the offset of its pose and velocities it sheds over the rate span (δp, δθ, δv, δω) where it sheds one |
//! | last step size | f64 (0 before the first step) |
//! | start time | f64 |
//! | stop time | u8 (1: defined), f64 (0 when not) |
//! | counters | internal steps, iterations, retries, rejected steps: u64 |
//! | dynamics present | u8 (0 before initialization) |
//! | dynamics | time f64; `3N` u64; positions, velocities, accelerations, pseudo-accelerations `3N` f64 each; multipliers: u64 count, f64 each; loads `n × 30` f64; gravity[3] f64; terms in force u8 (bit 0 f_nl, bit 1 stiffening, bit 2 model.auto's slabs, bit 3 slabs refused, bit 4 the linear body, bit 5 the slabs' own stiffening); since when their indicators are quiet [3] f64 (f64::MAX: not); step level, calm steps on it, steps the next probe waits for: u32; whether the rung came from a probe not yet confirmed: u8; internal steps since a motion input last jumped: u32; whether that jump came within 8 internal steps of the one before: u8; deformation scale f64; the scale of the modes above the lowest f64; the estimate floor f64; the slabs' stiffening ratio last measured f64; whether `model.auto` switched the slabs' own stiffening on: u8; when: f64 (0 when not); since when the deformation scale has not grown by 10 % f64, the scale then f64, whether it has settled u8; the last internal step's length f64 (0: none); whether its iteration's error ratio is carried u8, that ratio f64 (0 when not) |
//!
//! Reading checks every count against this body (interfaces, nodes, constraint multipliers), every
//! number for finiteness and the parameters' ranges, so a damaged or foreign payload is an error
//! with a message, never a panic or a NaN later.

use super::{Dynamics, InputDerivatives, Inputs, Parameters, Slave, SlaveState, INTERFACE_SLOTS};
use crate::body::interface::DrivingFrame;
use crate::error::{Error, Result};
use crate::fem::IsotropicMaterial;
use crate::model::enumerations::{Formulation, Integrator, Stiffening};
use crate::model::variables::FixedKey;
use crate::solver::problem::DynamicState;
use nalgebra::{Matrix3, Vector3};

/// Version of the payload layout above; bump it when the layout changes.
pub const PAYLOAD_FORMAT: u32 = 18;

struct Writer<'a>(&'a mut Vec<u8>);

impl Writer<'_> {
    fn f64(&mut self, x: f64) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn f64s(&mut self, xs: &[f64]) {
        xs.iter().for_each(|&x| self.f64(x));
    }
    fn u64(&mut self, x: u64) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn u32(&mut self, x: u32) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn i32(&mut self, x: i32) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn u8(&mut self, x: u8) {
        self.0.push(x);
    }
}

/// Reads little-endian numbers of a serialized FMU state; every error names what it was reading
/// and where (the FMI layer reads its header with it too).
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Reader<'a> {
        Reader { bytes, at: 0 }
    }

    /// The next `n` bytes.
    pub(crate) fn bytes(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        let end = self.at.checked_add(n).filter(|&end| end <= self.bytes.len()).ok_or_else(|| {
            Error::new(format!(
                "the serialized FMU state is truncated: {} bytes, {what} needs {n} bytes from byte {}",
                self.bytes.len(),
                self.at
            ))
        })?;
        let chunk = &self.bytes[self.at..end];
        self.at = end;
        Ok(chunk)
    }

    /// The bytes not read yet.
    pub(crate) fn rest(&self) -> &'a [u8] {
        &self.bytes[self.at..]
    }

    fn take<const N: usize>(&mut self, what: &str) -> Result<[u8; N]> {
        let end = self.at + N;
        let chunk = self.bytes.get(self.at..end).ok_or_else(|| {
            Error::new(format!(
                "the serialized FMU state is truncated: {} bytes, {what} needs bytes {}..{end}",
                self.bytes.len(),
                self.at
            ))
        })?;
        self.at = end;
        Ok(chunk.try_into().expect("N bytes"))
    }
    fn f64(&mut self, what: &str) -> Result<f64> {
        let x = f64::from_le_bytes(self.take::<8>(what)?);
        if x.is_finite() {
            Ok(x)
        } else {
            Err(Error::new(format!(
                "the serialized FMU state holds {x} for {what} (byte {}): not a finite number",
                self.at - 8
            )))
        }
    }
    fn f64s(&mut self, out: &mut [f64], what: &str) -> Result<()> {
        for x in out {
            *x = self.f64(what)?;
        }
        Ok(())
    }
    pub(crate) fn u64(&mut self, what: &str) -> Result<u64> {
        Ok(u64::from_le_bytes(self.take::<8>(what)?))
    }
    pub(crate) fn u32(&mut self, what: &str) -> Result<u32> {
        Ok(u32::from_le_bytes(self.take::<4>(what)?))
    }
    fn i32(&mut self, what: &str) -> Result<i32> {
        Ok(i32::from_le_bytes(self.take::<4>(what)?))
    }
    /// An enumeration item (i32) read through `from_item`.
    fn choice<T>(&mut self, what: &str, from_item: impl Fn(i32) -> Option<T>) -> Result<T> {
        let item = self.i32(what)?;
        from_item(item).ok_or_else(|| {
            Error::new(format!(
                "the serialized FMU state holds {item} for {what}: not an item of its enumeration"
            ))
        })
    }
    pub(crate) fn u8(&mut self, what: &str) -> Result<u8> {
        Ok(self.take::<1>(what)?[0])
    }
    /// A Boolean (u8 0 or 1).
    fn boolean(&mut self, what: &str) -> Result<bool> {
        match self.u8(what)? {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(Error::new(format!(
                "the serialized FMU state holds {b} for {what}: not a Boolean"
            ))),
        }
    }
    /// A count that must equal `expected` (a property of this body).
    fn count(&mut self, expected: usize, what: &str) -> Result<()> {
        let n = self.u64(what)?;
        if n == expected as u64 {
            Ok(())
        } else {
            Err(Error::new(format!(
                "the serialized FMU state has {n} {what}, this body has {expected}: it belongs to another body"
            )))
        }
    }
}

impl SlaveState {
    /// Appends the payload (layout in the module documentation) to `out`.
    pub fn write_bytes(&self, out: &mut Vec<u8>) {
        let mut w = Writer(out);
        w.u32(PAYLOAD_FORMAT);
        w.u32(self.inputs.len() as u32);
        let p = &self.parameters;
        w.f64s(&[
            p.material.youngs_modulus,
            p.material.poisson_ratio,
            p.material.density,
            p.damping_alpha,
            p.damping_beta,
        ]);
        w.f64s(&p.gravity);
        w.f64s(&p.initial_position);
        w.f64s(&p.initial_rotation);
        w.f64s(&p.initial_velocity);
        w.f64s(&p.initial_angular_velocity);
        w.f64s(&[p.step_size, p.rho_inf, p.tolerance, p.accuracy]);
        w.i32(p.max_iterations);
        w.i32(p.formulation.item());
        w.i32(p.stiffening.item());
        w.i32(p.frames);
        w.i32(p.anderson_depth);
        w.i32(p.integrator.item());
        w.i32(p.modes);
        w.u8(u8::from(p.nonlinear_forces));
        w.u8(u8::from(p.auto));
        w.u8(u8::from(p.linear));
        self.inputs.iter().for_each(|i| w.f64s(i));
        for d in &self.input_derivatives {
            w.f64s(&d[0]);
            w.f64s(&d[1]);
        }
        w.f64s(&self.input_times);
        for f in &self.driving {
            w.f64s(f.position.as_slice());
            w.f64s(f.rotation.transpose().as_slice());
            w.f64s(f.velocity.as_slice());
            w.f64s(f.angular_velocity.as_slice());
            w.f64s(f.acceleration.as_slice());
            w.f64s(f.angular_acceleration.as_slice());
            w.f64(f.changed_at);
            w.f64(f.rate_span);
            w.f64(f.updated_at);
            f.offset.iter().for_each(|o| w.f64s(o.as_slice()));
            w.f64(if f.sheds { 1.0 } else { 0.0 });
        }
        w.f64(self.last_step_size);
        w.f64(self.start_time);
        w.u8(u8::from(self.stop_time.is_some()));
        w.f64(self.stop_time.unwrap_or(0.0));
        self.counters.iter().for_each(|&c| w.u64(c));
        match &self.dynamics {
            None => w.u8(0),
            Some(d) => {
                w.u8(1);
                let s = &d.state;
                w.f64(s.time);
                w.u64(s.position.len() as u64);
                w.f64s(&s.position);
                w.f64s(&s.velocity);
                w.f64s(&s.acceleration);
                w.f64s(&s.pseudo_acceleration);
                w.u64(s.multipliers.len() as u64);
                w.f64s(&s.multipliers);
                d.loads.iter().for_each(|l| w.f64s(l));
                w.f64s(&d.gravity);
                w.u8(u8::from(d.features.nonlinear_forces)
                    | u8::from(d.features.stiffening) << 1
                    | u8::from(d.features.frames) << 2
                    | u8::from(d.features.frames_refused) << 3
                    | u8::from(d.features.linear) << 4
                    | u8::from(d.features.slab_stiffening) << 5);
                w.f64s(&d.quiet_since);
                w.u32(d.ladder.level);
                w.u32(d.ladder.calm_steps);
                w.u32(d.ladder.probe_after);
                w.u8(u8::from(d.ladder.probed));
                w.u32(d.ladder.since_motion_jump);
                w.u8(u8::from(d.ladder.sampled_motion));
                w.f64(d.deformation_scale);
                w.f64(d.high_mode_scale);
                w.f64(d.estimate_floor);
                w.f64(d.slab_stiffening_ratio);
                w.u8(u8::from(d.slab_stiffening_since.is_some()));
                w.f64(d.slab_stiffening_since.unwrap_or(0.0));
                w.f64(d.scale_settling.since);
                w.f64(d.scale_settling.scale);
                w.u8(u8::from(d.scale_settling.settled));
                w.f64(s.step_size);
                let carried = s.iteration_error_ratio.is_finite();
                w.u8(u8::from(carried));
                w.f64(if carried {
                    s.iteration_error_ratio
                } else {
                    0.0
                });
            }
        }
    }
}

impl Slave {
    /// Reads a payload written by [`SlaveState::write_bytes`] for this body; every count, number
    /// and parameter is checked (see the module documentation).
    pub fn state_from_bytes(&self, bytes: &[u8]) -> Result<SlaveState> {
        let mut r = Reader::new(bytes);
        let format = r.u32("the payload format")?;
        if format != PAYLOAD_FORMAT {
            return Err(Error::new(format!(
                "the serialized FMU state has payload format {format}; this FMU reads format {PAYLOAD_FORMAT}"
            )));
        }
        let n = r.u32("the interface count")? as usize;
        if n != self.inputs.len() {
            return Err(Error::new(format!(
                "the serialized FMU state has {n} interfaces, this body has {}: it belongs to another body",
                self.inputs.len()
            )));
        }
        let p = self.read_parameters(&mut r)?;
        let mut inputs: Vec<Inputs> = vec![[0.0; INTERFACE_SLOTS]; n];
        for i in &mut inputs {
            r.f64s(i, "an input")?;
        }
        let mut input_derivatives: Vec<InputDerivatives> = vec![[[0.0; INTERFACE_SLOTS]; 2]; n];
        for d in &mut input_derivatives {
            r.f64s(&mut d[0], "an input derivative")?;
            r.f64s(&mut d[1], "an input derivative")?;
        }
        let mut input_times = vec![0.0; n];
        r.f64s(&mut input_times, "an input sample time")?;
        let mut driving = vec![DrivingFrame::default(); n];
        for f in &mut driving {
            let mut v = [0.0; 40];
            r.f64s(&mut v, "a driving frame")?;
            f.position = Vector3::from_column_slice(&v[0..3]);
            f.rotation = Matrix3::from_row_slice(&v[3..12]);
            f.velocity = Vector3::from_column_slice(&v[12..15]);
            f.angular_velocity = Vector3::from_column_slice(&v[15..18]);
            f.acceleration = Vector3::from_column_slice(&v[18..21]);
            f.angular_acceleration = Vector3::from_column_slice(&v[21..24]);
            f.changed_at = v[24];
            f.rate_span = v[25];
            f.updated_at = v[26];
            for (k, o) in f.offset.iter_mut().enumerate() {
                *o = Vector3::from_column_slice(&v[27 + 3 * k..30 + 3 * k]);
            }
            f.sheds = match v[39] {
                0.0 => false,
                1.0 => true,
                other => {
                    return Err(Error::new(format!(
                        "the serialized FMU state has {other} for whether a driving frame sheds its offset, which is 0 or 1"
                    )))
                }
            };
        }
        let last_step_size = r.f64("the last step size")?;
        let start_time = r.f64("the start time")?;
        let stop_defined = r.boolean("whether the stop time is defined")?;
        let stop_time = r.f64("the stop time")?;
        let stop_time = stop_defined.then_some(stop_time);
        if let Some(stop) = stop_time.filter(|&stop| stop < start_time) {
            return Err(Error::new(format!(
                "the serialized FMU state's stop time {stop} is before its start time {start_time}"
            )));
        }
        let counters = [
            r.u64("the step counter")?,
            r.u64("the iteration counter")?,
            r.u64("the retry counter")?,
            r.u64("the rejected-step counter")?,
        ];
        let dynamics = self.read_dynamics(&mut r, &p, n)?;
        if r.at != bytes.len() {
            return Err(Error::new(format!(
                "the serialized FMU state has {} bytes after its end (byte {})",
                bytes.len() - r.at,
                r.at
            )));
        }
        Ok(SlaveState {
            parameters: p,
            inputs,
            input_derivatives,
            input_times,
            driving,
            last_step_size,
            start_time,
            stop_time,
            dynamics,
            counters,
        })
    }

    /// The parameters of a payload, checked as `fmi2SetReal`/`fmi2SetInteger` would.
    fn read_parameters(&self, r: &mut Reader) -> Result<Parameters> {
        let mut p = self.defaults.clone();
        let mut head = [0.0; 5];
        r.f64s(&mut head, "material and damping parameters")?;
        p.material = IsotropicMaterial {
            youngs_modulus: head[0],
            poisson_ratio: head[1],
            density: head[2],
        };
        p.damping_alpha = head[3];
        p.damping_beta = head[4];
        r.f64s(&mut p.gravity, "gravity")?;
        r.f64s(&mut p.initial_position, "initial.position")?;
        r.f64s(&mut p.initial_rotation, "initial.rotation")?;
        r.f64s(&mut p.initial_velocity, "initial.velocity")?;
        r.f64s(&mut p.initial_angular_velocity, "initial.angularVelocity")?;
        let mut solver = [0.0; 4];
        r.f64s(&mut solver, "solver parameters")?;
        [p.step_size, p.rho_inf, p.tolerance, p.accuracy] = solver;
        p.max_iterations = r.i32("solver.maxIterations")?;
        p.formulation = r.choice("model.formulation", Formulation::from_item)?;
        p.stiffening = r.choice("model.stiffening", Stiffening::from_item)?;
        p.frames = r.i32("model.frames")?;
        p.anderson_depth = r.i32("solver.andersonDepth")?;
        p.integrator = r.choice("solver.integrator", Integrator::from_item)?;
        p.modes = r.i32("model.modes")?;
        p.nonlinear_forces = r.boolean("model.nonlinearForces")?;
        p.auto = r.boolean("model.auto")?;
        p.linear = r.boolean("model.linear")?;
        check_parameters(&p)?;
        Ok(p)
    }

    /// The dynamics of a payload for parameters `p` and `n` interfaces (`None` before
    /// initialization); every count is checked against this body.
    fn read_dynamics(&self, r: &mut Reader, p: &Parameters, n: usize) -> Result<Option<Dynamics>> {
        Ok(match r.u8("the initialization flag")? {
            0 => None,
            1 => {
                let time = r.f64("the time")?;
                let n3 = if p.modes == 0 {
                    let n3 = 3 * (self.mesh.node_count() + self.mass_points.len());
                    r.count(n3, "position coordinates")?;
                    n3
                } else {
                    // A reduced body: 3 per field, at most 3 per mesh node; `set_state` checks
                    // the count against the reduction it builds.
                    let n3 = r.u64("position coordinates")?;
                    if n3 % 3 != 0 || n3 > 3 * self.mesh.node_count() as u64 {
                        return Err(Error::new(format!(
                            "the serialized FMU state has {n3} position coordinates: not a reduced body of this mesh ({} nodes)",
                            self.mesh.node_count()
                        )));
                    }
                    n3 as usize
                };
                let mut vectors = [vec![0.0; n3], vec![0.0; n3], vec![0.0; n3], vec![0.0; n3]];
                for (v, what) in vectors.iter_mut().zip([
                    "positions",
                    "velocities",
                    "accelerations",
                    "pseudo-accelerations",
                ]) {
                    r.f64s(v, what)?;
                }
                let multipliers = if p.modes == 0 {
                    let multipliers = self.multiplier_count();
                    r.count(multipliers, "constraint multipliers")?;
                    multipliers
                } else {
                    // A reduced body's rigid sets are 3 or 4 points each, fewer rows than on the
                    // mesh; `set_state` checks the count against the model it builds.
                    let m = r.u64("constraint multipliers")?;
                    if m > self.multiplier_count() as u64 {
                        return Err(Error::new(format!(
                            "the serialized FMU state has {m} constraint multipliers, more than this body's {} on its mesh: it belongs to another body",
                            self.multiplier_count()
                        )));
                    }
                    m as usize
                };
                let mut lambda = vec![0.0; multipliers];
                r.f64s(&mut lambda, "the constraint multipliers")?;
                let mut loads: Vec<Inputs> = vec![[0.0; INTERFACE_SLOTS]; n];
                for l in &mut loads {
                    r.f64s(l, "the loads of the state")?;
                }
                let mut gravity = [0.0; 3];
                r.f64s(&mut gravity, "the gravity of the state")?;
                let features = match r.u8("the terms in force")? {
                    b @ 0..=63 => super::Features {
                        nonlinear_forces: b & 1 != 0,
                        stiffening: b & 2 != 0,
                        frames: b & 4 != 0,
                        frames_refused: b & 8 != 0,
                        linear: b & 16 != 0,
                        slab_stiffening: b & 32 != 0,
                    },
                    b => {
                        return Err(Error::new(format!(
                            "the serialized FMU state holds {b} for the terms in force: not 0 to 63"
                        )))
                    }
                };
                let mut quiet_since = [0.0; 3];
                r.f64s(
                    &mut quiet_since,
                    "the times since the terms' indicators are quiet",
                )?;
                let step_level = r.u32("the step level")?;
                if step_level > super::step_control::MAX_LEVEL {
                    return Err(Error::new(format!(
                        "the serialized FMU state holds step level {step_level}: more than {}",
                        super::step_control::MAX_LEVEL
                    )));
                }
                let calm_steps = r.u32("the calm steps on the step level")?;
                let probe_after = r.u32("the steps the next probe of the step level waits for")?;
                let probed = match r.u8("whether the step level came from a probe")? {
                    0 => false,
                    1 => true,
                    b => {
                        return Err(Error::new(format!(
                            "the serialized FMU state holds {b} for whether the step level came from a probe: not 0 or 1"
                        )))
                    }
                };
                let probe_range =
                    super::step_control::PROBE_FIRST..=super::step_control::PROBE_LAST;
                if !probe_range.contains(&probe_after) {
                    return Err(Error::new(format!(
                        "the serialized FMU state holds {probe_after} for the steps the next probe waits for: not within {probe_range:?}"
                    )));
                }
                let since_motion_jump =
                    r.u32("the internal steps since a motion input last jumped")?;
                let sampled_motion = r.boolean("whether the motion inputs are sampled")?;
                let deformation_scale = r.f64("the deformation scale")?;
                let high_mode_scale = r.f64("the scale of the modes above the lowest")?;
                let estimate_floor = r.f64("the estimate floor")?;
                let slab_stiffening_ratio = r.f64("the slabs' stiffening ratio")?;
                let ramped = r.boolean("whether model.auto switched the slabs' stiffening on")?;
                let since = r.f64("when the slabs' stiffening came on")?;
                if since > time {
                    return Err(Error::new(format!(
                        "the serialized FMU state has the slabs' stiffening come on at t = {since}, after its time {time}"
                    )));
                }
                let slab_stiffening_since = ramped.then_some(since);
                let settling_since = r.f64("since when the deformation scale has not grown")?;
                if settling_since > time {
                    return Err(Error::new(format!(
                        "the serialized FMU state has the deformation scale unchanged since t = {settling_since}, after its time {time}"
                    )));
                }
                let settling_scale = r.f64("the deformation scale the settling is counted from")?;
                let settled = r.boolean("whether the deformation scale has settled")?;
                for (scale, name) in [
                    (slab_stiffening_ratio, "slabs' stiffening ratio"),
                    (estimate_floor, "estimate floor"),
                    (deformation_scale, "deformation scale"),
                    (high_mode_scale, "scale of the modes above the lowest"),
                    (
                        settling_scale,
                        "deformation scale the settling is counted from",
                    ),
                ] {
                    if scale < 0.0 {
                        return Err(Error::new(format!(
                            "the serialized FMU state holds a negative {name} {scale}"
                        )));
                    }
                }
                let step_size = r.f64("the last internal step's length")?;
                if !(step_size.is_finite() && step_size >= 0.0) {
                    return Err(Error::new(format!(
                        "the serialized FMU state holds {step_size} for the last internal step's length: not finite and at least 0"
                    )));
                }
                let carried = r.boolean("whether an iteration's error ratio is carried")?;
                let ratio = r.f64("the iteration's error ratio")?;
                // `θ/(1 − θ)` with `θ ≤ 0.5`, or that grown by a power below 1: in [0, 1];
                // carried only after a step of the length given.
                if !(0.0..=1.0).contains(&ratio)
                    || (!carried && ratio != 0.0)
                    || (carried && step_size == 0.0)
                {
                    return Err(Error::new(format!(
                        "the serialized FMU state holds {ratio} for the iteration's error ratio (carried: {carried}, after a step of {step_size} s): not in [0, 1], 0 when not carried, carried only after a step"
                    )));
                }
                let iteration_error_ratio = if carried { ratio } else { f64::INFINITY };
                let [position, velocity, acceleration, pseudo_acceleration] = vectors;
                Some(Dynamics {
                    state: DynamicState {
                        time,
                        position,
                        velocity,
                        acceleration,
                        pseudo_acceleration,
                        multipliers: lambda,
                        step_size,
                        iteration_error_ratio,
                    },
                    loads,
                    gravity,
                    features,
                    quiet_since,
                    ladder: super::step_control::Ladder {
                        level: step_level,
                        calm_steps,
                        probe_after,
                        probed,
                        since_motion_jump,
                        sampled_motion,
                    },
                    deformation_scale,
                    high_mode_scale,
                    estimate_floor,
                    slab_stiffening_ratio,
                    slab_stiffening_since,
                    scale_settling: super::step_control::ScaleSettling {
                        since: settling_since,
                        scale: settling_scale,
                        settled,
                    },
                })
            }
            b => {
                return Err(Error::new(format!(
                    "the serialized FMU state holds {b} for the initialization flag: not 0 or 1"
                )))
            }
        })
    }
}

/// The parameter checks of `fmi2SetReal`/`fmi2SetInteger` for a deserialized set.
fn check_parameters(p: &Parameters) -> Result<()> {
    for (name, key, value) in [
        (
            "material.youngsModulus",
            FixedKey::YoungsModulus,
            p.material.youngs_modulus,
        ),
        (
            "material.poissonRatio",
            FixedKey::PoissonRatio,
            p.material.poisson_ratio,
        ),
        ("material.density", FixedKey::Density, p.material.density),
        ("damping.alpha", FixedKey::DampingAlpha, p.damping_alpha),
        ("damping.beta", FixedKey::DampingBeta, p.damping_beta),
        ("solver.stepSize", FixedKey::StepSize, p.step_size),
        ("solver.rhoInf", FixedKey::RhoInf, p.rho_inf),
        ("solver.tolerance", FixedKey::Tolerance, p.tolerance),
        ("model.accuracy", FixedKey::Accuracy, p.accuracy),
    ] {
        Parameters::check_real(name, key, value)
            .map_err(|e| Error::new(format!("the serialized FMU state: {}", e.message)))?;
    }
    let bad = |name: &str, value: i32, why: &str| {
        Err(Error::new(format!(
            "the serialized FMU state: {name} = {value} rejected: {why}"
        )))
    };
    if p.max_iterations < 1 {
        return bad(
            "solver.maxIterations",
            p.max_iterations,
            "must be at least 1",
        );
    }
    if p.frames < 1 {
        return bad("model.frames", p.frames, "must be at least 1");
    }
    if p.modes < crate::model::body_file::MODES_AUTO {
        return bad("model.modes", p.modes, "must be at least -1 (auto)");
    }
    if !(0..=crate::solver::anderson::MAX_DEPTH as i32).contains(&p.anderson_depth) {
        return bad("solver.andersonDepth", p.anderson_depth, "not in [0, 8]");
    }
    Ok(())
}
