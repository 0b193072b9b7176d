//! The body file's choices checked against the parameters before a model is built: what the
//! lumped bodies, material regions, reduced bodies and rigid sets support, each refusal an
//! error naming what is not supported and why.

use super::super::Slave;
use crate::error::{Error, Result};
use crate::model::enumerations::{Formulation, Integrator, Stiffening};
use crate::model::InterfaceKind;

impl Slave {
    /// Lumped bodies (mass points) ride on the mesh body with the reduced-strain formulation and
    /// no stiffening: anything else is an error naming the interface and what is not supported.
    pub(super) fn check_mass_points(&self) -> Result<()> {
        let p = &self.parameters;
        let unsupported = if p.formulation == Formulation::Full {
            Some("model.formulation = full")
        } else if p.stiffening != Stiffening::None {
            Some("model.stiffening other than none (the mass points carry no stress)")
        } else {
            None
        };
        match unsupported {
            Some(what) => {
                let name = self
                    .body_file
                    .interfaces
                    .iter()
                    .find(|i| i.mass.is_some())
                    .map_or("?", |i| i.name.as_str());
                Err(Error::new(format!(
                    "interface '{name}': a lumped body (mass) is not available with {what}"
                )))
            }
            None => Ok(()),
        }
    }

    /// Material regions are supported by the reduced-strain body, with one frame or several
    /// (each slab's elements with their own materials, as `model.auto`'s slabs), without
    /// `model.stiffening`: anything else is an error naming what is not supported.
    pub(super) fn check_regions(&self) -> Result<()> {
        let (p, regions) = (&self.parameters, &self.body_file.regions);
        if regions.is_empty() {
            return Ok(());
        }
        let unsupported = if p.formulation == Formulation::Full {
            Some("model.formulation = full")
        } else if p.stiffening != Stiffening::None {
            Some("model.stiffening other than none")
        } else if !p.output_directory.is_empty() {
            Some("output.directory (the stress output uses one material)")
        } else {
            None
        };
        match unsupported {
            Some(what) => Err(Error::new(format!(
                "material regions ('{}'{}) are supported by the reduced-strain body (one frame or several) without stiffening only, not with {what}",
                regions[0].name,
                if regions.len() > 1 { ", ..." } else { "" }
            ))),
            None => Ok(()),
        }
    }

    /// `inertial` stiffening acts on the one co-moving frame's deformation `ū`: with several
    /// frames, which turn apart from it, it is an error naming both parameters (on B3 with 20
    /// frames it moved the tip from 2.6e-3 to 1.4e-2 of the peak off `full`); `stress` with
    /// several frames is each slab's own (docs/formulation.md, "Geometric stiffening within the
    /// slabs").
    pub(in crate::slave) fn check_stiffening_frames(&self) -> Result<()> {
        let p = &self.parameters;
        if p.frames > 1
            && p.stiffening == Stiffening::Inertial
            && p.formulation != Formulation::Full
        {
            // `stress` is each slab's own prestress on the mesh; a reduced body has none.
            let instead = if p.modes == 0 {
                "with several frames use model.stiffening = stress, each slab's own prestress (docs/formulation.md, \"Geometric stiffening within the slabs\")"
            } else {
                "a reduced body with several frames takes no stiffening (model.stiffening = none)"
            };
            return Err(Error::new(format!(
                "model.stiffening = inertial with model.frames = {}: its unit load cases act on the one co-moving frame's deformation, which several frames replace; {instead}",
                p.frames
            )));
        }
        Ok(())
    }

    /// Whether a reduced body carries inertial stiffening from its driving motion
    /// (docs/formulation.md, "The reduced body"): `model.stiffening = inertial`, or, with a
    /// motion interface, whatever [`Self::decides_reduced_stiffening`] decides.
    pub(in crate::slave) fn reduced_stiffening(&self) -> bool {
        let p = &self.parameters;
        p.stiffening == Stiffening::Inertial
            || (p.stiffening == Stiffening::None && self.decides_reduced_stiffening())
    }

