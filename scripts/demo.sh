#!/usr/bin/env bash
# The main job. Until the firmware lands: the Table 2 curve from the host CLI.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
cargo build --release --quiet
./target/release/mccs curve --params params/table2.toml --from -0.2 --to 1.3 --step 0.05
