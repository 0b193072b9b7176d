//! FMU states: the snapshot `fmi2GetFMUstate` hands out and its portable byte form
//! (`fmi2SerializeFMUstate`).

use super::{CoSimSlave, Instance, MachineState, ANY_BUT_FATAL, M};
use crate::fmi2::types::fmi2Status;
use crate::slave::StateReader;

/// Identifies a [`Snapshot`] made by this crate (a cheap guard against foreign pointers).
pub(super) const SNAPSHOT_MAGIC: u64 = 0x666c_6578_6d75_7374; // "flexmust"

/// The first bytes of a serialized FMU state.
///
/// Layout of `fmi2SerializeFMUstate`'s bytes (little-endian): the magic `FLEXBODY` (8 bytes),
/// the format version [`SERIALIZED_FORMAT`] (u32), the GUID (u32 length, UTF-8 bytes), the
/// calling-sequence state (u8) and the termination flag (u8), the payload length (u64) and the
/// slave's payload (`src/slave/state_bytes.rs`: positions, velocities, accelerations,
/// pseudo-accelerations, multipliers, inputs and their derivatives, parameters, counters as f64,
/// i32 and u64). The GUID covers the body file, the variable table and the crate version, so a
/// state of another body or another version is refused by name.
pub const SERIALIZED_MAGIC: &[u8; 8] = b"FLEXBODY";
/// Version of the serialized layout (header and payload together: bump on any change).
pub const SERIALIZED_FORMAT: u32 = 3;
/// Fixed bytes of the header besides the GUID.
const SERIALIZED_HEADER: usize = 8 + 4 + 4 + 1 + 1 + 8;

fn machine_state_code(m: MachineState) -> u8 {
    match m {
        M::Instantiated => 0,
        M::InitializationMode => 1,
        M::StepComplete => 2,
        M::StepFailed => 3,
        M::StepCanceled => 4,
        M::Terminated => 5,
        M::Error => 6,
        M::Fatal => 7,
    }
}

fn machine_state_from_code(code: u8) -> Option<MachineState> {
    Some(match code {
        0 => M::Instantiated,
        1 => M::InitializationMode,
        2 => M::StepComplete,
        3 => M::StepFailed,
        4 => M::StepCanceled,
        5 => M::Terminated,
        6 => M::Error,
        7 => M::Fatal,
        _ => return None,
    })
}

/// What `fmi2GetFMUstate` saves: the slave's snapshot and the calling-sequence state, so that
/// `fmi2SetFMUstate` after an `fmi2Discard` returns to StepComplete.
pub struct Snapshot<T> {
    pub(super) magic: u64,
    pub(super) guid: String,
    pub(super) slave: T,
    pub(super) machine: MachineState,
    pub(super) terminate_requested: bool,
}

impl<T> Snapshot<T> {
    /// Whether this looks like a snapshot made by this crate. A best-effort check: reading a
    /// snapshot the importer has already freed is outside FMI's contract (an FMU state must
    /// not be used after `fmi2FreeFMUstate` / `fmi3FreeFMUState`); the tag poisoned on drop
    /// makes such a use likely, not certain, to be caught.
    pub fn is_valid(&self) -> bool {
        self.magic == SNAPSHOT_MAGIC
    }
}

impl<T> Drop for Snapshot<T> {
    fn drop(&mut self) {
        // Poison the tag so a double free or use after free is more likely to be caught.
        self.magic = 0;
    }
}

impl<S: CoSimSlave> Instance<S> {
    /// `fmi2SerializeFMUstate`: the portable bytes of `snapshot` (layout in [`SERIALIZED_MAGIC`]).
    pub fn serialize_snapshot(
        &mut self,
        function: &str,
        snapshot: &Snapshot<S::State>,
    ) -> std::result::Result<Vec<u8>, fmi2Status> {
        self.check_state(function, ANY_BUT_FATAL)?;
        if !snapshot.is_valid() {
            return Err(self.fail(
                function,
                "FMUstate is not a live state of this FMU (freed, or from another FMU)",
            ));
        }
        let mut payload = Vec::new();
        self.slave.state_to_bytes(&snapshot.slave, &mut payload);
        let guid = snapshot.guid.as_bytes();
        let mut out = Vec::with_capacity(SERIALIZED_HEADER + guid.len() + payload.len());
        out.extend_from_slice(SERIALIZED_MAGIC);
        out.extend_from_slice(&SERIALIZED_FORMAT.to_le_bytes());
        out.extend_from_slice(&(guid.len() as u32).to_le_bytes());
        out.extend_from_slice(guid);
        out.push(machine_state_code(snapshot.machine));
        out.push(u8::from(snapshot.terminate_requested));
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(&payload);
        Ok(out)
    }

