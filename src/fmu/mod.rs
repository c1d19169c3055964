//! FMI 2.0 co-simulation export of a system: the variables an FMU of it has (its parameters,
//! and as outputs the reduced angle, its rate, every contact's force, the points' positions
//! and the phase index), its `modelDescription.xml` and the GUID that ties the description to
//! the model; `export` (feature `cli`) zips them with the shared library and the model's tapes
//! (the system's and its fast phases', in `resources/`) into `<model>.fmu`, and `fmi2`
//! (feature `fmi`) is that library's FMI 2.0 entry points, the same library for every model.
//!
//! Architecture invariant: the description and the library agree through [`variables`] alone:
//! the value reference of a variable is its index in that list, and [`guid`] hashes the list,
//! so a library whose variables differ from the description's refuses to instantiate.

#[cfg(feature = "cli")]
pub mod export;
#[cfg(feature = "fmi")]
pub mod fmi2;
#[cfg(feature = "cli")]
mod zip;

use crate::model::{ModelInfo, ParamInfo};
use crate::report::motion::xml as escape;
use crate::spec::units::{AngularUnit, Unit};
use std::fmt::Write;

/// The FMI 2.0 co-simulation functions a library must export (all of them, the unsupported
/// ones answering `fmi2Error`).
pub const FMI2_FUNCTIONS: &[&str] = &[
    "fmi2GetTypesPlatform",
    "fmi2GetVersion",
    "fmi2SetDebugLogging",
    "fmi2Instantiate",
    "fmi2FreeInstance",
    "fmi2SetupExperiment",
    "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode",
    "fmi2Terminate",
    "fmi2Reset",
    "fmi2GetReal",
    "fmi2GetInteger",
    "fmi2GetBoolean",
    "fmi2GetString",
    "fmi2SetReal",
    "fmi2SetInteger",
    "fmi2SetBoolean",
    "fmi2SetString",
    "fmi2GetFMUstate",
    "fmi2SetFMUstate",
    "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize",
    "fmi2SerializeFMUstate",
    "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative",
    "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives",
    "fmi2DoStep",
    "fmi2CancelStep",
    "fmi2GetStatus",
    "fmi2GetRealStatus",
    "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus",
    "fmi2GetStringStatus",
];

/// The file in the FMU's `resources/` that tells the library its model and start values.
pub const RESOURCES: &str = "rodcube.json";

/// `resources/rodcube.json`: the model and the parameters' start values (those of the model
/// description), which the host need not set.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Resources {
    /// The system's name.
    pub model: String,
    /// Its GUID ([`guid`]), as in the model description.
    pub guid: String,
    /// The parameters' start values, in the model's order.
    pub start: Vec<f64>,
}

/// What a variable of the FMU is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// A parameter: its index in [`ModelInfo::parameters`], and whether it is tunable (may be
    /// set between steps; [`tunable`]) or fixed.
    Parameter {
        /// Its index in [`ModelInfo::parameters`].
        index: usize,
        /// Whether it is tunable.
        tunable: bool,
    },
    /// The reduced coordinate (an output).
    Angle,
    /// The reduced coordinate's rate (an output).
    Rate,
    /// Contact `i`'s force (an output).
    Force(usize),
    /// The x coordinate of point `i` (an output).
    PointX(usize),
    /// The y coordinate of point `i` (an output).
    PointY(usize),
    /// The index of the phase the motion is in, from 0 at release (an Integer output).
    Phase,
}

/// Why a model description could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DescriptionError {
    /// The model's reduced coordinate is none of its coordinates (a malformed model).
    #[error("model `{model}`: its reduced coordinate {index} is none of its coordinates")]
    ReducedIndex {
        /// The model.
        model: &'static str,
        /// The index it gives.
        index: usize,
    },
    /// Not one start value per parameter.
    #[error("model `{model}` has {expected} parameters; {got} start values were given")]
    StartValues {
        /// The model.
        model: &'static str,
        /// Its number of parameters.
        expected: usize,
        /// The number of start values.
        got: usize,
    },
}

