#!/usr/bin/env bash
# The long runs that the test command leaves out (docs/reliability.md):
#   1. the short-trajectory properties of Solver::step at CASES cases per arithmetic
#      (default 50,000: ten times the test command's, about 10⁷ ticks in all), and the
#      settling properties at CASES / 100;
#   2. the roaming probe over random caps and paths at CASES / 10 cases
#      (host-tests/tests/cap.rs), any run of the link at CASES / 25
#      (host-tests/tests/link/any_run.rs), the stability bound against the exact one on CASES / 2
#      random configurations (host-tests/tests/stability.rs), and the force-table bound
#      over 10⁵ random springs (host-tests/tests/table_bound/), and the arm's stable
#      region against its device file's (`mccs arm stability`);
#   3. every fuzz target for FUZZ_SECONDS (default 300) each (scripts/fuzz.sh).
# First, the whole host test suite in a release build (link-time optimisation, as
# docs/cli.md builds the CLI), and that build's stack probes
# (scripts/check_stack_probes.py: an LLVM defect once cost the window its position).
# Each step says what it runs and ticks every 10 s (scripts/lib.sh, `run_stage`), its log
# in target/logs/long/. Prints the STACKPROBE, PROPERTY, STABILITY, TABLEBOUND, STABLE and FUZZ
# lines; exits with failure at the first run that fails.
#   scripts/long.sh [CASES] [FUZZ_SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
LOG_DIR=target/logs/long
source scripts/lib.sh
cases=${1:-50000}
fuzz_seconds=${2:-300}
for n in "$cases" "$fuzz_seconds"; do
  [[ $n =~ ^[1-9][0-9]*$ ]] || { say "usage: scripts/long.sh [CASES] [FUZZ_SECONDS] (positive integers; not '$n')"; exit 2; }
done
start=$SECONDS
# (fd 3: the terminal's stderr, for the table bound's own progress lines inside a stage.)
exec 3>&2

stack_probes() {
  rm -f "$TARGET_DIR"/release/deps/mccs-*.s
  cargo rustc --release -p mccs-host --bin mccs -- --emit asm -C llvm-args=-x86-asm-syntax=intel
  python3 scripts/check_stack_probes.py "$TARGET_DIR"/release/deps/mccs-*.s
}
say "long.sh: the host tests in a release build (several minutes from scratch), then its stack probes"
run_stage release-host-tests cargo test --release -p mccs-host
run_stage stack-probes stack_probes
grep -E "^STACKPROBE " "$LOG_DIR/stack-probes.log"

say "long.sh: the short-trajectory properties at $cases cases per arithmetic"
PROPTEST_CASES=$cases run_stage properties cargo test --release -p mccs-host --test host \
  -- --show-output solver_properties::short_trajectories
settle=$((cases / 100 > 60 ? cases / 100 : 60))
say "long.sh: the settling properties at $settle cases per arithmetic"
PROPTEST_CASES=$settle run_stage settling cargo test --release -p mccs-host --test host \
  -- --show-output solver_properties::after_lift_off
grep -hE "^PROPERTY " "$LOG_DIR/properties.log" "$LOG_DIR/settling.log"

caps=$((cases / 10))
say "long.sh: the roaming probe over random caps at $caps cases"
PROPTEST_CASES=$caps run_stage cap-paths cargo test --release -p mccs-host --test host -- cap::robust
echo "PROPERTY case=cap_paths cases=$caps result=ok"

links=$((cases / 25))
say "long.sh: any run of the link, end to end, at $links cases (about 80 s at 1,500)"
PROPTEST_CASES=$links run_stage link-runs cargo test --release -p mccs-host --test host \
  -- link::any_run
echo "PROPERTY case=link_runs cases=$links result=ok"

configs=$((cases / 2))
# (A new seed each run unless PROPTEST_RNG_SEED is set; the STABILITY line names it.)
seed=${PROPTEST_RNG_SEED:-$RANDOM$RANDOM}
say "long.sh: the stability bound on $configs random configurations, seed $seed (about 5 minutes at 25,000)"
PROPTEST_RNG_SEED=$seed PROPTEST_CASES=$configs run_stage stability \
  cargo test --release -p mccs-host --test host \
  -- --nocapture stability::the_chosen_bound_is_never_optimistic_on_random
grep -E "^STABILITY " "$LOG_DIR/stability.log"

# The log keeps everything; the test's own progress lines also go to the terminal.
table_bound() {
  TABLE_BOUND_SPRINGS=100000 cargo test --release -p mccs-host --test host \
    -- --nocapture table_bound::every_table 2>&1 \
    | tee >(grep --line-buffered "^table_bound:" >&3 || true)
}
say "long.sh: the force-table bound over 10^5 random springs (about 22 minutes on two cores; docs/reliability.md)"
run_stage table-bound table_bound
grep -E "^TABLEBOUND " "$LOG_DIR/table-bound.log"

# The arm's stable region re-measured (`mccs arm stability`, in the release build) and
# the device file it writes held to the shipped one, byte for byte: the test command
# holds only the region's edge at the board's damping.
arm_region() {
  cargo run --release -q -p mccs-host --bin mccs -- arm stability \
    --device devices/woodenhaptics.toml --out "$LOG_DIR/woodenhaptics.toml" || return 1
  cmp devices/woodenhaptics.toml "$LOG_DIR/woodenhaptics.toml" \
    || { diff devices/woodenhaptics.toml "$LOG_DIR/woodenhaptics.toml"; return 1; }
}
say "long.sh: the arm's stable region re-measured against devices/woodenhaptics.toml (10 to 20 minutes)"
run_stage arm-region arm_region
grep -E "^STABLE " "$LOG_DIR/arm-region.log"

say "long.sh: properties done in $((SECONDS - start)) s; fuzzing $fuzz_seconds s per target"
bash scripts/fuzz.sh "$fuzz_seconds"
