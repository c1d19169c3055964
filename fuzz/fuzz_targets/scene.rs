//! Fuzz target: any text given to the scene parser (`Scene::parse`) gives a scene or a
//! `SceneError` whose message can be printed, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    rodcube::fuzzing::scene(data);
});
