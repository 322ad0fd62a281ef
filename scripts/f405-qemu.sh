#!/usr/bin/env bash
# Builds the STM32F405 board firmware with `--features qemu` and runs it in QEMU
# (netduinoplus2, -icount shift=3: the runner in .cargo/config.toml), printing the
# decoded defmt log. QEMU's SPI has no encoder behind it, so the run ends in the safe
# state on the tick the fault rules say; the SUMMARY line's verdict holds it to them.
# Exit status: QEMU's (0 when the firmware exits through semihosting with success).
# `--arm`: the arm variant (--features arm,qemu): its counters read and its home input
# stays low in QEMU, so it is never homed: no fault, zero duty on every joint throughout.
# `--arm-sim`: the arm variant on its simulated arm (--features arm,sim,qemu): homed, its
# direction checked, then one palpation of the tissue (5.5 s of ticks), ending with the
# trainer's tick at its worst (`BENCH core=m4f case=trainer_tick …`) and the SUMMARY.
#   scripts/f405-qemu.sh [--arm | --arm-sim]
set -euo pipefail
cd "$(dirname "$0")/.."
features=qemu
case "${1:-}" in
  "") ;;
  --arm) features=arm,qemu ;;
  --arm-sim) features=arm,sim,qemu ;;
  *) echo "usage: scripts/f405-qemu.sh [--arm | --arm-sim] (not '$1')" >&2; exit 2 ;;
esac
source scripts/lib.sh  # build_decoder, $DECODER, board_build, board_elf, qemu_runner
echo "f405-qemu: building the board firmware (--features $features) and the log decoder" >&2
build_decoder --quiet
board_build "$features" --quiet
elf=$(board_elf "$features")
runner=$(qemu_runner thumbv7em-none-eabihf)
echo "f405-qemu: running it in QEMU (netduinoplus2, a second of ticks; the simulated arm 5.5 s)" >&2
# shellcheck disable=SC2086  # the runner is a command line, split into its words
timeout --foreground 300 $runner "$elf" < /dev/null 2> >(grep -v "Timer with period zero" >&2) \
  | "$DECODER" "$elf"
