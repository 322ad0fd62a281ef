#!/usr/bin/env bash
# The test command: formatting, clippy, the thumb builds, the firmware on all three cores
# in QEMU (the main job under a pseudo-terminal), the tick-path check, the bench and its
# budgets, the firmware's size, the host tests, and the docs' figures against the code.
# The host tests run in the background from the end of the host build on, beside the
# firmware stages; their stage waits for them near the end.
#
# Every stage says what it does, ticks every 10 s while it runs and logs to
# target/logs/test/<stage>.log (the path is printed when it fails). It ends with a
# table of the stages and one line, `N passed, N failed` (each stage is one check, each
# host test one more); the exit status is 0 when nothing failed.
set -uo pipefail
cd "$(dirname "$0")/.."
all_start=$SECONDS
source scripts/setup.sh || exit 1
set +e  # setup.sh sets -e; here every stage runs, and the table counts the failures
source scripts/lib.sh
LOG_DIR=target/logs/test
rm -rf "$LOG_DIR"
mkdir -p "$LOG_DIR" target/qemu

THUMB=(thumbv6m-none-eabi thumbv7m-none-eabi thumbv7em-none-eabihf)

# Linted in one cargo run for two thumb targets at once (their crates check side by
# side): the firmware, which lints the core with defmt on each (clippy lints every
# workspace crate it compiles), on the two whose code differs from the others', the M4F
# (its assembly, `mccs_dsp`, `eabihf`) and the M0 (its 16-bit products, no 32-bit
# atomics). The M3 has no code of its own: each of its `cfg`s holds on one of those two
# as well (no DSP as on the M0, atomics as on the M4F), and the firmware-builds stage
# compiles it. Then the core alone without defmt (it builds without any firmware module:
# what defmt changes, its derives and `src/defmt.rs`, is the same on every target, so
# one target, the plainest, ARMv6-M); then the board crate. In the release profile, as
# the firmware is built: the host's proc macros and build scripts these need are then
# built once, here, for both (in the dev profile the firmware builds built them again,
# about 14 s of CPU; no code here depends on `debug_assertions`).
THUMB_ARGS=()
for t in "${THUMB[@]}"; do THUMB_ARGS+=(--target "$t"); done
clippy_thumb() {
  cargo clippy --release -p mccs -p mccs-link --target thumbv6m-none-eabi -- -D warnings || return 1
  cargo clippy --release -p mccs-firmware --target thumbv6m-none-eabi --target thumbv7em-none-eabihf \
    --lib --bins -- -D warnings || return 1
  cargo clippy --release -p mccs-firmware --target thumbv7em-none-eabihf --bins --features arm -- -D warnings || return 1
  cargo clippy --release -p haptic-f405 --target thumbv7em-none-eabihf --lib --bins -- -D warnings || return 1
  cargo clippy --release -p haptic-f405 --target thumbv7em-none-eabihf --lib --bins --features qemu -- -D warnings || return 1
  cargo clippy --release -p haptic-f405 --target thumbv7em-none-eabihf --lib --bins --features qemu-link -- -D warnings || return 1
  cargo clippy --release -p haptic-f405 --target thumbv7em-none-eabihf --lib --bins --features arm,qemu -- -D warnings || return 1
  cargo clippy --release -p haptic-f405 --target thumbv7em-none-eabihf --lib --bins --features arm -- -D warnings || return 1
  # The simulated plants (scripts/qemu-link.sh --sim [--one-dof]), as the link tests build them.
  cargo clippy --release -p haptic-f405 --target thumbv7em-none-eabihf --lib --bins --features arm,sim,qemu-link -- -D warnings || return 1
  cargo clippy --release -p haptic-f405 --target thumbv7em-none-eabihf --lib --bins --features sim,qemu-link -- -D warnings || return 1
  cargo clippy --release -p haptic-f405 --target thumbv7em-none-eabihf --bins --features fault-test -- -D warnings
}

# Without warnings, which fails the stage: rustc's on the M3 are checked here, as the
# lints above leave its target out. First the log decoder, which the stages after need
# to read the firmware's output (a bin without tests, which the host build leaves out).
firmware_builds() {
  local out=$LOG_DIR/firmware-builds-cargo.log status=0
  build_decoder || return 1
  cargo build --release -p mccs-firmware "${THUMB_ARGS[@]}" --bins > "$out" 2>&1 || status=1
  cat "$out"
  [ "$status" = 0 ] || return 1
  if grep -q '^warning' "$out"; then
    echo "the firmware builds have warnings (above)"
    return 1
  fi
}

