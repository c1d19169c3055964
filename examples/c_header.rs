//! Regenerates the C header `include/rodcube.h` from `src/ffi.rs` (cbindgen, `cbindgen.toml`):
//! `cargo run --example c_header` writes it; `-- --check` only compares and fails when it is
//! stale, as `tests/capi_header.rs` does. The file is written atomically (`io::write_atomic`).

#[path = "common/c_header.rs"]
mod c_header;

use std::process::ExitCode;

fn main() -> ExitCode {
    let check = std::env::args().skip(1).any(|a| a == "--check");
    let root = c_header::root();
    let path = root.join(c_header::HEADER);
    let header = match c_header::generate(&root) {
        Ok(header) => header,
        Err(e) => {
            eprintln!("c_header: {e}");
            return ExitCode::FAILURE;
        }
    };
    let current = std::fs::read_to_string(&path).unwrap_or_default();
    if current == header {
        println!("{} is up to date", c_header::HEADER);
        return ExitCode::SUCCESS;
    }
    if check {
        eprintln!("{} is stale: run `{}`", c_header::HEADER, c_header::COMMAND);
        return ExitCode::FAILURE;
    }
    match rodcube::io::write_atomic(&path, header.as_bytes()) {
        Ok(()) => {
            println!("wrote {}", c_header::HEADER);
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("c_header: cannot write {}: {e}", path.display());
            ExitCode::FAILURE
        }
    }
}
