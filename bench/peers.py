"""Peer models of B1 in Exudyn, on exactly our mesh and matrices (issue 7).

    python bench/peers.py --matrices DIR --reference REF.csv --csv OUT.csv [--quick]

DIR holds what `cargo run --release --example export_matrices -- DIR` writes for B1 (the
default cantilever, hex20 20x2x2, 621 nodes, 1863 DOF): node positions with their HRZ-lumped
masses, the consistent mass Ms (M = Ms (x) I3) and the small-strain stiffness K. Exudyn's
FEMinterface takes them as they are (nodes 'Position', massMatrix, stiffnessMatrix as scipy CSR),
so the peers differ from our models only by their formulation and integrator, not by the mesh.

Problem (B1 dynamic, as `examples/work_precision.rs`): root face x = 0 clamped, 10 N in -y applied
at t = 0 on the tip face x = 1 m, distributed over its nodes with the HRZ weights (our force
interface's distribution), no damping, 0.1 s. Output: the same weighted average of the tip nodes'
y displacement (our `tip.position[2]`), sampled every 2 ms and compared with REF.csv (our
`reducedStrain` at h = 2.5e-5 s, written by work_precision). Integrator: Exudyn's generalized-alpha
(index-2 constraints), spectral radius 0.9 as our body file's rhoInf, modified Newton (Jacobian
kept while it converges), solution files off, sensors stored in memory.

Models:
* `Exudyn FFRF CB-8`: ObjectFFRFreducedOrder (C++ mass and force terms, no Python user functions)
  on a Hurty-Craig-Bampton basis from FEMinterface.ComputeHurtyCraigBamptonModes with the root face
  as the one (RBE2) boundary: its rigid-body modes are removed, so the basis is the 8 lowest
  fixed-root eigenmodes. The root face does not move against the reference frame in any mode, so
  the root is clamped by a GenericJoint of all 6 axes between the ground and the frame's rigid-body
  node (the same trajectory as a joint on a MarkerSuperElementRigid over the root nodes, measured
  4-5x faster).
* `Exudyn FFRF CB-8 + tip`: the same with the tip face as a second RBE2 boundary: 6 static modes
  of the tip interface + 8 fixed-interface eigenmodes (14 modal coordinates); it carries the static
  response to the tip load exactly, the tip face rigid.
* `Exudyn full FFRF`: ObjectFFRF with all nodal DOF (the nonlinear FFRF mass matrix); the
  reference frame's rigid-body node is fixed to the ground (a GenericJoint on all 6 axes) and every
  root node's three coordinates by CoordinateConstraints: exactly our clamp. Run at h = 2e-3 and
  1e-3 s for 0.02 s only (it is slow: its steps/s are the figure, its error covers only that
  window and is not comparable with the 0.1 s runs) with Exudyn's sparse solver (EigenSparse; the dense default is far slower).

Timing: wall time of mbs.SolveDynamic (assembly and initialisation of the solver included, the
mode computation not), median of three runs (one for the full FFRF). CSV columns as
work_precision's: problem,model,h,steps,wall_s,steps_per_s,max_error_m,relative_error.
"""

import argparse
import statistics
import sys
import time

import numpy as np
import scipy.sparse as sp

import exudyn as exu
from exudyn.itemInterface import (
    CoordinateConstraint,
    GenericJoint,
    LoadForceVector,
    MarkerBodyRigid,
    MarkerNodeCoordinate,
    MarkerNodeRigid,
    MarkerSuperElementPosition,
    ObjectGround,
    NodePointGround,
    SensorMarker,
)
from exudyn.FEM import (
    FEMinterface,
    HCBstaticModeSelection,
    ObjectFFRFinterface,
    ObjectFFRFreducedOrderInterface,
)

SAMPLE = 2e-3  # s, as work_precision's communication step
END = 0.1  # s
FORCE = 10.0  # N, in -y


