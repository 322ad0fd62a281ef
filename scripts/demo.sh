#!/usr/bin/env bash
# The main job: the haptic firmware on the default controller (Cortex-M4F, QEMU
# netduinoplus2), running the 1 kHz MCCS patch against a simulated probe, with its defmt
# log decoded. Other cores: scripts/firmware.sh m3 | m0.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
exec bash scripts/firmware.sh m4f
