//! Fuzz target: a compiled model's tape, edited as the input says (or a tape's text), given to
//! the tape loader (`rodcube::tape::parse`) gives a `TapeError` naming the file or a model whose
//! every `Model` and `Reduction` method runs, with slices of the lengths its info gives,
//! without a panic (`rodcube::fuzzing::tape`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    rodcube::fuzzing::tape(data);
});
