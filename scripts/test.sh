#!/usr/bin/env bash
# The test command: host tests, formatting, clippy, and the thumb builds of the core.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

step() { printf '\n== %s\n' "$*" >&2; }

step "cargo fmt --check"
cargo fmt --all -- --check

step "clippy (host, all targets, -D warnings)"
cargo clippy --workspace --all-targets -- -D warnings

step "clippy (thumb, with and without defmt, -D warnings)"
for t in thumbv6m-none-eabi thumbv7m-none-eabi thumbv7em-none-eabihf; do
  cargo clippy -p mccs --target "$t" -- -D warnings
  cargo clippy -p mccs --target "$t" --features defmt -- -D warnings
done

step "thumb builds of the core (release)"
for t in thumbv6m-none-eabi thumbv7m-none-eabi thumbv7em-none-eabihf; do
  cargo build -p mccs --release --target "$t"
  cargo build -p mccs --release --target "$t" --features defmt
done

step "host tests"
log=$(mktemp)
cargo test --workspace 2>&1 | tee "$log"
passed=$(grep -Eo 'test result: ok\. [0-9]+ passed' "$log" | awk '{s += $4} END {print s + 0}')
failed=$(grep -Eo '[0-9]+ failed' "$log" | awk '{s += $1} END {print s + 0}')
rm -f "$log"
echo "host tests: $passed passed, $failed failed"
