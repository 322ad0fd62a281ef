#!/usr/bin/env bash
# Instruction counts per core from QEMU under -icount (src/bin/bench.rs), compared with
# the committed baseline bench/baseline.txt: fails if any figure grew by more than 5 %.
# `scripts/bench.sh --update` rewrites the baseline instead.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-check}
mkdir -p target/qemu
out=target/qemu/bench.txt
: > "$out"
for spec in "m4f thumbv7em-none-eabihf" "m3 thumbv7m-none-eabi" "m0 thumbv6m-none-eabi"; do
  set -- $spec
  cargo build --quiet --release --target "$2" --bin bench
  timeout 300 cargo run --quiet --release --target "$2" --bin bench 2> >(grep -v "Timer with period zero" >&2) \
    | defmt-print -e "target/$2/release/bench" | grep -E "^(BENCH|MEM) " >> "$out"
done
cat "$out"
if [ "$mode" = "--update" ]; then
  cp "$out" bench/baseline.txt
  echo "bench: baseline updated"
  exit 0
fi
python3 - "$out" bench/baseline.txt <<'PY'
import sys
def load(path):
    out = {}
    for line in open(path):
        f = dict(kv.split("=", 1) for kv in line.split()[1:])
        if line.startswith("BENCH "):
            out[(f["core"], f["case"])] = int(f["instructions"])
    return out
now, base = load(sys.argv[1]), load(sys.argv[2])
bad = [f"{c} {k}: {now[(c, k)]} > {base[(c, k)]} + 5 %" for (c, k) in base
       if (c, k) not in now or now[(c, k)] > base[(c, k)] * 1.05]
for b in bad:
    print("bench regression:", b)
print(f"bench: {len(base) - len(bad)} passed, {len(bad)} failed against bench/baseline.txt")
sys.exit(1 if bad else 0)
PY