def load_fem(directory):
    nodes = np.loadtxt(f"{directory}/nodes.txt")
    x, w = nodes[:, :3], nodes[:, 3]
    n = len(x)
    ms = np.loadtxt(f"{directory}/mass.txt")
    ms = sp.csr_matrix((ms[:, 2], (ms[:, 0].astype(int), ms[:, 1].astype(int))), shape=(n, n))
    k = np.loadtxt(f"{directory}/stiffness.txt")
    k = sp.csr_matrix((k[:, 2], (k[:, 0].astype(int), k[:, 1].astype(int))), shape=(3 * n, 3 * n))
    fem = FEMinterface()
    fem.nodes = {"Position": x}
    fem.massMatrix = sp.kron(ms, sp.identity(3), format="csr")
    fem.stiffnessMatrix = k
    fem.surface = [{"Name": "none", "Trigs": np.zeros((0, 3), dtype=int)}]
    length = x[:, 0].max()
    root = [int(i) for i in np.flatnonzero(np.abs(x[:, 0]) < 1e-9)]
    tip = [int(i) for i in np.flatnonzero(np.abs(x[:, 0] - length) < 1e-9)]
    return fem, w, root, tip


def settings(h, end, sparse):
    s = exu.SimulationSettings()
    if sparse:
        s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    s.timeIntegration.numberOfSteps = int(round(end / h))
    s.timeIntegration.endTime = end
    s.timeIntegration.verboseMode = 0
    s.timeIntegration.generalizedAlpha.spectralRadius = 0.9
    s.timeIntegration.newton.useModifiedNewton = True
    s.solution.file.write = False
    s.solution.sensors.writePeriod = SAMPLE
    return s


def tip_load_and_sensor(mbs, body, w, tip):
    weights = w[tip] / w[tip].sum()
    marker = mbs.AddMarker(
        MarkerSuperElementPosition(bodyNumber=body, meshNodeNumbers=tip, weightingFactors=weights)
    )
    mbs.AddLoad(LoadForceVector(markerNumber=marker, loadVector=[0, -FORCE, 0]))
    return mbs.AddSensor(
        SensorMarker(
            markerNumber=marker,
            outputVariableType=exu.OutputVariableType.Position,
            storeInternal=True,
        )
    )


def build_reduced(fem, w, root, tip, with_tip_boundary):
    boundaries = [root, tip] if with_tip_boundary else [root]
    fem.ComputeHurtyCraigBamptonModes(
        boundaryNodesList=boundaries,
        nEigenModes=8,
        useSparseSolver=True,
        computationMode=HCBstaticModeSelection.RBE2,
    )
    cms = ObjectFFRFreducedOrderInterface(fem)
    modes = cms.nModes

    def make():
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        obj = cms.AddObjectFFRFreducedOrder(mbs, positionRef=[0, 0, 0])
        body = obj["oFFRFreducedOrder"]
        ground = mbs.AddObject(ObjectGround(referencePosition=[0, 0, 0]))
        m_root = mbs.AddMarker(MarkerNodeRigid(nodeNumber=obj["nRigidBody"]))
        m_ground = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[0, 0, 0]))
        mbs.AddObject(GenericJoint(markerNumbers=[m_ground, m_root], constrainedAxes=[1] * 6))
        sensor = tip_load_and_sensor(mbs, body, w, tip)
        mbs.Assemble()
        return sc, mbs, sensor

    return make, modes


def build_full(fem, w, root, tip):
    fem.modeBasis = {"matrix": np.zeros((3 * fem.NumberOfNodes(), 1)), "type": "none"}
    ffrf = ObjectFFRFinterface(fem)

    def make():
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        obj = ffrf.AddObjectFFRF(exu, mbs, positionRef=[0, 0, 0], constrainRigidBodyMotion=False)
        body = obj["oFFRF"]
        ground = mbs.AddObject(ObjectGround(referencePosition=[0, 0, 0]))
        m_ground = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[0, 0, 0]))
        m_frame = mbs.AddMarker(MarkerNodeRigid(nodeNumber=obj["nRigidBody"]))
        mbs.AddObject(GenericJoint(markerNumbers=[m_ground, m_frame], constrainedAxes=[1] * 6))
        n_ground = mbs.AddNode(NodePointGround(referenceCoordinates=[0, 0, 0]))
        m_fixed = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=n_ground, coordinate=0))
        for i in root:
            node = obj["nodeList"][i]
            for c in range(3):
                m = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=c))
                mbs.AddObject(CoordinateConstraint(markerNumbers=[m_fixed, m]))
        sensor = tip_load_and_sensor(mbs, body, w, tip)
        mbs.Assemble()
        return sc, mbs, sensor

    return make


