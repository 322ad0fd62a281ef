#!/usr/bin/env bash
# The long runs that the test command leaves out (docs/reliability.md):
#   1. the short-trajectory properties of Solver::step at CASES cases per arithmetic
#      (default 50,000: ten times the test command's, about 10⁷ ticks in all), and the
#      settling properties at CASES / 100;
#   2. the roaming probe over random caps and paths at CASES / 10 cases
#      (host-tests/tests/cap.rs), the stability bound against the exact one on CASES / 2
#      random configurations (host-tests/tests/stability.rs), and the force-table bound
#      over 10⁵ random springs (host-tests/tests/table_bound.rs);
#   3. every fuzz target for FUZZ_SECONDS (default 300) each (scripts/fuzz.sh).
# First, the whole host test suite in a release build (link-time optimisation, as
# docs/cli.md builds the CLI), and that build's stack probes
# (scripts/check_stack_probes.py: an LLVM defect once cost the window its position).
# Prints the STACKPROBE, PROPERTY and FUZZ lines; exits with failure if any run fails.
#   scripts/long.sh [CASES] [FUZZ_SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
cases=${1:-50000}
fuzz_seconds=${2:-300}
mkdir -p target/logs/long
echo "long.sh: the host tests in a release build (log: target/logs/long/release.log)" >&2
cargo test --release -p mccs-host > target/logs/long/release.log 2>&1 \
  || { echo "long.sh: the release host tests failed; see target/logs/long/release.log" >&2; exit 1; }
echo "long.sh: the release CLI's stack probes" >&2
rm -f target/release/deps/mccs-*.s
cargo rustc --release -p mccs-host --bin mccs -- --emit asm -C llvm-args=-x86-asm-syntax=intel \
  >> target/logs/long/release.log 2>&1
python3 scripts/check_stack_probes.py target/release/deps/mccs-*.s
log=target/logs/long/properties.log
echo "long.sh: the short-trajectory properties at $cases cases per arithmetic (log: $log)" >&2
start=$(date +%s)
PROPTEST_CASES=$cases cargo test --release -p mccs-host --test host \
    -- --show-output solver_properties::short_trajectories > "$log" 2>&1 &
pid=$!
while kill -0 "$pid" 2>/dev/null; do
  sleep 10
  kill -0 "$pid" 2>/dev/null && echo "long.sh: ... $(( $(date +%s) - start )) s" >&2
done
wait "$pid" || { echo "long.sh: the properties failed; see $log" >&2; exit 1; }
settle=$(( cases / 100 > 60 ? cases / 100 : 60 ))
echo "long.sh: the settling properties at $settle cases per arithmetic" >&2
PROPTEST_CASES=$settle cargo test --release -p mccs-host --test host \
    -- --show-output solver_properties::after_lift_off >> "$log" 2>&1 || { echo "long.sh: the settling properties failed; see $log" >&2; exit 1; }
grep -E "^PROPERTY " "$log"
caps=$(( cases / 10 ))
echo "long.sh: the roaming probe over random caps at $caps cases" >&2
PROPTEST_CASES=$caps cargo test --release -p mccs-host --test host \
    -- cap::robust > target/logs/long/cap.log 2>&1 \
  || { echo "long.sh: the cap property failed; see target/logs/long/cap.log" >&2; exit 1; }
echo "PROPERTY case=cap_paths cases=$caps result=ok"
configs=$(( cases / 2 ))
# (A new seed each run unless PROPTEST_RNG_SEED is set; the STABILITY line names it.)
seed=${PROPTEST_RNG_SEED:-$RANDOM$RANDOM}
echo "long.sh: the stability bound on $configs random configurations, seed $seed (about 5 minutes at 25,000: 289 s on 2026-11-27)" >&2
PROPTEST_RNG_SEED=$seed PROPTEST_CASES=$configs cargo test --release -p mccs-host --test host \
    -- --nocapture stability::the_chosen_bound_is_never_optimistic_on_random > target/logs/long/stability.log 2>&1 \
  || { echo "long.sh: the stability property failed; see target/logs/long/stability.log" >&2; exit 1; }
grep -E "^STABILITY " target/logs/long/stability.log
echo "long.sh: the force-table bound over 10^5 random springs (about 40 minutes: 2,324 s on 2026-11-27; its progress every 10 s)" >&2
# The log keeps everything; the progress lines also go to the terminal.
TABLE_BOUND_SPRINGS=100000 cargo test --release -p mccs-host --test host \
    -- --nocapture table_bound::every_table 2>&1 | tee target/logs/long/table_bound.log \
    | { grep --line-buffered "^table_bound:" >&2 || true; } \
  || { echo "long.sh: the table bound failed; see target/logs/long/table_bound.log" >&2; exit 1; }
grep -E "^TABLEBOUND " target/logs/long/table_bound.log
echo "long.sh: properties done in $(( $(date +%s) - start )) s; fuzzing $fuzz_seconds s per target" >&2
bash scripts/fuzz.sh "$fuzz_seconds"
