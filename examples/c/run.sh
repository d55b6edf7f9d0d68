#!/usr/bin/env bash
# Builds the synovia C library, compiles examples/c/main.c against include/synovia.h (once with
# the shared library, once with the static one), and runs it with the contact forces that the
# Rust API computes for the same model: exits 0 only when they agree to 1e-12 relative and all
# error-code checks pass. Works from any directory; honours CARGO_TARGET_DIR (default:
# <repo>/target).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
if [ -n "${CARGO_TARGET_DIR:-}" ]; then
    # relative to the caller's directory, as cargo would read it
    target="$(mkdir -p "$CARGO_TARGET_DIR" && cd "$CARGO_TARGET_DIR" && pwd)"
else
    target="$root/target"
fi
export CARGO_TARGET_DIR="$target"
cd "$root"

echo "== building the library (cargo build --release -p synovia-capi)"
cargo build --release -p synovia-capi
cargo build --release -p synovia-capi --example reference
lib="$target/release"

echo "== reference forces (Rust API, crates/synovia-capi/examples/reference.rs)"
read -r -a reference <<<"$("$target/release/examples/reference")"
echo "${reference[*]}"

out="$target/c-example"
mkdir -p "$out"
CC="${CC:-cc}"
# -ffp-contract=off: build the mesh with exactly the floating-point operations of the Rust side
cflags=(-std=c11 -O2 -Wall -Wextra -Werror -ffp-contract=off -I"$root/include")

echo "== compiling against the shared library (libsynovia_capi.so, rpath)"
"$CC" "${cflags[@]}" "$here/main.c" -o "$out/synovia_example_shared" \
    -L"$lib" -lsynovia_capi -Wl,-rpath,"$lib" -lm -lpthread -ldl
echo "== compiling against the static library (libsynovia_capi.a)"
"$CC" "${cflags[@]}" "$here/main.c" -o "$out/synovia_example_static" \
    "$lib/libsynovia_capi.a" -lm -lpthread -ldl

echo "== compiling the soak program (examples/c/soak.c, shared library)"
"$CC" "${cflags[@]}" "$here/soak.c" -o "$out/synovia_soak" \
    -L"$lib" -lsynovia_capi -Wl,-rpath,"$lib" -lm -lpthread -ldl

echo "== running (shared)"
"$out/synovia_example_shared" "${reference[@]}"
echo "== running (static)"
"$out/synovia_example_static" "${reference[@]}" >/dev/null
echo "== soak smoke run: 3 steps of the 43k-DOF frictional model (10 000 steps: docs/reliability.md)"
"$out/synovia_soak" 3
echo "examples/c: the C API agrees with the Rust API (shared and static library)"
