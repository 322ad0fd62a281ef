#!/usr/bin/env bash
# Runs every fuzz target (fuzz/fuzz_targets/) for SECONDS each (default 60) with
# cargo-fuzz on the nightly toolchain, and prints the executions each reached:
#   FUZZ target=<name> seconds=<s> executions=<n> crashes=<n> slow_units=<n>
# A crash leaves its input in fuzz/artifacts/<target>/; turn it into a regression test
# (host-tests) before fixing it. Not part of the test command (see docs/reliability.md).
set -euo pipefail
cd "$(dirname "$0")/.."
LOG_DIR=target/fuzz
source scripts/lib.sh  # run_stage: says what runs, ticks every 10 s, logs to target/fuzz/
seconds=${1:-60}
[[ $seconds =~ ^[1-9][0-9]*$ ]] || { say "usage: scripts/fuzz.sh [SECONDS] (a positive integer; not '$seconds')"; exit 2; }
if ! rustup toolchain list | grep -q '^nightly'; then
  echo "fuzz.sh: installing the nightly toolchain (rustup toolchain install nightly)" >&2
  rustup toolchain install nightly --profile minimal >&2
fi
if ! command -v cargo-fuzz >/dev/null 2>&1; then
  echo "fuzz.sh: cargo install cargo-fuzz (about two minutes, once)" >&2
  cargo install cargo-fuzz --locked >&2
fi
mkdir -p target/fuzz
status=0
fuzz_one() {
  cd fuzz && cargo +nightly fuzz run "$1" "corpus/$1" -- \
    -max_total_time="$seconds" -rss_limit_mb=4096 -print_final_stats=1
}
for target in $(sed -n 's/^name = "\(.*\)"$/\1/p' fuzz/Cargo.toml | grep -v mccs-fuzz); do
  echo "fuzz.sh: building and running $target for $seconds s" >&2
  log="target/fuzz/$target.log"
  mkdir -p "fuzz/corpus/$target"
  # The committed inputs start every corpus (the test command runs them too).
  cp -n fuzz/seeds/"$target"/* "fuzz/corpus/$target/" 2>/dev/null || true
  rc=0
  run_stage "$target" fuzz_one "$target" || rc=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  # libFuzzer's artifacts: crash-, leak-, oom-, timeout- (failures) and slow-unit- (an
  # input over its 10 s report threshold, under the sanitizer: not a failure, but kept).
  crashes=$(ls "fuzz/artifacts/$target" 2>/dev/null | grep -vc '^slow-unit-' || true)
  slow=$(ls "fuzz/artifacts/$target" 2>/dev/null | grep -c '^slow-unit-' || true)
  echo "FUZZ target=$target seconds=$seconds executions=${execs:-0} crashes=$crashes slow_units=$slow"
  if [ "$rc" != 0 ]; then
    echo "fuzz.sh: $target failed (exit $rc): see $log" >&2
    grep -E "panicked|ERROR|SUMMARY" "$log" | head -n 5 >&2 || true
    status=1
  fi
done
exit $status
