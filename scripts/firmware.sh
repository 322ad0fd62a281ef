#!/usr/bin/env bash
# Builds the haptic firmware for one core and runs it in QEMU, printing the decoded defmt
# log. Usage: scripts/firmware.sh m4f|m3|m0 [extra cargo args, e.g. --features panic-test]
# Exit status: QEMU's (0 when the firmware exits through semihosting with success).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib.sh
core=${1:-m4f}
shift || true
target=$(core_target "$core")
build_decoder --quiet
cargo build --quiet --release -p mccs-firmware --target "$target" --bin haptic "$@"
elf="$TARGET_DIR/$target/release/haptic"
# The runner from .cargo/config.toml (QEMU with -icount, off the terminal), output
# decoded. A hung firmware fails after 5 minutes instead of stalling the caller.
timeout --foreground 300 cargo run --quiet --release -p mccs-firmware --target "$target" --bin haptic "$@" \
    < /dev/null 2> >(grep -v "Timer with period zero" >&2) \
  | "$DECODER" "$elf"
