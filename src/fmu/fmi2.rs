//! The FMI 2.0 co-simulation entry points of an exported FMU (feature `fmi`, in the shared
//! library `rodcube fmu` zips, the same for every model): `fmi2Instantiate` loads the tapes in
//! the FMU's `resources/` (`<model>.tape.json`: the system and its fast phases) into the
//! registry, a model compiled into the library with the same program keeping its compiled
//! code, and reads the model and the parameters' start values from
//! `resources/rodcube.json`; `fmi2ExitInitializationMode` binds the
//! parameters and solves the release, and `fmi2DoStep` walks the motion with the planner's
//! [`Walker`] (the phases `rodcube run` solves), phase by phase as far as the step's end, and
//! samples it there: a step that crosses an event (a contact opening or closing, an impact)
//! gets the phase after it, solved to the tolerance of `fmi2SetupExperiment`.
//!
//! Architecture invariant: no panic crosses the boundary. Every entry point runs inside
//! `catch_unwind`; a caught panic puts the instance in its error state and returns
//! `fmi2Error`. Every refusal is logged through the host's logger callback.

use super::{RESOURCES, Resources, Role, Variable, guid, variables};
use crate::model::Model;
use crate::plan::{DEFAULT_TOLERANCE, ODE_RTOL_FACTOR, ODE_RTOL_FLOOR};
use crate::report::prose;
use crate::results::Work;
use crate::solve::SolveError;
use crate::solve::phases::{Motion, PhaseRun, Walker};
use crate::solve::series::{full_state_at, sample_at, sample_forces};
use crate::system::{Bound, check_value};
use std::ffi::{CStr, CString, c_char, c_int, c_uint, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// `fmi2OK`.
pub const FMI2_OK: c_int = 0;
/// `fmi2Warning`.
pub const FMI2_WARNING: c_int = 1;
/// `fmi2Discard`: the step stopped early (the motion ended; see `fmi2Terminated`).
pub const FMI2_DISCARD: c_int = 2;
/// `fmi2Error`.
pub const FMI2_ERROR: c_int = 3;
/// `fmi2CoSimulation` (`fmi2Type`).
pub const FMI2_CO_SIMULATION: c_int = 1;
/// `fmi2DoStepStatus` (`fmi2StatusKind`).
const DO_STEP_STATUS: c_int = 0;
/// `fmi2LastSuccessfulTime` (`fmi2StatusKind`).
const LAST_SUCCESSFUL_TIME: c_int = 2;
/// `fmi2Terminated` (`fmi2StatusKind`).
const TERMINATED: c_int = 3;

/// Two communication times closer than this, relative to the larger (and to 1 s), are the
/// same time: what a host's sum of steps rounds away.
const TIME_SLACK: f64 = 1e-12;

/// The host's logger (`fmi2CallbackLogger`; a C variadic function, called here with the
/// message as its format, `%` doubled, and no further arguments).
pub type Logger =
    unsafe extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char, ...);

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct CallbackFunctions {
    /// `logger`.
    pub logger: Option<Logger>,
    /// `allocateMemory` (not used: the library allocates with Rust's allocator).
    pub allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    /// `freeMemory` (not used).
    pub free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    /// `stepFinished` (not used: `fmi2DoStep` finishes before it returns).
    pub step_finished: Option<unsafe extern "C" fn(*mut c_void, c_int)>,
    /// `componentEnvironment`, handed back to the logger.
    pub component_environment: *mut c_void,
}

/// Where an instance is in FMI's state machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Instantiated,
    Initialization,
    Stepping,
    Terminated,
    Failed,
}

/// The motion being followed: the walker, the phases solved so far and the work done.
struct Sim {
    walker: Walker<'static>,
    motion: Motion<'static>,
    work: Work,
    /// The phase index of the motion's first phase: the phases before it, where the
    /// parameters were changed during the motion (the motion taken up again mid-phase).
    first_phase: usize,
}