# A demo log's longest tick as a figure line: `TICK demo=<name> instructions=<i>`.
longest_tick() {
  sed -n "s/^INFO  longest tick: .* = \([0-9.]*\) instructions under .*/TICK demo=$1 instructions=\1/p" "$2"
}

# The main job as a person runs it (the README's two steps): scripts/demo.sh in a
# terminal (script(1) gives it a pseudo-terminal), whose firmware output must end with
# its SUMMARY line, then `mccs demo --check` on the log the demo leaves.
demo_in_a_terminal() {
  local out=target/qemu/demo-m4f.log  # (demo.sh removes it before it runs the firmware)
  script -qec "bash scripts/demo.sh" /dev/null > "$out.raw" 2>&1 < /dev/null || return 1
  tr -d '\r' < "$out.raw" | grep -vE '^(\.\.\.  |ok   |setup: )' > "$out.seen"
  tail -n 1 "$out.seen" | grep -q '^SUMMARY ' || { echo "the demo did not end with its SUMMARY line"; return 1; }
  cmp -s "$out.seen" "$out" || { echo "the demo's log $out is not what the terminal showed"; return 1; }
  target/debug/mccs demo --core m4f --check "$out" || return 1
  longest_tick m4f "$out" > target/qemu/demo-tick-m4f.txt
}

demo_core() {
  local core=$1 out="target/qemu/demo-$1.log"
  bash scripts/firmware.sh "$core" > "$out" || return 1
  tail -n 2 "$out"
  target/debug/mccs demo --core "$core" --check "$out"
}


# The demo on the arm (--features arm, the M4F): the palpation through the WoodenHaptics
# arm's joint counts, its SUMMARY with the duties equal to the host's run, its tick path
# checked (the arm's chain in it); then the demo firmware rebuilt without the feature,
# for the stages after.
demo_arm() {
  local out=target/qemu/demo-m4f-arm.log elf=$TARGET_DIR/thumbv7em-none-eabihf/release/haptic
  bash scripts/firmware.sh m4f --features arm > "$out" || { tail -n 5 "$out"; return 1; }
  tail -n 2 "$out"
  target/debug/mccs demo --core m4f --arm --check "$out" || return 1
  longest_tick m4f-arm "$out" > target/qemu/demo-tick-m4f-arm.txt
  # The largest patch at 1 kHz within half a tick on the arm: 84,000 instructions at 168 MHz.
  [ -s target/qemu/demo-tick-m4f-arm.txt ] \
    && awk '{split($3, a, "="); if (a[2] + 0 > 84000 || a[2] == "") exit 1}' target/qemu/demo-tick-m4f-arm.txt \
    || { echo "the arm demo's longest tick is over half a tick (84000 instructions)"; return 1; }
  python3 scripts/check_tick_path.py "$elf" | tail -n 1 || return 1
  python3 scripts/size.py "$elf" thumbv7em-none-eabihf haptic-arm 98304 16384 | tee target/qemu/sizes-arm.txt
  [ "${PIPESTATUS[0]}" = 0 ] || return 1
  cargo build --release -p mccs-firmware --target thumbv7em-none-eabihf --bin haptic
}

tick_path() {
  for t in "${THUMB[@]}"; do
    python3 scripts/check_tick_path.py "$TARGET_DIR/$t/release/haptic" | tail -n 1 || return 1
  done
}

# A panic in the tick exits QEMU with failure, and the tick-path check sees it.
panic_test() {
  if bash scripts/firmware.sh m4f --features panic-test > target/qemu/panic.log; then
    echo "the panic-test firmware exited with success"
    return 1
  fi
  grep "panic: " target/qemu/panic.log || return 1
  if python3 scripts/check_tick_path.py "$TARGET_DIR"/thumbv7em-none-eabihf/release/haptic > /dev/null; then
    echo "the tick-path check missed the injected panic"
    return 1
  fi
  # Rebuild without the feature, for the stages after.
  cargo build --release -p mccs-firmware --target thumbv7em-none-eabihf --bin haptic
}

