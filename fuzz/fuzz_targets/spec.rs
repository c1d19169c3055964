//! Fuzz target: any text given to the model-spec parser (`rodcube::spec::parse`) gives a checked
//! spec or a `SpecError` naming file, line and field, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    rodcube::fuzzing::spec(data);
});