/// One FMU instance (an `fmi2Component`).
struct Instance {
    name: CString,
    model: &'static dyn Model,
    /// The models the motion may use (the system's fast phases among them), as the registry
    /// held them once this instance's tapes were loaded.
    registry: &'static [&'static dyn Model],
    vars: Vec<Variable>,
    logger: Option<Logger>,
    env: *mut c_void,
    start_values: Vec<f64>,
    values: Vec<f64>,
    tolerance: f64,
    start_time: f64,
    stop_time: Option<f64>,
    mode: Mode,
    sim: Option<Sim>,
    /// The current communication point (s, the host's time).
    time: f64,
    /// Each variable's value at `time` (the parameters' included), by value reference.
    outputs: Vec<f64>,
    phase: c_int,
    terminated: bool,
}

/// A refusal: its status and the message logged.
struct Refusal(c_int, String);

fn refuse<T>(message: impl Into<String>) -> Result<T, Refusal> {
    Err(Refusal(FMI2_ERROR, message.into()))
}

impl Instance {
    /// Logs `message` with `status` through the host's logger, if it gave one.
    fn log(&self, status: c_int, message: &str) {
        log(self.logger, self.env, &self.name, status, message);
    }

    fn expect_mode(&self, allowed: &[Mode], call: &str) -> Result<(), Refusal> {
        if allowed.contains(&self.mode) {
            return Ok(());
        }
        refuse(format!(
            "{call} is not allowed now (the instance is {:?})",
            self.mode
        ))
    }

    /// Binds the parameters and solves the release: the motion's first phase.
    fn start(&mut self) -> Result<(), Refusal> {
        let general = Bound::from_values(self.model, &self.values)
            .map_err(|e| Refusal(FMI2_ERROR, format!("the parameters were refused: {e}")))?;
        let until = match self.stop_time {
            Some(stop) if stop > self.start_time => Some(stop - self.start_time),
            Some(stop) => {
                return refuse(format!(
                    "the stop time {stop} s is not after the start time {} s",
                    self.start_time
                ));
            }
            None => None,
        };
        let walker = Walker::new(
            general,
            self.registry,
            self.tolerance,
            (self.tolerance * ODE_RTOL_FACTOR).max(ODE_RTOL_FLOOR),
        )
        .with_until(until);
        let mut work = Work::default();
        let first = walker.release().and_then(|(start, opened)| {
            let run = walker.solve(&start, &mut work)?;
            Ok(Motion::starting(run, opened, until.is_some()))
        });
        let motion = first.map_err(|e| Refusal(FMI2_ERROR, format!("at release: {e}")))?;
        self.sim = Some(Sim {
            walker,
            motion,
            work,
            first_phase: 0,
        });
        self.time = self.start_time;
        self.terminated = false;
        self.sample(0.0)
    }

    /// Sets the outputs to the motion at `t` (s from release).
    fn sample(&mut self, t: f64) -> Result<(), Refusal> {
        let Some(sim) = self.sim.as_mut() else {
            return refuse("the motion has not started");
        };
        let failed = |e: SolveError| Refusal(FMI2_ERROR, format!("at t = {t} s: {e}"));
        let phase = sim
            .outputs(t, &self.vars, &mut self.outputs)
            .map_err(failed)?;
        self.phase =
            c_int::try_from(phase).map_err(|_| Refusal(FMI2_ERROR, "too many phases".into()))?;
        Ok(())
    }

    /// `fmi2DoStep`: follows the motion to `current + step`.
    fn step(&mut self, current: f64, step: f64) -> Result<c_int, Refusal> {
        self.expect_mode(&[Mode::Stepping], "fmi2DoStep")?;
        if !(step >= 0.0 && step.is_finite() && current.is_finite()) {
            return refuse(format!("a step of {step} s from {current} s"));
        }
        if !same_time(current, self.time) {
            return refuse(format!(
                "the step starts at {current} s, but the instance is at {} s",
                self.time
            ));
        }
        if self.terminated {
            return Err(Refusal(FMI2_DISCARD, "the motion has ended".into()));
        }
        let target = current + step;
        let t = target - self.start_time;
        let Some(sim) = self.sim.as_mut() else {
            return refuse("the motion has not started");
        };
        sim.reach(t).map_err(|e| {
            Refusal(
                FMI2_ERROR,
                format!("following the motion to t = {t} s: {e}"),
            )
        })?;
        let end = sim.motion.end_time();
        if sim.motion.complete() && t > end && !same_time(t, end) {
            self.sample(end)?;
            self.time = self.start_time + end;
            self.terminated = true;
            let why = format!(
                "the motion ended at t = {end} s ({}); the step to {target} s stopped there",
                self.sim.as_ref().map_or_else(String::new, Sim::ending)
            );
            return Err(Refusal(FMI2_DISCARD, why));
        }
        self.sample(t.min(end))?;
        self.time = target;
        Ok(FMI2_OK)
    }