# A breached budget exits the bench with failure: the M4F's bench as the bench stage
# built it, run with `budget-test` on its semihosting command line (QEMU's
# `-semihosting-config …,arg=`, added to the target's runner), which measures one case
# (one spring's force and stiffness) and holds it to a budget no code can meet, and to
# nothing else (the whole bench with that budget added took 13 s; this, under 1 s).
budget_test() {
  local t=thumbv7em-none-eabihf runner
  local elf=$TARGET_DIR/$t/release/bench
  runner=$(qemu_runner "$t") || return 1
  case $runner in
    *"-semihosting-config enable=on,target=native "*) ;;
    *) echo "no QEMU runner with semihosting for $t in .cargo/config.toml"; return 1 ;;
  esac
  runner=${runner/target=native /target=native,arg=bench,arg=budget-test }
  # shellcheck disable=SC2086  # the runner is a command line, split into its words
  timeout --foreground 300 $runner "$elf" < /dev/null 2> /dev/null \
    | "$DECODER" "$elf" > target/qemu/budget-test.log
  local status=("${PIPESTATUS[@]}")
  if [ "${status[0]}" = 0 ]; then
    echo "the bench firmware passed an impossible budget"
    return 1
  fi
  [ "${status[1]}" = 0 ] || { echo "the log decoder failed"; return 1; }
  grep "result=OVER" target/qemu/budget-test.log
}

# A bench run that stops before its budget check fails the bench, whatever QEMU's exit
# status (the M0's stack once overflowed into a lockup that QEMU ended with status 0, and
# a truncated run had passed): the M0's log of the bench stage passes the check, and the
# same log cut before its budget lines does not.
bench_truncated() {
  local log=target/qemu/bench-m0.log cut=target/qemu/bench-m0-truncated.log
  bash scripts/bench.sh --check-log m0 "$log" || { echo "the complete log fails"; return 1; }
  grep -v "^BUDGET " "$log" > "$cut"
  if bash scripts/bench.sh --check-log m0 "$cut"; then
    echo "a bench log without its budget check passed"
    return 1
  fi
  # A frame the decoder skipped (it marks the place) fails the log too.
  { head -n 5 "$log"; echo "defmt-log: malformed frame skipped"; tail -n +6 "$log"; } > "$cut"
  if bash scripts/bench.sh --check-log m0 "$cut"; then
    echo "a bench log that lost a frame passed"
    return 1
  fi
  echo "a complete bench log passes; one cut before its budget check, or that lost a frame, fails"
}

# Flash and static RAM of the demo firmware (defmt included), per core.
# Flash budget: 96 KiB on every core (the roaming demo's tick, the window's start-up and
# the main loop's table builder; a 128 KiB part holds it: the microbit's nRF51822 has
# 256 KiB, the LM3S6965 256 KiB, an STM32F405 1 MiB). RAM: 16 KiB static everywhere (the
# microbit has 16 KiB in all).
sizes() {
  for t in "${THUMB[@]}"; do
    python3 scripts/size.py "$TARGET_DIR/$t/release/haptic" "$t" haptic 98304 16384 || return 1
  done | tee target/qemu/sizes.txt
}

# The STM32F405 board firmware (boards/f405): the real build, its size held to the budget
# (128 KiB flash; 64 KiB static RAM, half of the STM32F405's 128 KiB of SRAM, the rest
# the stack's: the N = 10 patch's controller and the link's work take 40 KB of it) and
# its tick path (TIM2) checked; then the QEMU build,
# its tick path checked too, run in QEMU, where its SUMMARY verdict must be ok (the fault
# rules, for an encoder that reads zeros).
board_f405() {
  local t=thumbv7em-none-eabihf elf
  local init='haptic_f405::firmware::init'
  board_build "" || return 1
  elf=$(board_elf "")
  python3 scripts/size.py "$elf" "$t" haptic-f405 131072 65536 | tee target/qemu/sizes-f405.txt
  [ "${PIPESTATUS[0]}" = 0 ] || return 1
  python3 scripts/check_tick_path.py "$elf" TIM2 "$init" | tail -n 1 || return 1
  bash scripts/f405-qemu.sh > target/qemu/f405.log || { tail -n 5 target/qemu/f405.log; return 1; }
  tail -n 1 target/qemu/f405.log
  tail -n 1 target/qemu/f405.log | grep -q '^SUMMARY board=f405 .* verdict=ok$' || return 1
  python3 scripts/check_tick_path.py "$(board_elf qemu)" TIM2 "$init" | tail -n 1
}