def run(make, h, end, sparse):
    sc, mbs, sensor = make()
    s = settings(h, end, sparse)
    started = time.perf_counter()
    mbs.SolveDynamic(s)
    wall = time.perf_counter() - started
    data = mbs.GetSensorStoredData(sensor)
    return data[:, 0], data[:, 2], wall


def error_against(reference, t, y):
    """Largest |y - y_ref| at the reference's samples that the run covers."""
    ref_t, ref_y = reference
    k = np.rint(t / SAMPLE).astype(int)
    keep = (np.abs(t - k * SAMPLE) < 1e-9) & (k < len(ref_y))
    return float(np.max(np.abs(y[keep] - ref_y[k[keep]])))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--matrices", required=True)
    parser.add_argument("--reference", required=True)
    parser.add_argument("--csv", required=True)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()

    ref = np.loadtxt(args.reference, delimiter=",", skiprows=1)
    reference = (ref[:, 0], ref[:, 1])
    peak = float(np.max(np.abs(ref[:, 1])))
    fem, w, root, tip = load_fem(args.matrices)
    n_dof = 3 * fem.NumberOfNodes()
    print(
        f"Exudyn {exu.config.Version()}; B1 on our hex20 mesh ({fem.NumberOfNodes()} nodes, "
        f"{n_dof} DOF, root {len(root)} nodes, tip {len(tip)} nodes); reference peak |tip y| = "
        f"{peak:.4e} m\n"
    )
    print("| peer model | h (s) | simulated (s) | steps | wall (ms, median) | steps/s | max tip error (m) | error / peak |")
    print("|---|---|---|---|---|---|---|---|")
    rows = []
    steps_cb = [2e-3, 5e-4] if args.quick else [2e-3, 1e-3, 5e-4, 2.5e-4, 1e-4]
    repeats = 1 if args.quick else 3
    started = time.perf_counter()
    cases = []
    for with_tip in (False, True):
        make, modes = build_reduced(fem, w, root, tip, with_tip)
        label = "Exudyn FFRF CB-8 + tip" if with_tip else "Exudyn FFRF CB-8"
        label_long = f"{label} ({modes} modal coordinates)"
        cases += [(label, label_long, make, h, END, repeats) for h in steps_cb]
    full_end = 0.01 if args.quick else 0.02
    make_full = build_full(fem, w, root, tip)
    for h in [2e-3] if args.quick else [2e-3, 1e-3]:
        cases.append(("Exudyn full FFRF", f"Exudyn full FFRF ({n_dof} nodal DOF)", make_full, h, full_end, 1))
    print(f"(models built in {time.perf_counter() - started:.1f} s)\n", file=sys.stderr)
    for label, label_long, make, h, end, runs in cases:
        walls = []
        for _ in range(runs):
            t, y, wall = run(make, h, end, label == "Exudyn full FFRF")
            walls.append(wall)
        wall = statistics.median(walls)
        steps = int(round(end / h))
        err = error_against(reference, t, y)
        print(
            f"| {label_long} | {h:g} | {end:g} | {steps} | {1e3 * wall:.1f} | {steps / wall:.3g} "
            f"| {err:.3e} | {err / peak:.2e} |",
            flush=True,
        )
        rows.append(f"B1,{label},{h:e},{steps},{wall:.6e},{steps / wall:.6e},{err:.6e},{err / peak:.6e}")
    with open(args.csv, "w") as f:
        f.write("problem,model,h,steps,wall_s,steps_per_s,max_error_m,relative_error\n")
        f.write("\n".join(rows) + "\n")
    print(f"\nExudyn version: {exu.config.Version()}")


if __name__ == "__main__":
    main()