    /// `fmi2SetReal`: parameters only; before the motion starts each value checked at once
    /// (finite, positive where declared, a friction coefficient not negative), the
    /// requirements between them at `fmi2ExitInitializationMode`; between steps the tunable
    /// ones ([`Instance::tune`]).
    fn set_real(&mut self, refs: &[c_uint], values: &[f64]) -> Result<c_int, Refusal> {
        if self.mode == Mode::Stepping {
            return self.tune(refs, values);
        }
        self.expect_mode(&[Mode::Instantiated, Mode::Initialization], "fmi2SetReal")?;
        for (&vr, &value) in refs.iter().zip(values) {
            let i = self.parameter(vr)?;
            check_value(self.model.info(), i, value)
                .map_err(|e| Refusal(FMI2_ERROR, format!("fmi2SetReal: {e}")))?;
            self.values[i] = value;
            self.outputs[vr as usize] = value;
            // Outputs read in initialization mode were of the values before.
            self.sim = None;
        }
        Ok(FMI2_OK)
    }

    /// The parameter index of value reference `vr`, or why it cannot be set.
    fn parameter(&self, vr: c_uint) -> Result<usize, Refusal> {
        let var = self.variable(vr)?;
        match var.role {
            Role::Parameter { index, .. } => Ok(index),
            _ => refuse(format!("{} is an output; it cannot be set", var.name)),
        }
    }

    /// `fmi2SetReal` between steps: tunable parameters only (a fixed one is refused), each
    /// value checked and the requirements between them too, then the motion taken up at the
    /// current communication point with the new values: the system's positions and velocities
    /// there kept, the contacts decided again as after an event, and the motion solved on from
    /// there. A refusal leaves the parameters and the motion as they were.
    fn tune(&mut self, refs: &[c_uint], values: &[f64]) -> Result<c_int, Refusal> {
        if refs.is_empty() {
            return Ok(FMI2_OK);
        }
        let info = self.model.info();
        let mut new = self.values.clone();
        for (&vr, &value) in refs.iter().zip(values) {
            let var = self.variable(vr)?;
            let Role::Parameter { index, tunable } = var.role else {
                return refuse(format!("{} is an output; it cannot be set", var.name));
            };
            if !tunable {
                return refuse(format!(
                    "{} ({}) is a fixed parameter, the geometry or the release state: it is \
                     set before fmi2ExitInitializationMode (or after fmi2Reset), not between \
                     steps",
                    var.name, var.unit
                ));
            }
            check_value(info, index, value)
                .map_err(|e| Refusal(FMI2_ERROR, format!("fmi2SetReal: {e}")))?;
            new[index] = value;
        }
        let general = Bound::from_values(self.model, &new)
            .map_err(|e| Refusal(FMI2_ERROR, format!("the parameters were refused: {e}")))?;
        let t = self.time - self.start_time;
        let Some(sim) = self.sim.as_mut() else {
            return refuse("the motion has not started");
        };
        if self.terminated || (sim.motion.complete() && t >= sim.motion.end_time()) {
            return refuse(format!(
                "the motion has ended (at t = {} s); there is no motion to change",
                sim.motion.end_time()
            ));
        }
        sim.restart(general, t).map_err(|e| {
            Refusal(
                FMI2_ERROR,
                format!("taking the motion up at t = {t} s with the new parameters: {e}"),
            )
        })?;
        for (&vr, &value) in refs.iter().zip(values) {
            self.outputs[vr as usize] = value;
        }
        self.values = new;
        self.sample(t)?;
        Ok(FMI2_OK)
    }

    /// Makes the outputs available: in initialization mode (FMI's initial unknowns) by solving
    /// the release with the parameters as they are, as `fmi2ExitInitializationMode` will.
    fn outputs_ready(&mut self) -> Result<(), Refusal> {
        match (&self.sim, self.mode) {
            (Some(_), _) => Ok(()),
            (None, Mode::Initialization) => self.start(),
            (None, _) => refuse("the outputs are computed from fmi2EnterInitializationMode on"),
        }
    }

