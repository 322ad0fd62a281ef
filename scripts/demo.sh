#!/usr/bin/env bash
# The main job: the haptic firmware on the default controller (Cortex-M4F, QEMU
# netduinoplus2), running the 1 kHz MCCS patch against a simulated probe, with its defmt
# log decoded. Other cores: scripts/firmware.sh m3 | m0.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
source scripts/lib.sh
LOG_DIR=target/logs/demo
mkdir -p "$LOG_DIR"
run_stage build-decoder build_decoder
run_stage build-firmware cargo build --release -p mccs-firmware --target thumbv7em-none-eabihf --bin haptic
say "...  running the firmware in QEMU (Cortex-M4F, 4 s of simulated ticks: a palpation)"
start=$SECONDS
# The decoded log is kept, for `mccs demo --core m4f --check` (the README's next step).
mkdir -p target/qemu
log=target/qemu/demo-m4f.log
rm -f "$log"
bash scripts/firmware.sh m4f | tee "$log"
say "ok   demo ($((SECONDS - start)) s); its log: $log (mccs demo --core m4f --check $log compares it with the host)"
