//! Many instances in one process, stepped from different threads at the same time, give bit for
//! bit the results they give when stepped alone (no global state, no shared scratch).

#![cfg(any(
    all(
        target_os = "linux",
        any(target_arch = "x86_64", target_arch = "aarch64")
    ),
    all(target_os = "windows", target_arch = "x86_64")
))]

mod fmi2_support;

use flexbody::fmi2::exports::*;
use flexbody::fmi2::types::*;
use flexbody::model::{Causality, VariableType};
use flexbody::slave::Slave;
use fmi2_support::*;
use std::ptr::null_mut;
use std::sync::{Arc, Barrier};

const OK: fmi2Status = fmi2Status::fmi2OK;
const INSTANCES: usize = 8;
const STEPS: usize = 60;

struct Setup {
    guid: String,
    outputs: Vec<u32>,
    by_name: Vec<(String, u32)>,
}

fn setup() -> Setup {
    let s = Slave::from_resources(None).unwrap();
    Setup {
        guid: s.guid().to_string(),
        outputs: s
            .variables()
            .iter()
            .filter(|v| v.causality == Causality::Output && v.ty == VariableType::Real)
            .map(|v| v.value_reference)
            .collect(),
        by_name: s
            .variables()
            .iter()
            .map(|v| (v.name.clone(), v.value_reference))
            .collect(),
    }
}

fn vr(setup: &Setup, name: &str) -> u32 {
    setup.by_name.iter().find(|(n, _)| n == name).unwrap().1
}

/// Instance `k`: its own load, damping and step pattern (uneven steps, a state saved and
/// restored half-way); returns the outputs after every step. `barrier` lines the threads up
/// before the first step so that they really step at the same time.
fn run(setup: &Setup, k: usize, barrier: Option<&Barrier>) -> Vec<Vec<f64>> {
    let recorder = Recorder::default();
    let functions = callbacks(&recorder);
    let c = instantiate(
        Some(&format!("thread {k}")),
        fmi2CoSimulation,
        Some(&setup.guid),
        None,
        Some(&functions),
        false,
    );
    assert!(!c.is_null());
    let fz = vr(setup, "tip.force[3]");
    let fy = vr(setup, "tip.force[2]");
    unsafe {
        assert_eq!(
            fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0),
            OK
        );
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(
            set_real(c, &[vr(setup, "damping.beta")], &[1e-4 * k as f64]),
            OK
        );
        assert_eq!(set_real(c, &[fz], &[-(k as f64 + 1.0)]), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
    }
    if let Some(b) = barrier {
        b.wait();
    }
    let mut rows = Vec::with_capacity(STEPS);
    let mut t = 0.0;
    let mut saved: fmi2FMUstate = null_mut();
    for step in 0..STEPS {
        let h = if step % 3 == 0 { 1.5e-3 } else { 1e-3 };
        unsafe {
            if step == STEPS / 2 {
                assert_eq!(fmi2GetFMUstate(c, &mut saved), OK);
                // A detour that is undone: the results must not notice it.
                assert_eq!(set_real(c, &[fy], &[100.0]), OK);
                assert_eq!(fmi2DoStep(c, t, 5e-3, fmi2False), OK);
                assert_eq!(fmi2SetFMUstate(c, saved), OK);
            }
            assert_eq!(set_real(c, &[fy], &[(step as f64 * 0.1).sin()]), OK);
            assert_eq!(fmi2DoStep(c, t, h, fmi2True), OK, "instance {k} at t = {t}");
        }
        t += h;
        let (s, values) = get_real(c, &setup.outputs);
        assert_eq!(s, OK);
        rows.push(values);
    }
    unsafe {
        assert_eq!(fmi2FreeFMUstate(c, &mut saved), OK);
        assert_eq!(fmi2Terminate(c), OK);
        fmi2FreeInstance(c);
    }
    assert!(recorder.take().iter().all(|m| m.status == OK));
    rows
}

#[test]
fn eight_instances_on_eight_threads_match_their_runs_alone_bit_for_bit() {
    let setup = Arc::new(setup());
    let alone: Vec<Vec<Vec<f64>>> = (0..INSTANCES).map(|k| run(&setup, k, None)).collect();
    let barrier = Arc::new(Barrier::new(INSTANCES));
    let handles: Vec<_> = (0..INSTANCES)
        .map(|k| {
            let (setup, barrier) = (setup.clone(), barrier.clone());
            std::thread::spawn(move || run(&setup, k, Some(&barrier)))
        })
        .collect();
    let together: Vec<Vec<Vec<f64>>> = handles.into_iter().map(|h| h.join().unwrap()).collect();
    let bits =
        |r: &Vec<Vec<f64>>| -> Vec<u64> { r.iter().flatten().map(|x| x.to_bits()).collect() };
    for k in 0..INSTANCES {
        assert_eq!(bits(&together[k]), bits(&alone[k]), "instance {k}");
    }
    // Not vacuous: the instances differ from each other (different loads).
    let tip = setup
        .outputs
        .iter()
        .position(|&v| v == vr(&setup, "tip.position[3]"))
        .unwrap();
    let mut ends: Vec<u64> = alone.iter().map(|r| r[STEPS - 1][tip].to_bits()).collect();
    ends.sort();
    ends.dedup();
    assert_eq!(ends.len(), INSTANCES);
}