# The arm variant of the board (--features arm): its size, its tick path (the arm's
# kinematics in it), and its QEMU run (never homed there: no fault, zero duty). Its
# flash budget is 144 KiB: with the motors' direction check and the black box (3.5 and
# 5 KiB) it outgrew a 128 KiB part; the STM32F405 has 1 MiB (docs/arm.md). Static RAM:
# 64 KiB, as the 1-DOF's.
board_f405_arm() {
  local t=thumbv7em-none-eabihf elf
  board_build arm || return 1
  elf=$(board_elf arm)
  python3 scripts/size.py "$elf" "$t" haptic-f405-arm 147456 65536 | tee target/qemu/sizes-f405-arm.txt
  [ "${PIPESTATUS[0]}" = 0 ] || return 1
  python3 scripts/check_tick_path.py "$elf" TIM2 haptic_f405::firmware::init | tail -n 1 || return 1
  bash scripts/f405-qemu.sh --arm > target/qemu/f405-arm.log || { tail -n 5 target/qemu/f405-arm.log; return 1; }
  grep '^INFO  arm homed' target/qemu/f405-arm.log | tail -n 1
  tail -n 1 target/qemu/f405-arm.log
  tail -n 1 target/qemu/f405-arm.log | grep -q '^SUMMARY board=f405-arm .* verdict=ok$'
}

# The arm board on its simulated arm, no link (scripts/f405-qemu.sh --arm-sim): homed, its
# direction checked, one palpation of the tissue; its SUMMARY held to the fault rules,
# the tissue touched (a force logged), and its worst tick — the trainer's whole tick,
# `BENCH core=m4f case=trainer_tick` — held to the board's budget in bench/budgets.txt
# (`BOARD_BUDGET`: the bench firmware does not run the board's tick).
board_f405_arm_sim() {
  local log=target/qemu/f405-arm-sim.log worst max model
  bash scripts/f405-qemu.sh --arm-sim > "$log" || { tail -n 5 "$log"; return 1; }
  grep '^BENCH core=m4f case=trainer_tick ' "$log" && tail -n 1 "$log"
  tail -n 1 "$log" | grep -q '^SUMMARY board=f405-arm-sim .* verdict=ok$' || return 1
  grep -q 'force_n=[0-9.]*[1-9]' "$log" || { echo "the simulated arm never touched the tissue ($log)"; return 1; }
  worst=$(sed -n 's/^BENCH core=m4f case=trainer_tick .* worst_instructions=\([0-9]*\).*/\1/p' "$log")
  max=$(sed -n 's/^BOARD_BUDGET core=m4f case=trainer_tick max=\([0-9]*\) status=enforced$/\1/p' bench/budgets.txt)
  [ -n "$worst" ] && [ -n "$max" ] || { echo "no trainer_tick figure or budget"; return 1; }
  echo "BOARD_BUDGET core=m4f case=trainer_tick value=$worst limit=$max result=$([ "$worst" -le "$max" ] && echo ok || echo OVER)"
  [ "$worst" -le "$max" ] || return 1
  # The board's budget model (its BoardConfig's tick_base_cost and substep_cost, which a
  # tissue's check is held to) must cover the tick it runs.
  model=$(sed -n 's/^BENCH core=m4f case=trainer_tick .* model_instructions=\([0-9]*\).*/\1/p' "$log")
  [ -n "$model" ] && [ "$worst" -le "$model" ] || {
    echo "the worst tick, $worst, is over the board's budget model, ${model:-none}: remeasure its costs (docs/arm.md)"
    return 1
  }
}