    /// `fmi2GetReal`.
    fn get_real(&mut self, refs: &[c_uint], values: &mut [f64]) -> Result<c_int, Refusal> {
        for (&vr, value) in refs.iter().zip(values.iter_mut()) {
            let var = self.variable(vr)?;
            *value = match var.role {
                Role::Parameter { index, .. } => self.values[index],
                Role::Phase => return refuse(format!("{} is an Integer", var.name)),
                _ => {
                    self.outputs_ready()?;
                    self.outputs[vr as usize]
                }
            };
        }
        Ok(FMI2_OK)
    }

    /// `fmi2GetInteger`: the phase index.
    fn get_integer(&mut self, refs: &[c_uint], values: &mut [c_int]) -> Result<c_int, Refusal> {
        for (&vr, value) in refs.iter().zip(values.iter_mut()) {
            let var = self.variable(vr)?;
            if var.role != Role::Phase {
                return refuse(format!("{} is a Real", var.name));
            }
            self.outputs_ready()?;
            *value = self.phase;
        }
        Ok(FMI2_OK)
    }

    fn variable(&self, vr: c_uint) -> Result<&Variable, Refusal> {
        match self.vars.get(vr as usize) {
            Some(v) => Ok(v),
            None => refuse(format!("no variable with value reference {vr}")),
        }
    }

    /// `fmi2Reset`: back to the state after `fmi2Instantiate`.
    fn reset(&mut self) {
        self.values = self.start_values.clone();
        self.outputs = vec![0.0; self.vars.len()];
        for (i, v) in self.values.iter().enumerate() {
            self.outputs[i] = *v;
        }
        self.tolerance = DEFAULT_TOLERANCE;
        self.start_time = 0.0;
        self.stop_time = None;
        self.mode = Mode::Instantiated;
        self.sim = None;
        self.time = 0.0;
        self.phase = 0;
        self.terminated = false;
    }
}

/// Logs `message` with `status` through `logger`, if there is one (the message is the format,
/// its `%` doubled, and there are no further arguments).
fn log(logger: Option<Logger>, env: *mut c_void, name: &CStr, status: c_int, message: &str) {
    let Some(logger) = logger else { return };
    let text = message.replace('%', "%%").replace('\0', " ");
    let Ok(text) = CString::new(text) else { return };
    let category: &CStr = if status == FMI2_OK {
        c"logAll"
    } else {
        c"logStatusError"
    };
    // SAFETY: the host's logger, called with its environment, NUL-terminated strings that live
    // across the call, and a format without conversions.
    unsafe {
        logger(env, name.as_ptr(), status, category.as_ptr(), text.as_ptr());
    }
}

/// Whether two communication times are the same (within [`TIME_SLACK`]).
fn same_time(a: f64, b: f64) -> bool {
    (a - b).abs() <= TIME_SLACK * a.abs().max(b.abs()).max(1.0)
}

impl Sim {
    /// How the motion ended, for a message.
    fn ending(&self) -> String {
        if let Some(halt) = &self.motion.halted {
            return format!("halted: {}", prose::halt_words(halt));
        }
        match self.motion.last_end() {
            Some(end) => prose::event_words(end),
            None => "no phase".into(),
        }
    }

    /// Solves phases until one runs past `t` (s from release) or the motion ends.
    fn reach(&mut self, t: f64) -> Result<(), SolveError> {
        while !self.motion.complete() && self.motion.end_time() <= t {
            self.walker.step(&mut self.motion, &mut self.work)?;
        }
        Ok(())
    }

    /// The phase that runs at `t`, as `rodcube run`'s series choose it: the last one starting
    /// at or before `t` that lasts past it; at the motion's end, the one ending there.
    fn phase_at(&self, t: f64) -> Option<usize> {
        let end = self.motion.end_time();
        let phases = || self.motion.phases.iter();
        if t < end {
            phases().rposition(|p| p.t_start() <= t && t < p.t_end())
        } else {
            (phases().rposition(|p| p.t_start() < end && p.t_end() >= end))
                .or_else(|| phases().rposition(|p| p.t_start() <= t && p.t_end() >= end))
        }
    }