/// One variable of the FMU; its value reference is its index in [`variables`].
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    /// Its name in the model description.
    pub name: String,
    /// What it is.
    pub role: Role,
    /// Its SI unit as rodcube writes it (`kg`, `m/s^2`, `rad/s`, `N m`); empty for none.
    pub unit: &'static str,
    /// What it means, for people.
    pub description: String,
}

/// The variables of an FMU of `info`'s system, in value-reference order: its parameters, then
/// the angle, its rate, the contacts' forces and the points' positions (`<point>.x`,
/// `<point>.y`), then the phase index.
pub fn variables(info: &ModelInfo) -> Result<Vec<Variable>, DescriptionError> {
    let var = |name: String, role, unit, description: String| Variable {
        name,
        role,
        unit,
        description,
    };
    let mut out = Vec::new();
    for (index, p) in info.parameters.iter().enumerate() {
        let tunable = tunable(p);
        let what = if tunable { TUNABLE } else { FIXED };
        let role = Role::Parameter { index, tunable };
        out.push(var(
            p.name.into(),
            role,
            p.unit,
            format!("{}; {what}", p.meaning),
        ));
    }
    // The reduced coordinate and its rate, where the system has one.
    if let Some(index) = info.reduced_index {
        let angle =
            (info.coordinates.get(index).copied()).ok_or(DescriptionError::ReducedIndex {
                model: info.name,
                index,
            })?;
        let what = format!("the reduced coordinate {angle}");
        out.push(var(angle.into(), Role::Angle, "rad", what));
        let what = format!("the rate of {angle}");
        out.push(var(format!("{angle}_dot"), Role::Rate, "rad/s", what));
    }
    for (i, c) in info.contacts.iter().enumerate() {
        let v = var(c.name.into(), Role::Force(i), c.unit, c.meaning.into());
        out.push(v);
    }
    for (i, p) in info.points.iter().enumerate() {
        let (x, y) = (format!("{}.x", p.name), format!("{}.y", p.name));
        out.push(var(x, Role::PointX(i), "m", format!("x of {}", p.meaning)));
        out.push(var(y, Role::PointY(i), "m", format!("y of {}", p.meaning)));
    }
    let what = "the phase the motion is in: 0 from release, one more at each contact that \
                opens or closes";
    out.push(var("phase".into(), Role::Phase, "", what.into()));
    Ok(out)
}

/// What a tunable parameter's description adds.
const TUNABLE: &str = "tunable: set between steps, it changes the motion from that time on \
                       (positions and velocities kept, contacts decided again)";

/// What a fixed parameter's description adds.
const FIXED: &str = "fixed: a length or an angle (the geometry or the release state), set \
                     before fmi2ExitInitializationMode only";

/// Whether parameter `p` is tunable: whether a change of it during the motion leaves the
/// configuration admissible and still means something after release. Decided from its unit:
/// a length (`m`), an angle (`rad`) or the rate of either (`m/s`, `rad/s`) is the geometry or
/// the release state, fixed; every other parameter (a mass, gravity, a spring constant, a
/// friction or restitution coefficient) only weighs the forces, tunable. A unit rodcube
/// cannot read counts as fixed.
pub fn tunable(p: &ParamInfo) -> bool {
    let Ok(unit) = AngularUnit::parse(p.unit) else {
        return false;
    };
    let (length, speed) = (Unit::integers(0, 1, 0), Unit::integers(0, 1, -1));
    let geometric = (unit.rad().is_zero() && (unit.si() == length || unit.si() == speed))
        || unit.is_angle_or_rate();
    !geometric
}

/// The GUID of an FMU of `info`'s system: a hash of rodcube's version, the model's name and
/// its variables (names, roles and units), written as a UUID.
pub fn guid(info: &ModelInfo) -> Result<String, DescriptionError> {
    let mut text = format!("rodcube {} {}", env!("CARGO_PKG_VERSION"), info.name);
    for v in variables(info)? {
        let _ = write!(text, "|{}:{:?}:{}", v.name, v.role, v.unit);
    }
    let fnv = |offset: u64| {
        text.bytes().fold(offset, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
        })
    };
    let (a, b) = (fnv(0xcbf2_9ce4_8422_2325), fnv(0x84222325_cbf29ce4));
    Ok(format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        a >> 32,
        (a >> 16) & 0xffff,
        a & 0xffff,
        b >> 48,
        b & 0xffff_ffff_ffff
    ))
}

