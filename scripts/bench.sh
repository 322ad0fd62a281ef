#!/usr/bin/env bash
# Instruction counts per core from QEMU under -icount (firmware/src/bin/bench/). The
# firmware checks its core's budgets in bench/budgets.txt and exits with failure on a
# breach of an enforced one; this script then compares every figure with the committed
# baseline bench/baseline.txt and fails if any grew by more than 5 %.
# With it, the `table_new` firmware (firmware/src/bin/table_new.rs): what a force table
# built at a device's start-up costs, in instructions and stack, and in flash the code
# only its builder reaches (scripts/code_size.py, into target/qemu/code-size.txt).
# `scripts/bench.sh --update` rewrites the baseline instead of comparing. `mccs check`
# compiles the baseline in (its TRAINER figures in docs/): run the host tests again after
# an update before `scripts/figures.py update`, or the docs take the old baseline's.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib.sh  # core_target
mode=${1:-check}
case "$mode" in
  check | --update | --check-log) ;;
  *) echo "usage: scripts/bench.sh [--update | --check-log CORE LOG] (not '$mode')" >&2; exit 2 ;;
esac
# Whether a bench log ran to its end (the firmware's last act is its budget check) and
# lost no frame on the way (the decoder marks each it skipped).
complete() { grep -q "^BUDGET core=$1 " "$2" && ! grep -q "^defmt-log: malformed frame skipped" "$2"; }
# `scripts/bench.sh --check-log CORE LOG`: only that (the test command's check of it).
if [ "$mode" = "--check-log" ]; then
  complete "$2" "$3"
  exit
fi
mkdir -p target/qemu
out=target/qemu/bench.txt
: > "$out"
status=0
build_decoder --quiet
echo "bench: building the bench and table_new firmware for m4f, m3 and m0" >&2
cargo build --quiet --release -p mccs-firmware --bin bench --bin table_new \
  --target thumbv7em-none-eabihf --target thumbv7m-none-eabi --target thumbv6m-none-eabi
# The three cores run side by side (each QEMU is one thread; under -icount their counts
# do not depend on the host's load); each one's exit status in its .rc file.
echo "bench: running m4f, m3 and m0 in QEMU side by side (about 35 s)" >&2
# `run_bin CORE BIN LOG`: the firmware in QEMU, its log decoded, its status in LOG.rc.
run_bin() {
  local t
  t=$(core_target "$1")
  rm -f "$3.rc"
  set +e
  timeout --foreground 300 cargo run --quiet --release -p mccs-firmware --target "$t" --bin "$2" \
      < /dev/null 2> >(grep -v "Timer with period zero" >&2) \
    | "$DECODER" "$TARGET_DIR/$t/release/$2" > "$3"
  echo "${PIPESTATUS[0]}" > "$3.rc"
}
for core in m4f m3 m0; do
  (
    run_bin "$core" bench "target/qemu/bench-$core.log"
    run_bin "$core" table_new "target/qemu/table-new-$core.log"
  ) &
done
wait
: > target/qemu/code-size.txt
for core in m4f m3 m0; do
  log="target/qemu/table-new-$core.log"
  grep -E "^BENCH " "$log" >> "$out" || true
  if [ "$(cat "$log.rc" 2> /dev/null)" != 0 ] || ! grep -q "^BENCH " "$log"; then
    echo "bench: the $core table_new firmware failed (see $log)" >&2
    status=1
  fi
  python3 scripts/code_size.py "$TARGET_DIR/$(core_target "$core")/release/table_new" "$core" \
    'mccs_firmware::entry::table_new' table_new >> target/qemu/code-size.txt || status=1
done
cat target/qemu/code-size.txt
for core in m4f m3 m0; do
  log="target/qemu/bench-$core.log"
  rc=$(cat "$log.rc" 2> /dev/null || echo missing)
  grep -E "^(BENCH|MEM|FIT|BUDGET|RATIO|MEMORY) " "$log" >> "$out" || true
  if [ "$rc" != 0 ]; then
    echo "bench: the $core firmware exited with status $rc (a budget breached, or a fault: see $log)" >&2
    grep -E "result=(OVER|missing)|malformed|panic" "$log" >&2 || true
    status=1
  elif grep -q "^defmt-log: malformed frame skipped" "$log"; then
    # A frame lost on the way (the M0's stack once overran defmt's state): a figure may
    # be missing or wrong.
    echo "bench: the $core log lost frames (defmt-log: malformed frame skipped, in $log)" >&2
    status=1
  elif ! complete "$core" "$log"; then
    # Its last act is the budget check. A run that stops before it with status 0 is a
    # fault QEMU did not report: a lockup (the M0's stack overflowing into a hard fault
    # that cannot stack its frame ends QEMU with status 0).
    echo "bench: the $core firmware stopped before its budget check, with status 0 (a lockup: see $log; its last line: $(tail -n 1 "$log"))" >&2
    status=1
  fi
done
cat "$out"
if [ "$status" != 0 ]; then
  echo "bench: failed: a firmware exited with failure:" >&2
  grep -hE "result=(OVER|missing)|malformed|panic" target/qemu/bench-*.log >&2 || true
  exit 1
fi
if [ "$mode" = "--update" ]; then
  grep -E "^(BENCH|MEM) " "$out" > bench/baseline.txt
  echo "bench: baseline updated"
  exit 0
fi
python3 - "$out" bench/baseline.txt <<'PY'
import sys
def load(path):
    out = {}
    for line in open(path):
        if not line.startswith("BENCH "):
            continue
        f = dict(kv.split("=", 1) for kv in line.split()[1:])
        # The largest patch grows by its n, not by its instructions.
        key = "n" if f["case"] == "largest_patch_1khz" else "instructions"
        out[(f["core"], f["case"])] = int(f[key])
    return out
now, base = load(sys.argv[1]), load(sys.argv[2])
def worse(c, k):
    if (c, k) not in now:
        return True
    if k == "largest_patch_1khz":
        return now[(c, k)] < base[(c, k)]
    return now[(c, k)] > base[(c, k)] * 1.05
bad = [f"{c} {k}: {now.get((c, k))} against {base[(c, k)]}" + (" (n, smaller)" if k == "largest_patch_1khz" else " + 5 %")
       for (c, k) in base if worse(c, k)]
for b in bad:
    print("bench regression:", b)
budgets = [l for l in open(sys.argv[1]) if l.startswith(("BUDGET ", "RATIO ", "MEMORY "))]
met = sum("result=ok" in l for l in budgets)
print(f"bench: {len(base) - len(bad)} passed, {len(bad)} failed against bench/baseline.txt; "
      f"budgets: {met} enforced and met (bench/budgets.txt)")
sys.exit(1 if bad else 0)
PY