    /// The motion taken up at `t` (s from release, within the solved motion) with the
    /// parameters of `general`: the system's state there (positions and velocities; in a fast
    /// phase too), the contacts decided as after an event ([`Walker::resume`]) and the next
    /// phase solved from there. On an error the motion is left as it was.
    fn restart(&mut self, general: Bound<'static>, t: f64) -> Result<(), SolveError> {
        let k = self.phase_at(t).ok_or(SolveError::Inversion {
            target: t,
            duration: self.motion.end_time(),
            reason: "no solved phase runs at this time",
        })?;
        let phase = &self.motion.phases[k];
        let held = phase.closed()?;
        let (state, friction_work) = full_state_at(phase, t - phase.t_start(), &mut self.work)?;
        let walker = Walker {
            general,
            ..self.walker.clone()
        };
        let start = walker.resume(state, t, &held, friction_work)?;
        let run = walker.solve(&start, &mut self.work)?;
        let through = self.motion.through_impacts;
        self.motion = Motion::starting(run, Vec::new(), through);
        self.walker = walker;
        self.first_phase += k;
        Ok(())
    }

    /// Every variable's value at `t` (s from release, within the solved motion) into `out`
    /// (the parameters' left as they are); returns the phase's index.
    fn outputs(&mut self, t: f64, vars: &[Variable], out: &mut [f64]) -> Result<usize, SolveError> {
        let k = self.phase_at(t).ok_or(SolveError::Inversion {
            target: t,
            duration: self.motion.end_time(),
            reason: "no solved phase runs at this time",
        })?;
        let phase: &PhaseRun = &self.motion.phases[k];
        let s = sample_at(phase, &[(t - phase.t_start()).max(0.0)], &mut self.work)?;
        let forces = sample_forces(phase, &s)?;
        let (Some(state), Some(forces)) = (s.states.first(), forces.first()) else {
            return Err(SolveError::Inversion {
                target: t,
                duration: phase.duration(),
                reason: "the phase gave no sample",
            });
        };
        let points = phase.bound().points(state)?;
        let missing = |what: &str, i: usize| SolveError::PhaseMismatch {
            system: self.walker.general.info().name,
            name: phase.bound().info().name,
            why: format!("it has no {what} {i}"),
        };
        for (vr, v) in vars.iter().enumerate() {
            out[vr] = match v.role {
                Role::Parameter { .. } | Role::Phase => continue,
                Role::Angle => *s.theta.first().ok_or_else(|| missing("angle sample", 0))?,
                Role::Rate => *s
                    .theta_dot
                    .first()
                    .ok_or_else(|| missing("rate sample", 0))?,
                Role::Force(i) => *forces.get(i).ok_or_else(|| missing("contact", i))?,
                Role::PointX(i) => points.pos.get(i).ok_or_else(|| missing("point", i))?[0],
                Role::PointY(i) => points.pos.get(i).ok_or_else(|| missing("point", i))?[1],
            };
        }
        Ok(self.first_phase + k)
    }
}

/// The path of the directory a `file:` URI names (`file:///a/b`, `file:/a/b`,
/// `file://localhost/a/b`; the scheme in any case), its percent escapes decoded, or why it
/// names none: empty, another scheme, another host, a bad escape, not UTF-8.
fn uri_path(uri: &str) -> Result<PathBuf, String> {
    let bad = |why: &str| {
        Err(format!(
            "the resource location {uri:?} is not the file: URI of a local directory: {why}"
        ))
    };
    if uri.is_empty() {
        return Err(
            "the host gave no resource location (the file: URI of the unzipped FMU's \
                    resources/ directory, where its model's tapes are)"
                .into(),
        );
    }
    let Some(rest) = (uri.get(..5))
        .filter(|scheme| scheme.eq_ignore_ascii_case("file:"))
        .and_then(|_| uri.get(5..))
    else {
        return bad("it does not start with `file:`");
    };
    let rest = match rest.strip_prefix("//") {
        Some(r) if r.starts_with('/') => r,
        Some(r) => match r.get(..9) {
            Some(host) if host.eq_ignore_ascii_case("localhost") => &r[9..],
            _ => return bad("it names another host"),
        },
        None => rest,
    };
    if !rest.starts_with('/') {
        return bad("its path is not absolute");
    }
    let bytes = rest.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = |j: usize| bytes.get(j).and_then(|&b| (b as char).to_digit(16));
            let (Some(hi), Some(lo)) = (hex(i + 1), hex(i + 2)) else {
                return bad("a `%` not followed by two hexadecimal digits");
            };
            // Two hexadecimal digits: at most 255.
            out.push(u8::try_from(hi * 16 + lo).unwrap_or(u8::MAX));
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    match String::from_utf8(out) {
        Ok(path) => Ok(PathBuf::from(path)),
        Err(_) => bad("its decoded path is not UTF-8"),
    }
}