    /// Whether `model.auto` switches a reduced body's stiffening from the driving motion by
    /// itself, against `model.accuracy` (`slave::auto_features::choose_driven_stiffening`): a
    /// body held by one motion interface alone, with one frame, no lumped body and no material
    /// regions (which the stiffening does not support), generalized-α with
    /// `model.accuracy > 0`.
    pub(in crate::slave) fn decides_reduced_stiffening(&self) -> bool {
        let p = &self.parameters;
        p.auto
            && p.accuracy > 0.0
            && p.frames == 1
            && p.integrator == Integrator::GeneralizedAlpha
            && p.stiffening != Stiffening::Stress
            && self.mass_points.is_empty()
            && self.body_file.regions.is_empty()
            && self.driven_alone()
    }

    /// Whether the body is held by exactly one interface, a motion interface: the one whose
    /// driving motion is the rigid acceleration field of a reduced body's stiffening (with a
    /// second held interface the body's field is no one interface's).
    fn driven_alone(&self) -> bool {
        let held = |kinds: &[InterfaceKind]| {
            self.interfaces
                .iter()
                .filter(|i| kinds.contains(&i.kind))
                .count()
        };
        held(&[InterfaceKind::Motion]) == 1
            && held(&[InterfaceKind::Motion, InterfaceKind::Fixed]) == 1
    }

    /// `model.modes > 0` supports a reduced-strain body (one frame or `model.frames` slabs),
    /// generalized-α or Radau IIA, with `inertial` stiffening only when a motion interface drives
    /// it, with pins and hinges on rigid sets only;
    /// anything else is an error naming the parameter.
    pub(in crate::slave) fn check_reducible(&self) -> Result<()> {
        let p = &self.parameters;
        let reason = if p.formulation == Formulation::Full {
            Some(
                "model.formulation = full is the nonlinear reference on the whole mesh".to_string(),
            )
        } else if p.stiffening == Stiffening::Stress {
            Some("model.stiffening = stress: the stress of the current deformation is not projected on the fields (inertial is)".to_string())
        } else if p.stiffening == Stiffening::Inertial && !self.driven_alone() {
            Some("model.stiffening = inertial: a reduced body takes its prestress from the driving motion of its motion interface, and this body is not held by exactly one motion interface alone (on fixed supports the rigid acceleration is zero; with two held interfaces the body's field is no one interface's)".to_string())
        } else if p.integrator == Integrator::CentralDifference {
            Some("solver.integrator = centralDifference needs a lumped (diagonal) mass; the reduced mass is dense".to_string())
        } else {
            // A pin or hinge holds a point of a rigid set (its own, or another's on the same
            // nodes): a boundary set of the basis, whose points the constraint holds exactly.
            let specs = &self.body_file.interfaces;
            let rigid = self.rigid_attachments();
            let rigid_sets: Vec<&[usize]> = self
                .interfaces
                .iter()
                .zip(&rigid)
                .filter(|(_, &r)| r)
                .map(|(i, _)| &i.set.frame_weights.nodes[..])
                .collect();
            self.interfaces
                .iter()
                .zip(specs)
                .find(|(i, _)| {
                    matches!(i.kind, InterfaceKind::Pin | InterfaceKind::Hinge)
                        && !rigid_sets.iter().any(|set| {
                            i.set.frame_weights.nodes.iter().all(|n| set.contains(n))
                        })
                })
                .map(|(i, spec)| {
                    format!(
                        "interface '{}' is a {:?} support on nodes that are not a rigid set: a pin or hinge on a reduced body must be rigid (\"rigid\": true) or sit on a rigid attachment's nodes; otherwise use a fixed support, a motion interface or the mesh body (model.modes = 0)",
                        spec.name, i.kind
                    )
                })
                .or_else(|| {
                    // Two boundary sets of the basis may not share nodes (their affine motions
                    // would not be independent).
                    let held = self.interfaces.iter().zip(specs).filter(|(i, _)| {
                        matches!(i.kind, InterfaceKind::Fixed | InterfaceKind::Motion)
                    });
                    held.flat_map(|(h, h_spec)| {
                        self.interfaces
                            .iter()
                            .zip(specs)
                            .zip(&rigid)
                            .filter(move |((i, _), &r)| {
                                r && i
                                    .set
                                    .frame_weights
                                    .nodes
                                    .iter()
                                    .any(|n| h.set.frame_weights.nodes.contains(n))
                            })
                            .map(move |((_, spec), _)| (h_spec, spec))
                    })
                    .next()
                    .map(|(h_spec, spec)| {
                        format!(
                            "interface '{}' is a rigid attachment on nodes that '{}' holds: on a reduced body a rigid set and a {:?} interface may not share nodes",
                            spec.name, h_spec.name, h_spec.kind
                        )
                    })
                })
        };
        match reason {
            Some(r) => Err(Error::invalid_value(
                "model.modes",
                self.parameters.modes,
                &r,
            )),
            None => Ok(()),
        }
    }