# Every way out of the board firmware cuts the motor first (boards/f405/src/safe_stop.rs):
# each fault class injected after 100 ticks (--features fault-test, the class on the
# semihosting command line) must reach its handler, which logs `stop: <class>, the motor
# cut`, stops the black box and resets (the watchdog's reset, which QEMU does not model);
# the next boot must read the black box back — what stopped the run, what ended it and
# when — and exit QEMU with failure. (QEMU models no TIM1 or GPIO: the register writes are held
# by the host test of the stop's sequence on a mock register block.)
board_faults() {
  local elf class
  board_build fault-test || return 1
  elf=$(board_elf fault-test)
  for class in panic:panic hard:HardFault mem:MemManage bus:BusFault usage:UsageFault; do
    timeout --foreground 60 qemu-system-arm -machine netduinoplus2 -display none -serial null \
      -monitor none -semihosting-config "enable=on,target=native,arg=haptic,arg=${class%%:*}" \
      -icount shift=3,sleep=off -kernel "$elf" < /dev/null 2> /dev/null \
      | "$DECODER" "$elf" > "target/qemu/fault-${class%%:*}.log" 2>&1
    local status=("${PIPESTATUS[@]}")
    if [ "${status[0]}" = 0 ]; then echo "the ${class%%:*} fault exited QEMU with success"; return 1; fi
    grep "^ERROR stop: ${class#*:}" "target/qemu/fault-${class%%:*}.log" \
      || { echo "no 'stop: ${class#*:}' in target/qemu/fault-${class%%:*}.log"; return 1; }
    local kept=${class#*:}
    kept=$(echo "$kept" | sed -E 's/MemManage/mem-manage/; s/HardFault/hard-fault/; s/BusFault/bus-fault/; s/UsageFault/usage-fault/')
    # (QEMU's 1-DOF board reads zeros from its encoder: the read fault at tick 9 stops
    # the box first, and the injected fault ends the run after tick 99.)
    grep -E "^INFO  black box: the last run stopped by read \(the encoder's frames\) at tick 9, ended by $kept at tick (99|10[0-9]) pc=0x[0-9a-f]+; reset flags 0x0; 10 ticks kept" \
      "target/qemu/fault-${class%%:*}.log" \
      || { echo "no black box of the $kept read back in target/qemu/fault-${class%%:*}.log"; return 1; }
  done
}

# The property tests on a fixed seed, so that a run is reproducible (`cargo test` alone
# draws a new one each time, and so does scripts/long.sh: they explore).
host_tests() {
  PROPTEST_RNG_SEED=${PROPTEST_RNG_SEED:-2026} cargo test --workspace --no-fail-fast -- --show-output \
    --skip link::qemu::
}

# The host link against the board firmware in QEMU (scripts/qemu-link.sh, which builds it
# with the link's QEMU feature): one test, its figures in target/qemu/link.log.
link_qemu() {
  # (--workspace: the host build's features, so that the test binary is not rebuilt.)
  MCCS_LINK_QEMU=1 cargo test --workspace --test host -- link::qemu:: --show-output \
    > target/qemu/link.log 2>&1
  local status=$?
  grep -E '^LINK |test result' target/qemu/link.log
  if [ "$status" != 0 ]; then
    # What failed, and what the firmware logged last.
    grep -E -A4 'panicked at' target/qemu/link.log
    echo "the firmware's log, last lines (target/qemu/link-firmware.log):"
    tail -n 8 target/qemu/link-firmware.log
  fi
  return $status
}

# The simulated arm board in QEMU with its link on the unix socket $1, its log in $2;
# returns once the socket is there, QEMU's pid in SIM_BOARD_PID.
sim_board() {
  local sock=$1 log=$2 waited=0
  rm -f "$sock"
  bash scripts/qemu-link.sh --sim "$sock" > "$log" 2>&1 < /dev/null &
  SIM_BOARD_PID=$!
  until [ -S "$sock" ]; do
    sleep 0.5; waited=$((waited + 1))
    if [ "$waited" -gt 600 ] || ! kill -0 "$SIM_BOARD_PID" 2> /dev/null; then
      echo "QEMU did not open $sock ($log)"; tail -n 5 "$log"
      kill "$SIM_BOARD_PID" 2> /dev/null; return 1
    fi
  done
}

# The scene's first lines, as a scene's author builds and runs them (examples/c/scene.c,
# examples/python/scene.py), against the simulated arm board in QEMU
# (scripts/qemu-link.sh --sim): the C ABI, the example compiled with gcc as its header
# comment says, the Python package pip-installed into a fresh venv; each opens, loads,
# arms, holds 2 s, moves the pose, reads a mesh and disarms. (The library the host build
# wrote, `deps/libmccs_client.so`: the same code as the release build the examples name,
# where the release build from scratch took 129 s. Not `cargo build -p mccs-client`:
# without the tests' dev-dependencies its dependencies resolve other features (serde's,
# postcard's), and it built them and the core again, 55 s of CPU from a fresh clone.)
scene_examples() {
  local sock=target/qemu/scene.sock venv=target/venv-scene qemu_pid status=0 lib=$TARGET_DIR/debug/deps
  [ -e "$lib/libmccs_client.so" ] || { echo "no $lib/libmccs_client.so: the host build did not write it"; return 1; }
  gcc examples/c/scene.c -I client/include -L "$lib" -lmccs_client \
    -o target/qemu/scene-c || return 1
  if [ ! -x "$venv/bin/python" ]; then python3 -m venv "$venv" || return 1; fi
  # (From a copy: setuptools builds in the source tree, its build/ and egg-info.)
  rm -rf target/python-src && cp -r client/python target/python-src || return 1
  "$venv/bin/pip" install --quiet target/python-src > /dev/null || return 1
  sim_board "$sock" target/qemu/scene-firmware.log || return 1
  qemu_pid=$SIM_BOARD_PID
  echo "C: target/qemu/scene-c unix:$sock"
  LD_LIBRARY_PATH=$lib timeout --foreground 60 target/qemu/scene-c "unix:$sock" || status=1
  echo "Python: examples/python/scene.py unix:$sock"
  MCCS_CLIENT_LIB=$lib/libmccs_client.so timeout --foreground 60 \
    "$venv/bin/python" examples/python/scene.py "unix:$sock" || status=1
  pkill -f "path=$sock" 2> /dev/null; kill "$qemu_pid" 2> /dev/null; wait "$qemu_pid" 2> /dev/null
  return $status
}

# `mccs view` in headless Chromium (host-tests/tests/browser/view.py: each step named):
# its screenshots' PNG reader on random images first, then against the demo's soft
# device, then against the simulated arm board in QEMU.
view_browser() {
  local sock=target/qemu/view.sock qemu_pid status=0
  python3 host-tests/tests/browser/view.py --self-test || return 1
  echo "mccs view --demo"
  timeout --foreground 120 python3 host-tests/tests/browser/view.py target/debug/mccs --demo || status=1
  sim_board "$sock" target/qemu/view-firmware.log || return 1
  qemu_pid=$SIM_BOARD_PID
  echo "mccs view --connect unix:$sock (the simulated arm board in QEMU)"
  timeout --foreground 120 python3 host-tests/tests/browser/view.py target/debug/mccs \
    --connect "unix:$sock" || status=1
  pkill -f "path=$sock" 2> /dev/null; kill "$qemu_pid" 2> /dev/null; wait "$qemu_pid" 2> /dev/null
  return $status
}

# The scene's library builds for Windows (no unix sockets there; TCP and serial): the
# target's standard library added here if missing (the demo does not need it).
client_windows() {
  if ! rustup target list --installed | grep -qx x86_64-pc-windows-gnu; then
    echo "rustup target add x86_64-pc-windows-gnu (the scene's library, checked for Windows)"
    rustup target add x86_64-pc-windows-gnu || return 1
  fi
  cargo check --quiet -p mccs-client --target x86_64-pc-windows-gnu
}

# The host tests need only the host build, and they run beside the firmware stages (a
# QEMU run or a thumb link leaves a core idle; the tests keep both busy): started in the
# background once the host build is done, their output in $HOST_BG.log and their exit
# status in $HOST_BG.status. The host-tests stage waits for them. They run at a lower
# priority (nice), so that the stages in front, which are mostly one thread each near the
# end (the QEMU runs, the LTO links, the board's build), go first and the tests fill the
# other core until the end; at the same priority the tests ended early and the last
# stages ran on one core.
HOST_BG=$LOG_DIR/host-tests-background
# (Started from a subshell that ends at once, so that the run is not this shell's child:
# its CPU time, which it writes to $HOST_BG.cpu_ms, would otherwise be added to
# whichever stage was running when it ended, in the table's CPU column.)
start_host_tests() {
  (
    (
      renice -n 10 "$BASHPID" > /dev/null
      host_tests > "$HOST_BG.log" 2>&1 < /dev/null
      local status=$?
      children_cpu && echo "$CHILDREN_CPU_MS" > "$HOST_BG.cpu_ms"
      echo $status > "$HOST_BG.status.tmp" && mv "$HOST_BG.status.tmp" "$HOST_BG.status"
    ) &
  )
}

# (Without the background run, as when the host build failed, the tests run here.)
wait_host_tests() {
  if [ ! -e "$HOST_BG.log" ]; then
    host_tests
    return
  fi
  while [ ! -e "$HOST_BG.status" ]; do sleep 1; done
  cat "$HOST_BG.log"
  return "$(cat "$HOST_BG.status")"
}

run_stage fmt cargo fmt --all -- --check
# The host build first, so that the host tests start in the background as early as they
# can and fill what the stages after leave of the two cores (clippy's and the links'
# serial stretches): the wait for them after the last stage 18–21 s → 3 s
# (docs/performance.md, "The test command's time").
run_stage host-build cargo test --workspace --no-run && start_host_tests
# (The log decoder is linted where it is built, in firmware-builds: `build_decoder`.
# Checked here too, its dependencies, defmt-decoder's tree, took a third of this stage.)
run_stage clippy-host cargo clippy --workspace --exclude defmt-log --all-targets -- -D warnings
run_stage clippy-thumb clippy_thumb
run_stage firmware-builds firmware_builds && export DECODER_BUILT=1

# Then three lanes side by side (run_lanes, scripts/lib.sh), each its stages in order:
# the stages before them are CPU-bound on both cores, but these are mostly one thread
# each (a QEMU run, an LTO link, a browser), and one after another they left a core
# idle once the host tests had ended (from a fresh clone, before these stages end). The
# lanes share no file: the demo firmware and the bench are the first lane's alone; the
# board's variants each run from their own copy (board_build); each QEMU run with a
# link has its own socket. The link's lane keeps its priority and the
# others run at `nice` 5: a host on the link takes the link as lost after 400 ms without
# a frame (on its own clock), and a QEMU starved beside the bench's three QEMU runs sent
# none for 406 ms (tried). The QEMU runs of the other lanes count instructions, not time.
lane_firmware() {
  renice -n 5 "$BASHPID" > /dev/null
  run_stage demo-m4f-in-a-terminal demo_in_a_terminal
  run_stage demo-m3 demo_core m3
  run_stage demo-m0 demo_core m0
  run_stage demo-m4f-arm demo_arm
  run_stage tick-path tick_path
  run_stage panic-exits-with-failure panic_test
  run_stage bench bash scripts/bench.sh
  run_stage budget-breach-fails budget_test
  run_stage bench-truncated-fails bench_truncated
  run_stage firmware-size sizes
  run_stage client-windows client_windows
}
lane_board() {
  renice -n 5 "$BASHPID" > /dev/null
  run_stage board-f405 board_f405
  run_stage board-f405-arm board_f405_arm
  run_stage board-f405-arm-sim board_f405_arm_sim
  run_stage board-faults board_faults
}
lane_link() {
  run_stage link-qemu link_qemu
  run_stage scene-examples scene_examples
  run_stage view-browser view_browser
}
run_lanes lane_firmware lane_board lane_link
run_stage host-tests wait_host_tests
run_stage docs-figures python3 scripts/figures.py check

# The table, and the line CI reads.
host_log="$LOG_DIR/host-tests.log"
host_passed=$(grep -Eo 'test result: [a-zA-Z]+\. [0-9]+ passed' "$host_log" 2> /dev/null | awk '{s += $4} END {print s + 0}')
host_failed=$(grep -Eo '[0-9]+ failed;' "$host_log" 2> /dev/null | awk '{s += $1} END {print s + 0}')
passed=$host_passed
failed=$host_failed
# (CPU: user + system seconds of the stage's processes; the host-tests row gives the
# background run's, beside the other stages: its wall time is the wait at the end.)
printf '\n%-28s %-6s %7s %7s\n' stage result seconds cpu
for s in "${STAGES[@]}"; do
  IFS='|' read -r result name took cpu <<< "$s"
  if [ "$name" = host-tests ] && [ -e "$HOST_BG.cpu_ms" ]; then
    cpu=$((($(cat "$HOST_BG.cpu_ms") + 500) / 1000))
  fi
  printf '%-28s %-6s %7s %7s\n' "$name" "$result" "$took" "$cpu"
  if [ "$name" = host-tests ]; then
    # Counted by its tests; a failure without a failed test (a build error) counts one.
    if [ "$result" != ok ] && [ "$host_failed" = 0 ]; then failed=$((failed + 1)); fi
    continue
  fi
  if [ "$result" = ok ]; then passed=$((passed + 1)); else failed=$((failed + 1)); fi
done
echo "host tests: $host_passed passed, $host_failed failed; logs in $LOG_DIR; $((SECONDS - all_start)) s in all"
echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