/// What the model description says beyond the model: the parameters' start values (in the
/// order of [`ModelInfo::parameters`]) and the default experiment.
#[derive(Debug, Clone, PartialEq)]
pub struct Defaults {
    /// Each parameter's start value.
    pub start: Vec<f64>,
    /// The default relative tolerance.
    pub tolerance: f64,
    /// The default stop time (s), if any.
    pub stop: Option<f64>,
    /// Where the start values come from, for the description.
    pub source: String,
}

/// The `modelDescription.xml` of an FMU of `info`'s system with `defaults`.
pub fn model_description(
    info: &ModelInfo,
    defaults: &Defaults,
) -> Result<String, DescriptionError> {
    let vars = variables(info)?;
    if defaults.start.len() != info.parameters.len() {
        return Err(DescriptionError::StartValues {
            model: info.name,
            expected: info.parameters.len(),
            got: defaults.start.len(),
        });
    }
    let mut x = String::new();
    let _ = writeln!(x, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        x,
        r#"<fmiModelDescription fmiVersion="2.0" modelName="{}" guid="{}" description="{}" generationTool="rodcube {}" variableNamingConvention="structured" numberOfEventIndicators="0">"#,
        info.name,
        guid(info)?,
        escape(&format!(
            "{} Start values: {}.",
            info.description, defaults.source
        )),
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(
        x,
        r#"  <CoSimulation modelIdentifier="{}" canHandleVariableCommunicationStepSize="true" canBeInstantiatedOnlyOncePerProcess="false" canNotUseMemoryManagementFunctions="true" canGetAndSetFMUstate="false" canSerializeFMUstate="false" providesDirectionalDerivative="false"/>"#,
        info.name
    );
    unit_definitions(&mut x, &vars);
    let stop = defaults.stop.map(|s| format!(r#" stopTime="{s:?}""#));
    let _ = writeln!(
        x,
        r#"  <DefaultExperiment startTime="0.0"{} tolerance="{:?}"/>"#,
        stop.unwrap_or_default(),
        defaults.tolerance
    );
    let _ = writeln!(x, "  <ModelVariables>");
    for (vr, v) in vars.iter().enumerate() {
        scalar_variable(&mut x, vr, v, defaults);
    }
    let _ = writeln!(x, "  </ModelVariables>\n  <ModelStructure>\n    <Outputs>");
    let outputs: Vec<usize> = (vars.iter().enumerate())
        .filter(|(_, v)| !matches!(v.role, Role::Parameter { .. }))
        .map(|(i, _)| i + 1)
        .collect();
    for i in &outputs {
        let _ = writeln!(x, r#"      <Unknown index="{i}"/>"#);
    }
    let _ = writeln!(x, "    </Outputs>\n    <InitialUnknowns>");
    for i in &outputs {
        let _ = writeln!(x, r#"      <Unknown index="{i}"/>"#);
    }
    let _ = writeln!(
        x,
        "    </InitialUnknowns>\n  </ModelStructure>\n</fmiModelDescription>"
    );
    Ok(x)
}

/// One `<ScalarVariable>`.
fn scalar_variable(x: &mut String, vr: usize, v: &Variable, defaults: &Defaults) {
    let head = |causality: &str, variability: &str, initial: &str| {
        format!(
            r#"    <ScalarVariable name="{}" valueReference="{vr}" description="{}" causality="{causality}" variability="{variability}"{initial}>"#,
            escape(&v.name),
            escape(&v.description)
        )
    };
    let unit = if has_unit(v.unit) {
        format!(r#" unit="{}""#, escape(v.unit))
    } else {
        String::new()
    };
    let _ = match v.role {
        Role::Parameter { index, tunable } => {
            // One start value per parameter: `model_description` checked the count.
            let start = defaults
                .start
                .get(index)
                .map(|s| format!(" start=\"{s:?}\""));
            let variability = if tunable { "tunable" } else { "fixed" };
            writeln!(
                x,
                "{}\n      <Real{unit}{}/>",
                head("parameter", variability, r#" initial="exact""#),
                start.unwrap_or_default()
            )
        }
        Role::Phase => writeln!(x, "{}\n      <Integer/>", head("output", "discrete", "")),
        _ => writeln!(
            x,
            "{}\n      <Real{unit}/>",
            head("output", "continuous", "")
        ),
    };
    let _ = writeln!(x, "    </ScalarVariable>");
}

/// Whether `unit` is one to declare (not empty, not `1`).
fn has_unit(unit: &str) -> bool {
    !unit.is_empty() && unit != "1"
}

/// `<UnitDefinitions>`: each unit the variables use, with its exponents of kg, m and s where
/// they are integers, and of the radian (`rad="1"` for an angle or an angular rate).
fn unit_definitions(x: &mut String, vars: &[Variable]) {
    let mut units: Vec<&str> = vars
        .iter()
        .map(|v| v.unit)
        .filter(|u| has_unit(u))
        .collect();
    units.sort_unstable();
    units.dedup();
    if units.is_empty() {
        return;
    }
    let _ = writeln!(x, "  <UnitDefinitions>");
    for u in units {
        let mut base = String::new();
        if let Ok(parsed) = AngularUnit::parse(u) {
            let si = parsed.si();
            let exponents = [("kg", si.kg()), ("m", si.m()), ("s", si.s())];
            for (name, e) in exponents.into_iter().chain([("rad", parsed.rad())]) {
                if !e.is_zero() && e.is_integer() {
                    let _ = write!(base, r#" {name}="{}""#, e.num());
                }
            }
        }
        let _ = writeln!(
            x,
            "    <Unit name=\"{}\"><BaseUnit{base}/></Unit>",
            escape(u)
        );
    }
    let _ = writeln!(x, "  </UnitDefinitions>");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_system_has_unique_variable_names_and_its_own_guid() {
        let mut guids = Vec::new();
        for m in crate::models::all() {
            let info = m.info();
            let vars = variables(info).expect("well-formed model");
            let mut names: Vec<&str> = vars.iter().map(|v| v.name.as_str()).collect();
            names.sort_unstable();
            let n = names.len();
            names.dedup();
            assert_eq!(names.len(), n, "{}: duplicate variable names", info.name);
            guids.push(guid(info).expect("well-formed model"));
        }
        let n = guids.len();
        guids.sort();
        guids.dedup();
        assert_eq!(guids.len(), n);
    }

    #[test]
    fn the_description_escapes_and_declares_units() {
        let info = crate::models::find("rod_cube").map(|m| m.info());
        let Some(info) = info else {
            panic!("rod_cube is registered");
        };
        let defaults = Defaults {
            start: vec![1.0, 3.0, 1.0, 0.25, 9.81],
            tolerance: 1e-12,
            stop: None,
            source: "a < b & c".into(),
        };
        let xml = model_description(info, &defaults).expect("five start values");
        assert!(xml.contains("a &lt; b &amp; c"));
        assert!(xml.contains(r#"<Unit name="m/s^2"><BaseUnit m="1" s="-2"/></Unit>"#));
        assert!(xml.contains(r#"<Real unit="m/s^2" start="9.81"/>"#));
        assert!(xml.contains(r#"name="theta_dot""#));
        assert!(xml.contains(r#"name="g" valueReference="4""#));
        let tunable = xml
            .matches(r#"causality="parameter" variability="tunable""#)
            .count();
        let fixed = xml
            .matches(r#"causality="parameter" variability="fixed""#)
            .count();
        assert_eq!((tunable, fixed), (3, 2), "m1, m2, g tunable; ell, a fixed");
    }

    #[test]
    fn lengths_angles_and_their_rates_are_fixed_the_rest_tunable() {
        let param = |unit| ParamInfo {
            name: "p",
            meaning: "a parameter",
            unit,
            positive: true,
        };
        for unit in ["m", "rad", "m/s", "rad/s", "no such unit"] {
            assert!(!tunable(&param(unit)), "{unit}");
        }
        for unit in ["kg", "m/s^2", "N/m", "1", "N m"] {
            assert!(tunable(&param(unit)), "{unit}");
        }
        for m in crate::models::all() {
            for p in m.info().parameters {
                assert_eq!(tunable(p), !matches!(p.unit, "m" | "rad" | "m/s" | "rad/s"));
            }
        }
    }
}