/// The FMU's resources directory from its location: the directory itself, or (as some hosts
/// give) the unzipped FMU's root with `resources/` in it.
fn resources_dir(location: &str) -> Result<PathBuf, String> {
    let dir = uri_path(location)?;
    if dir.join(RESOURCES).is_file() {
        return Ok(dir);
    }
    let inner = dir.join("resources");
    if inner.join(RESOURCES).is_file() {
        return Ok(inner);
    }
    Err(format!(
        "the resource location {location:?} ({}) holds no {RESOURCES}: it is not the resources/ \
         directory of an FMU that `rodcube fmu` wrote, or the FMU was not unzipped whole",
        dir.display()
    ))
}

/// Loads the tapes in `dir` (the FMU's `resources/`) into the registry and finds the system
/// `name` there: the model and the registry as it stands (its fast phases in it). One loading
/// at a time, so an instance made on another thread at once sees its own models.
fn models_in(
    dir: &Path,
    name: &str,
) -> Result<(&'static dyn Model, &'static [&'static dyn Model]), String> {
    static LOADING: Mutex<()> = Mutex::new(());
    let _one = LOADING.lock().unwrap_or_else(|e| e.into_inner());
    crate::models::load(dir).map_err(|e| format!("the FMU's model was refused: {e}"))?;
    let registry = crate::models::all();
    let model = (registry.iter().copied())
        .find(|m| m.info().name == name)
        .ok_or_else(|| {
            format!(
                "no model `{name}`: {} has no {name}.tape.json and this library does not \
                 compile it in; export the FMU again with `rodcube fmu {name}` (and \
                 --models DIR where its tape is)",
                dir.display()
            )
        })?;
    Ok((model, registry))
}

/// A new instance from `fmi2Instantiate`'s arguments, or why not.
fn instantiate(
    name: &str,
    kind: c_int,
    guid_given: &str,
    resources: &str,
    logger: Option<Logger>,
    env: *mut c_void,
) -> Result<Instance, String> {
    if kind != FMI2_CO_SIMULATION {
        return Err("this FMU is for co-simulation only (fmi2CoSimulation)".into());
    }
    let dir = resources_dir(resources)?;
    let path = dir.join(RESOURCES);
    let text = std::fs::read_to_string(&path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let res: Resources =
        serde_json::from_str(&text).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let (model, registry) = models_in(&dir, &res.model)?;
    let info = model.info();
    let own = guid(info).map_err(|e| e.to_string())?;
    if own != guid_given || own != res.guid {
        return Err(format!(
            "GUID {guid_given} is not that of the model `{}` ({own}) this FMU's tapes hold: \
             the FMU was made by another rodcube, or its files were changed",
            info.name
        ));
    }
    if res.start.len() != info.parameters.len() {
        return Err(format!(
            "{} gives {} start values for {} parameters",
            path.display(),
            res.start.len(),
            info.parameters.len()
        ));
    }
    let vars = variables(info).map_err(|e| e.to_string())?;
    let mut instance = Instance {
        name: CString::new(name).map_err(|e| e.to_string())?,
        model,
        registry,
        outputs: vec![0.0; vars.len()],
        vars,
        logger,
        env,
        values: res.start.clone(),
        start_values: res.start,
        tolerance: DEFAULT_TOLERANCE,
        start_time: 0.0,
        stop_time: None,
        mode: Mode::Instantiated,
        sim: None,
        time: 0.0,
        phase: 0,
        terminated: false,
    };
    instance.reset();
    Ok(instance)
}

/// A C string argument, or why not (NULL, not UTF-8).
///
/// # Safety
/// `s` is NULL or a NUL-terminated string.
unsafe fn text<'a>(s: *const c_char, what: &str) -> Result<&'a str, String> {
    if s.is_null() {
        return Err(format!("{what} is NULL"));
    }
    // SAFETY: the caller gives a NUL-terminated string.
    unsafe { CStr::from_ptr(s) }
        .to_str()
        .map_err(|e| format!("{what} is not UTF-8: {e}"))
}

/// Runs `body` on the instance behind `c`, logging a refusal and catching a panic (which
/// leaves the instance failed).
///
/// # Safety
/// `c` is NULL or a live instance from `fmi2Instantiate`.
unsafe fn with(
    c: *mut c_void,
    body: impl FnOnce(&mut Instance) -> Result<c_int, Refusal>,
) -> c_int {
    // SAFETY: as the caller promises.
    let Some(instance) = (unsafe { c.cast::<Instance>().as_mut() }) else {
        return FMI2_ERROR;
    };
    let outcome = catch_unwind(AssertUnwindSafe(|| body(&mut *instance)));
    match outcome {
        Ok(Ok(status)) => status,
        Ok(Err(Refusal(status, message))) => {
            let _ = catch_unwind(AssertUnwindSafe(|| instance.log(status, &message)));
            status
        }
        Err(_) => {
            instance.mode = Mode::Failed;
            let _ = catch_unwind(AssertUnwindSafe(|| {
                instance.log(
                    FMI2_ERROR,
                    "internal error: rodcube panicked (please report it)",
                )
            }));
            FMI2_ERROR
        }
    }
}

/// `n` values at `p` as a slice (empty for `n == 0`).
///
/// # Safety
/// For `n > 0`, `p` is NULL or points to `n` readable values.
unsafe fn slice<'a, T>(p: *const T, n: usize) -> Result<&'a [T], Refusal> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return refuse("an array argument is NULL");
    }
    // SAFETY: the caller gives `n` readable values.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// `n` writable values at `p` as a slice (empty for `n == 0`).
///
/// # Safety
/// For `n > 0`, `p` is NULL or points to `n` writable values.
unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Result<&'a mut [T], Refusal> {
    if n == 0 {
        return Ok(&mut []);
    }
    if p.is_null() {
        return refuse("an array argument is NULL");
    }
    // SAFETY: the caller gives `n` writable values.
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

mod entry;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resource_locations_are_file_uris_percent_decoded() {
        let ok = |uri: &str| uri_path(uri).unwrap_or_else(|e| panic!("{uri}: {e}"));
        assert_eq!(ok("file:///tmp/a/resources"), Path::new("/tmp/a/resources"));
        assert_eq!(ok("file:/tmp/a"), Path::new("/tmp/a"));
        assert_eq!(ok("FILE://LocalHost/tmp/a"), Path::new("/tmp/a"));
        assert_eq!(
            ok("file:///tmp/un%20zipped%25/r%C3%A9sources/"),
            Path::new("/tmp/un zipped%/résources/")
        );
        let refused = |uri: &str, why: &str| {
            let e = uri_path(uri)
                .err()
                .unwrap_or_else(|| panic!("{uri} accepted"));
            assert!(e.contains(why), "{uri}: {e}");
        };
        refused("", "no resource location");
        refused("http://example.com/r", "does not start with `file:`");
        refused("/tmp/a", "does not start with `file:`");
        refused("file://server/share/r", "another host");
        refused("file:relative/r", "not absolute");
        refused("file:///tmp/a%2", "two hexadecimal digits");
        refused("file:///tmp/a%+1b", "two hexadecimal digits");
        refused("file:///tmp/%ff%fe", "not UTF-8");
    }

    #[test]
    fn the_resources_directory_is_the_location_or_its_resources() {
        let root = std::env::temp_dir().join(format!("rodcube-fmi2-{}", std::process::id()));
        let resources = root.join("resources");
        std::fs::create_dir_all(&resources).expect("temporary directory");
        let uri = |p: &Path| format!("file://{}", p.display());
        let none = resources_dir(&uri(&resources)).err().unwrap_or_default();
        assert!(none.contains("holds no rodcube.json"), "{none}");
        std::fs::write(resources.join(RESOURCES), "{}").expect("file");
        assert_eq!(resources_dir(&uri(&resources)), Ok(resources.clone()));
        assert_eq!(resources_dir(&uri(&root)), Ok(resources.clone()));
        let _ = std::fs::remove_dir_all(&root);
    }
}
