//! Results a person can look at: the deformed mesh at chosen times as VTK files for ParaView
//! (`output.directory`, `output.interval`), written outside the solver's hot path and only when
//! switched on.
//!
//! Each saved time gets `<directory>/<stem>_<frame>.vtu` with the current (deformed) node
//! positions and the point data
//!
//! * `displacement` (m): `x − X`, global axes (rigid motion included);
//! * `velocity` (m/s): `ẋ`, global axes;
//! * `deformation` (m): `ū = Rᵀ(x − c) − X̄`, the elastic part in the co-moving frame's axes;
//! * `vonMises` (Pa): the von Mises stress of the small-strain stress of `ū` (the reduced strain
//!   of the formulation, see [`crate::fem::stress`]), nodal-averaged;
//!
//! and `<directory>/<stem>.pvd` lists them with their times.

pub mod vtk;

use crate::body::Body;
use crate::fem::stress::{nodal_stress, von_mises};
use crate::fem::IsotropicMaterial;
use crate::mesh::Mesh;
use std::path::PathBuf;
use vtk::{Collection, PointData};

/// Writes the `.vtu` files and the `.pvd` collection of one run.
pub struct ResultWriter {
    directory: PathBuf,
    stem: String,
    /// Smallest time between saved states (s); 0: every communication point.
    interval: f64,
    collection: Collection,
    /// (time, file name) of the saved states listed in the collection.
    entries: Vec<(f64, String)>,
    /// Frames written so far (numbers the files; never reused).
    frames: usize,
    next_time: f64,
}

impl ResultWriter {
    /// Creates `directory` (and parents) and an empty `<stem>.pvd` in it; the error says which
    /// path failed and why.
    pub fn create(directory: &str, stem: &str, interval: f64) -> Result<ResultWriter, String> {
        let directory = PathBuf::from(directory);
        std::fs::create_dir_all(&directory)
            .map_err(|e| format!("cannot create the directory {}: {e}", directory.display()))?;
        let pvd = directory.join(format!("{stem}.pvd"));
        let collection =
            Collection::create(&pvd).map_err(|e| format!("cannot write {}: {e}", pvd.display()))?;
        Ok(ResultWriter {
            directory,
            stem: stem.to_string(),
            interval,
            collection,
            entries: Vec::new(),
            frames: 0,
            next_time: f64::NEG_INFINITY,
        })
    }

    /// The `.pvd` file.
    pub fn collection_path(&self) -> PathBuf {
        self.directory.join(format!("{}.pvd", self.stem))
    }

    /// Whether a state at time `t` (s) is to be saved: the first one, then once `interval` has
    /// passed since the last saved one (with a relative slack of 1e-9 for accumulated times), and
    /// any time earlier than the last saved one (after the importer restored an FMU state).
    pub fn is_due(&self, t: f64) -> bool {
        match self.entries.last() {
            None => true,
            Some(&(last, _)) => t < last || t >= self.next_time - 1e-9 * t.abs().max(1.0),
        }
    }

    /// Writes the state at time `t`: positions `x`, velocities `v` (flat `3N`).
    pub fn write(
        &mut self,
        t: f64,
        mesh: &Mesh,
        material: &IsotropicMaterial,
        body: &Body,
        x: &[f64],
        v: &[f64],
    ) -> Result<(), String> {
        // Going back in time (a restored FMU state): forget the saved states from t on.
        if self.entries.last().is_some_and(|&(last, _)| t <= last) {
            self.entries.retain(|&(time, _)| time < t);
            let pvd = self.collection_path();
            self.collection = Collection::create(&pvd)
                .map_err(|e| format!("cannot write {}: {e}", pvd.display()))?;
            for (time, file) in &self.entries {
                self.collection
                    .add(*time, file)
                    .map_err(|e| format!("cannot write {}: {e}", pvd.display()))?;
            }
        }
        let n = mesh.node_count();
        // The frame of the body's coordinates; a reduced body's nodes are `x_i = Σ_k S_ik q_k`.
        let frame = body.frame_weights.best_fit(x);
        let centroid = body.frame_weights.reference_centroid;
        // The mesh's nodes: a lumped body's mass points (after them) are not drawn.
        let (expanded, reference) = match &body.reduction {
            Some(r) => ((r.expand(x), r.expand(v)), &r.mesh_reference[..3 * n]),
            None => ((Vec::new(), Vec::new()), &body.reference[..3 * n]),
        };
        let (x, v) = match &body.reduction {
            Some(_) => (&expanded.0[..3 * n], &expanded.1[..3 * n]),
            None => (&x[..3 * n], &v[..3 * n]),
        };
        let displacement: Vec<f64> = x.iter().zip(reference).map(|(a, b)| a - b).collect();
        let mut deformation = vec![0.0; 3 * n];
        for i in 0..n {
            let xi = nalgebra::Vector3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
            let reference = nalgebra::Vector3::new(
                reference[3 * i],
                reference[3 * i + 1],
                reference[3 * i + 2],
            );
            let u = frame.rotation.transpose() * (xi - frame.origin) - (reference - centroid);
            deformation[3 * i..3 * i + 3].copy_from_slice(u.as_slice());
        }
        let stress: Vec<f64> = nodal_stress(mesh, material, &deformation)
            .iter()
            .map(von_mises)
            .collect();
        let text = vtk::unstructured_grid(
            mesh,
            x,
            &[
                PointData {
                    name: "displacement",
                    components: 3,
                    values: &displacement,
                },
                PointData {
                    name: "velocity",
                    components: 3,
                    values: v,
                },
                PointData {
                    name: "deformation",
                    components: 3,
                    values: &deformation,
                },
                PointData {
                    name: "vonMises",
                    components: 1,
                    values: &stress,
                },
            ],
        );
        let file = format!("{}_{:06}.vtu", self.stem, self.frames);
        let path = self.directory.join(&file);
        std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        self.frames += 1;
        self.collection
            .add(t, &file)
            .map_err(|e| format!("cannot write {}: {e}", self.collection_path().display()))?;
        self.entries.push((t, file));
        self.next_time = t + self.interval;
        Ok(())
    }
}
