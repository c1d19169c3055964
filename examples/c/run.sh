#!/usr/bin/env bash
# Builds rodcube's C library (the cdylib of Cargo.toml's [lib], without the command line: the
# feature `fmi` and the `capi` it implies, so it is also the library `rodcube fmu` packs) and the
# C programs of examples/c/ with the system C compiler (`cc`, or $CC), then runs one: `run.sh` runs paper, `run.sh per_point [N]`
# the per-point cost probe, `run.sh tapes DIR MODEL NAME=VALUE...` a model loaded from a
# directory of tapes. Honours CARGO_TARGET_DIR.
set -euo pipefail

root="$(cd "$(dirname "$0")/../.." && pwd)"
target="${CARGO_TARGET_DIR:-$root/target}"
program="${1:-paper}"
shift || true

cargo build --quiet --manifest-path "$root/Cargo.toml" --release --lib \
    --no-default-features --features fmi
mkdir -p "$target/c-example"
# Each program is linked to a file of this run's own and renamed into place, so that a run
# started beside this one (the tests run several) never executes a file still being written
# ("Text file busy").
for name in paper per_point tapes; do
    "${CC:-cc}" -std=c11 -O2 -Wall -Wextra -Werror -pedantic -I"$root/include" \
        "$root/examples/c/$name.c" -L"$target/release" -lrodcube -lm \
        -Wl,-rpath,"$target/release" -o "$target/c-example/$name.$$"
    mv -f "$target/c-example/$name.$$" "$target/c-example/$name"
done
exec "$target/c-example/$program" "$@"
