//! Fuzz target: any text given to the spec expression parser (`Expr::parse`) gives an
//! expression (which prints, tidies, evaluates and re-parses from its infix form) or a
//! `ParseError`, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    rodcube::fuzzing::expr(data);
});