    /// A rigid set may carry one held point (a pin, or a hinge, which on a rigid set holds the
    /// set's centroid and locks its rotation to the axis): two on one rigid set would hold the
    /// distance between them twice (the constraints are redundant and the iteration stalls on
    /// the conflict between their linearisations). Error naming the interfaces.
    pub(super) fn check_held_points_on_rigid_sets(&self) -> Result<()> {
        let specs = &self.body_file.interfaces;
        let is_rigid_set = self.rigid_attachments();
        for ((rigid, rigid_spec), _) in self
            .interfaces
            .iter()
            .zip(specs)
            .zip(&is_rigid_set)
            .filter(|(_, &r)| r)
        {
            let nodes = &rigid.set.frame_weights.nodes;
            let mut held = Vec::new();
            for (interface, spec) in self.interfaces.iter().zip(specs) {
                for (points, _) in &interface.point_constraints {
                    if points.iter().any(|n| nodes.contains(n)) {
                        held.push(format!("'{}'", spec.name));
                    }
                }
            }
            if held.len() > 1 {
                let count = held.len();
                held.dedup();
                return Err(Error::new(format!(
                    "interface '{}': its rigid set is held at {count} points (by {}), which holds the distance between them twice; a rigid set may be held by one pin or one hinge (which holds the set's centroid and locks its rotation to the axis)",
                    rigid_spec.name,
                    held.join(", ")
                )));
            }
        }
        Ok(())
    }

    /// Whether the body may be linear (docs/formulation.md, "The linear body"): forced by
    /// `model.linear`, or left to `model.auto` with `model.accuracy > 0` (generalized-α, neither
    /// `f_nl` nor stiffening allowed). Only a
    /// body held by fixed supports, nothing driving or pinning it, reduced strain with one
    /// frame: a body that moves or turns needs its frame to follow it. `model.linear` on any
    /// other body is an error naming the reason.
    pub(in crate::slave) fn linear_allowed(&self) -> Result<bool> {
        let p = &self.parameters;
        let has = |kind: InterfaceKind| self.interfaces.iter().any(|i| i.kind == kind);
        let reason = if has(InterfaceKind::Motion) {
            Some("a motion interface moves the body (its frame must follow it)")
        } else if has(InterfaceKind::Pin) || has(InterfaceKind::Hinge) {
            Some("a pin or hinge lets the body turn (its frame must follow it)")
        } else if self.rigid_attachments().iter().any(|&r| r) {
            Some("its rigid attachments' constraints are geometrically exact, which the linear body is not (and its steps iterate on them anyway)")
        } else if !has(InterfaceKind::Fixed) {
            Some("the body has no fixed support (a free body turns: its frame must follow it)")
        } else if p.formulation == Formulation::Full {
            Some("model.formulation = full is the geometrically exact body")
        } else if p.frames > 1 {
            Some("model.frames > 1: the slabs' frames follow the body")
        } else {
            None
        };
        // What the linear body cannot carry, when it is forced.
        let conflict = if p.nonlinear_forces && !p.auto {
            Some("model.nonlinearForces = true forces f_nl, which belongs to a frame that follows the body")
        } else if p.stiffening != Stiffening::None {
            Some("model.stiffening is the prestress of a frame that follows the body (its K_G would be turned by the held frame)")
        } else {
            None
        };
        match (p.linear, reason.or(conflict)) {
            (true, Some(reason)) => Err(Error::invalid_value("model.linear", "true", reason)),
            (true, None) => Ok(true),
            (false, Some(_)) => Ok(false),
            // Allowing f_nl or stiffening asks for the geometric effects the linear body
            // leaves out: model.auto does not take it then.
            (false, None) => Ok(p.auto
                && p.accuracy > 0.0
                && p.integrator == Integrator::GeneralizedAlpha
                && !p.nonlinear_forces
                && p.stiffening == Stiffening::None),
        }
    }
}
