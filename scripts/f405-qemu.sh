#!/usr/bin/env bash
# Builds the STM32F405 board firmware with `--features qemu` and runs it in QEMU
# (netduinoplus2, -icount shift=3: the runner in .cargo/config.toml), printing the
# decoded defmt log. QEMU's SPI has no encoder behind it, so the run ends in the safe
# state on the tick the fault rules say; the SUMMARY line's verdict holds it to them.
# Exit status: QEMU's (0 when the firmware exits through semihosting with success).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib.sh  # build_decoder, $DECODER
echo "f405-qemu: building the board firmware (--features qemu) and the log decoder" >&2
build_decoder --quiet
cargo build --quiet --release -p haptic-f405 --target thumbv7em-none-eabihf --bin haptic-f405 --features qemu
elf=$TARGET_DIR/thumbv7em-none-eabihf/release/haptic-f405
echo "f405-qemu: running it in QEMU (netduinoplus2, a second of ticks)" >&2
timeout --foreground 300 cargo run --quiet --release -p haptic-f405 --target thumbv7em-none-eabihf \
    --bin haptic-f405 --features qemu < /dev/null 2> >(grep -v "Timer with period zero" >&2) \
  | "$DECODER" "$elf"
