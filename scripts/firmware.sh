#!/usr/bin/env bash
# Builds the haptic firmware for one core and runs it in QEMU, printing the decoded defmt
# log. Usage: scripts/firmware.sh m4f|m3|m0 [extra cargo args, e.g. --features panic-test]
# Exit status: QEMU's (0 when the firmware exits through semihosting with success).
set -euo pipefail
cd "$(dirname "$0")/.."
core=${1:-m4f}
shift || true
case "$core" in
  m4f) target=thumbv7em-none-eabihf ;;
  m3) target=thumbv7m-none-eabi ;;
  m0) target=thumbv6m-none-eabi ;;
  *) echo "firmware.sh: core must be m4f, m3 or m0, not '$core'" >&2; exit 2 ;;
esac
cargo build --quiet --release -p mccs-firmware --target "$target" --bin haptic "$@"
elf="target/$target/release/haptic"
# The runner from .cargo/config.toml (QEMU with -icount), output decoded by defmt-print.
# timeout: a hung firmware must fail, not stall the caller.
timeout 300 cargo run --quiet --release -p mccs-firmware --target "$target" --bin haptic "$@" 2> >(grep -v "Timer with period zero" >&2) \
  | defmt-print -e "$elf"
