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

step "clippy (thumb: the core alone, with and without defmt, and the firmware; -D warnings)"
for t in thumbv6m-none-eabi thumbv7m-none-eabi thumbv7em-none-eabihf; do
  cargo clippy -p mccs --target "$t" -- -D warnings
  cargo clippy -p mccs --target "$t" --features defmt -- -D warnings
  cargo clippy -p mccs-firmware --target "$t" -- -D warnings
done

step "thumb builds of the core alone (release, no firmware module)"
for t in thumbv6m-none-eabi thumbv7m-none-eabi thumbv7em-none-eabihf; do
  cargo build -p mccs --release --target "$t"
  cargo build -p mccs --release --target "$t" --features defmt
done

step "firmware in QEMU: the demo on all three cores, checked against the host"
cargo build --quiet --release -p mccs-host --bin mccs
mkdir -p target/qemu
for core in m4f m3 m0; do
  bash scripts/firmware.sh "$core" > "target/qemu/demo-$core.log"
  tail -n 2 "target/qemu/demo-$core.log"
  ./target/release/mccs demo --core "$core" --check "target/qemu/demo-$core.log"
done

step "static check of the per-tick path: no panic, division or floating point"
for t in thumbv7em-none-eabihf thumbv7m-none-eabi thumbv6m-none-eabi; do
  python3 scripts/check_tick_path.py "target/$t/release/haptic" | tail -n 1
done

step "firmware in QEMU: a panic exits with failure (and the check above sees it)"
if bash scripts/firmware.sh m4f --features panic-test > target/qemu/panic.log; then
  echo "test.sh: the panic-test firmware exited with success" >&2
  exit 1
fi
grep -q "panic: " target/qemu/panic.log
if python3 scripts/check_tick_path.py target/thumbv7em-none-eabihf/release/haptic > /dev/null; then
  echo "test.sh: the tick-path check missed the injected panic" >&2
  exit 1
fi

step "instruction counts in QEMU: budgets (bench/budgets.txt) and bench/baseline.txt (+5 % at most)"
bash scripts/bench.sh

step "bench in QEMU: a breached budget exits with failure"
if timeout 300 cargo run --quiet --release -p mccs-firmware --target thumbv7em-none-eabihf --bin bench --features budget-test \
    2>/dev/null | defmt-print -e target/thumbv7em-none-eabihf/release/bench > target/qemu/budget-test.log; then
  echo "test.sh: the bench firmware passed an impossible budget" >&2
  exit 1
fi
grep "result=OVER" target/qemu/budget-test.log

step "memory of the demo firmware (defmt, release): flash ≤ 64 KiB"
size_tool="$(rustc --print sysroot)/lib/rustlib/$(rustc -vV | sed -n 's/^host: //p')/bin/llvm-size"
for t in thumbv7em-none-eabihf thumbv7m-none-eabi thumbv6m-none-eabi; do
  cargo build --quiet --release -p mccs-firmware --target "$t" --bin haptic
  "$size_tool" -A "target/$t/release/haptic" | python3 -c '
import sys
target = sys.argv[1]
sec = {}
for line in sys.stdin:
    p = line.split()
    if len(p) >= 3 and p[0].startswith(".") and p[1].isdigit():
        sec[p[0]] = int(p[1])
flash = sum(sec.get(s, 0) for s in (".vector_table", ".text", ".rodata", ".data", ".gnu.sgstubs"))
ram = sum(sec.get(s, 0) for s in (".data", ".bss", ".uninit"))
print(f"SIZE target={target} flash={flash} ram={ram} (static; the stack comes on top)")
if flash > 64 * 1024:
    sys.exit(f"test.sh: {target} demo firmware flash {flash} B > 64 KiB")
' "$t"
done

step "host tests"
log=$(mktemp)
cargo test --workspace 2>&1 | tee "$log"
passed=$(grep -Eo 'test result: ok\. [0-9]+ passed' "$log" | awk '{s += $4} END {print s + 0}')
failed=$(grep -Eo '[0-9]+ failed' "$log" | awk '{s += $1} END {print s + 0}')
rm -f "$log"
echo "host tests: $passed passed, $failed failed"