    /// `fmi2DeSerializeFMUstate`: a snapshot from bytes of [`Instance::serialize_snapshot`],
    /// checked: magic, format version, GUID (the same body and build), then the slave's payload.
    /// Bytes after the declared payload must be zero (an importer may pass a larger buffer).
    pub fn deserialize_snapshot(
        &mut self,
        bytes: &[u8],
    ) -> std::result::Result<Snapshot<S::State>, fmi2Status> {
        const F: &str = "fmi2DeSerializeFMUstate";
        self.check_state(F, ANY_BUT_FATAL)?;
        match self.parse_snapshot(bytes) {
            Ok(s) => Ok(s),
            Err(message) => Err(self.fail(F, &message)),
        }
    }

    fn parse_snapshot(&self, bytes: &[u8]) -> std::result::Result<Snapshot<S::State>, String> {
        if bytes.len() < SERIALIZED_MAGIC.len() || &bytes[..8] != SERIALIZED_MAGIC {
            return Err(format!(
                "the {} bytes are not a serialized state of this FMU (they do not start with \"FLEXBODY\")",
                bytes.len()
            ));
        }
        let message = |e: crate::Error| e.message;
        let mut r = StateReader::new(&bytes[SERIALIZED_MAGIC.len()..]);
        let format = r.u32("the format version").map_err(message)?;
        if format != SERIALIZED_FORMAT {
            return Err(format!(
                "the serialized FMU state has format version {format}; this FMU reads version {SERIALIZED_FORMAT} (it was written by another version of flexbody)"
            ));
        }
        let guid_len = r.u32("the GUID's length").map_err(message)? as usize;
        let guid =
            String::from_utf8_lossy(r.bytes(guid_len, "the GUID").map_err(message)?).into_owned();
        if guid != self.slave.guid() {
            return Err(format!(
                "the serialized FMU state belongs to an FMU with GUID {guid}; this instance has GUID {} (another body, body file or version of flexbody)",
                self.slave.guid()
            ));
        }
        let code = r.u8("the calling-sequence state").map_err(message)?;
        let machine = machine_state_from_code(code).ok_or_else(|| {
            format!("the serialized FMU state has an unknown calling-sequence state {code}")
        })?;
        let terminate_requested = match r.u8("the termination flag").map_err(message)? {
            0 => false,
            1 => true,
            b => {
                return Err(format!(
                    "the serialized FMU state has {b} as its termination flag: not 0 or 1"
                ))
            }
        };
        let len = r.u64("the payload length").map_err(message)?;
        let len =
            usize::try_from(len).map_err(|_| format!("the payload length {len} is too large"))?;
        let payload = r.bytes(len, "the payload").map_err(message)?;
        // An importer may pass a larger buffer: what follows the payload must be zero.
        if r.rest().iter().any(|&b| b != 0) {
            return Err(format!(
                "the serialized FMU state is followed by {} bytes that are not zero",
                r.rest().len()
            ));
        }
        let slave = self.slave.state_from_bytes(payload).map_err(message)?;
        Ok(Snapshot {
            magic: SNAPSHOT_MAGIC,
            guid,
            slave,
            machine,
            terminate_requested,
        })
    }

    /// `fmi2GetFMUstate` (new snapshot) — the caller boxes it or overwrites an old one.
    pub fn snapshot(
        &mut self,
        function: &str,
    ) -> std::result::Result<Snapshot<S::State>, fmi2Status> {
        self.check_state(function, ANY_BUT_FATAL)?;
        Ok(Snapshot {
            magic: SNAPSHOT_MAGIC,
            guid: self.slave.guid().to_string(),
            slave: self.slave.get_state(),
            machine: self.state,
            terminate_requested: self.terminate_requested,
        })
    }

    /// `fmi2SetFMUstate`: restores the slave and the calling-sequence state; the snapshot stays
    /// valid.
    pub fn restore(&mut self, snapshot: &Snapshot<S::State>) -> fmi2Status {
        const F: &str = "fmi2SetFMUstate";
        if let Err(s) = self.check_state(F, ANY_BUT_FATAL) {
            return s;
        }
        if !snapshot.is_valid() {
            return self.fail(
                F,
                "the FMU state is not a live state of this FMU (freed, or from another FMU)",
            );
        }
        if snapshot.guid != self.slave.guid() {
            return self.fail(
                F,
                &format!(
                    "the FMU state belongs to an FMU with GUID {}, this instance has {}",
                    snapshot.guid,
                    self.slave.guid()
                ),
            );
        }
        match self.slave.set_state(&snapshot.slave) {
            Ok(()) => {
                self.state = snapshot.machine;
                self.terminate_requested = snapshot.terminate_requested;
                self.logger.event(&format!(
                    "{F}: restored state {:?} at t = {}",
                    self.state,
                    self.slave.time()
                ));
                fmi2Status::fmi2OK
            }
            Err(e) => self.report(F, &e),
        }
    }

    /// Checks the state for `fmi2FreeFMUstate`.
    pub fn may_free_state(&mut self) -> std::result::Result<(), fmi2Status> {
        self.check_state("fmi2FreeFMUstate", ANY_BUT_FATAL)
    }
}
