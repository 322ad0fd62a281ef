# Shared by the scripts (sourced): stages that say what they do, tick while they run,
# log to a file, and time themselves.
#
#   run_stage NAME COMMAND...   runs COMMAND with its output in $LOG_DIR/NAME.log; prints
#                               "… NAME (12 s)" every 10 s while it runs, then
#                               "ok   NAME (34 s)" or "FAIL NAME (34 s): see LOG";
#                               returns COMMAND's status. STAGES gets
#                               "result|NAME|seconds|CPU seconds" (user + system of
#                               COMMAND and what it waited for).
#   say TEXT                    one line on stderr.
#   $TARGET_DIR                 cargo's target folder ($CARGO_TARGET_DIR, else target).
#   build_decoder [ARGS]        builds the defmt log decoder, $DECODER (its own cargo
#                               profile, `tool`: unoptimised, it builds in half the time),
#                               linted as it builds (clippy's driver as the workspace's
#                               rustc wrapper, warnings denied): the test command's
#                               clippy-host stage leaves it out. Nothing when
#                               DECODER_BUILT=1 (the test command, once it built it: a
#                               build relinks the file, which a run beside it may be
#                               starting).
#   run_lanes LANE...           runs each LANE, a function that runs its stages one after
#                               another with run_stage, side by side; their rows join
#                               STAGES in the order of the lanes.
#   board_build FEATURES [ARGS] builds the board firmware (boards/f405) with FEATURES
#                               ("" for none) and copies it to `board_elf FEATURES`.
#   board_elf FEATURES          that copy's path: one per feature set, as cargo writes
#                               every variant to one path (see board_build).
#   qemu_runner TARGET          the QEMU command line of TARGET's runner in
#                               .cargo/config.toml, without the ELF.

LOG_DIR=${LOG_DIR:-target/logs}
mkdir -p "$LOG_DIR"
STAGES=()

# Where cargo builds: $CARGO_TARGET_DIR when it is set, as cargo does.
TARGET_DIR=${CARGO_TARGET_DIR:-target}
DECODER=$TARGET_DIR/tool/defmt-log
build_decoder() {
  [ "${DECODER_BUILT:-}" = 1 ] && [ -x "$DECODER" ] && return 0
  RUSTFLAGS=-Dwarnings RUSTC_WORKSPACE_WRAPPER="$(rustup which clippy-driver)" \
    cargo build -p defmt-log --profile tool "$@"
}

say() { printf '%s\n' "$*" >&2; }

# CHILDREN_CPU_MS: the user + system CPU time, in ms, of this shell's children that have
# ended and been waited for (bash's `times`, second line: `0m1.250s 0m0.310s`). It sets
# a variable rather than printing: `times` in a command substitution's subshell counts
# that subshell's children only.
children_cpu() {
  local user sys
  times > "$LOG_DIR/.times.$BASHPID"
  { read -r _ _; read -r user sys; } < "$LOG_DIR/.times.$BASHPID"
  rm -f "$LOG_DIR/.times.$BASHPID"
  CHILDREN_CPU_MS=$(awk -v u="$user" -v s="$sys" 'function ms(t, m) {
      split(t, m, /[ms]/); return (m[1] * 60 + m[2]) * 1000 }
    BEGIN { printf "%d\n", ms(u) + ms(s) }')
}

run_stage() {
  local name=$1
  shift
  local log="$LOG_DIR/$name.log"
  local start=$SECONDS cpu_start
  children_cpu
  cpu_start=$CHILDREN_CPU_MS
  say "...  $name"
  "$@" > "$log" 2>&1 < /dev/null &
  local pid=$!
  (
    while sleep 10; do
      kill -0 "$pid" 2> /dev/null || exit 0
      say "...  $name ($((SECONDS - start)) s, still running; log: $log)"
    done
  ) &
  local ticker=$!
  local status=0
  wait "$pid" || status=$?
  kill "$ticker" 2> /dev/null || true
  wait "$ticker" 2> /dev/null || true
  local took=$((SECONDS - start)) cpu
  children_cpu
  cpu=$(((CHILDREN_CPU_MS - cpu_start + 500) / 1000))
  if [ "$status" = 0 ]; then
    say "ok   $name ($took s)"
    STAGES+=("ok|$name|$took|$cpu")
  else
    say "FAIL $name ($took s): exit $status; see $log"
    tail -n 15 "$log" | sed 's/^/     | /' >&2
    STAGES+=("FAIL|$name|$took|$cpu")
  fi
  return "$status"
}

# The target triple of a core name.
core_target() {
  case "$1" in
    m4f) echo thumbv7em-none-eabihf ;;
    m3) echo thumbv7m-none-eabi ;;
    m0) echo thumbv6m-none-eabi ;;
    *) say "core must be m4f, m3 or m0, not '$1'"; return 2 ;;
  esac
}

# Stages side by side: each lane in a subshell, which writes its rows to a file as it
# ends; a lane that ends without it (killed, or its shell failed) is a failed row.
run_lanes() {
  local lane pids=()
  for lane in "$@"; do
    rm -f "$LOG_DIR/.lane.$lane"
    (
      STAGES=()
      "$lane"
      printf '%s\n' "${STAGES[@]}" > "$LOG_DIR/.lane.$lane.tmp" \
        && mv "$LOG_DIR/.lane.$lane.tmp" "$LOG_DIR/.lane.$lane"
    ) &
    pids+=("$!")
  done
  wait "${pids[@]}"
  for lane in "$@"; do
    if [ -s "$LOG_DIR/.lane.$lane" ]; then
      mapfile -t -O "${#STAGES[@]}" STAGES < "$LOG_DIR/.lane.$lane"
    else
      say "FAIL lane $lane: it ended without its stages' results"
      STAGES+=("FAIL|lane-$lane|0|0")
    fi
    rm -f "$LOG_DIR/.lane.$lane"
  done
}

# The board firmware's variants. Cargo writes each to one path
# (…/release/haptic-f405), and a build that has nothing to do writes it again; so each
# is copied to its own path, the build and the copy under one lock, and a script reads
# its copy: scripts that run side by side (the test command's lanes) then each run the
# variant they built. (`haptic-f405-default` without features.)
board_elf() {
  local features=${1:-default}
  echo "$TARGET_DIR/thumbv7em-none-eabihf/release/haptic-f405-${features//,/-}"
}

board_build() {
  local features=$1 elf
  shift
  elf=$(board_elf "$features")
  mkdir -p "$TARGET_DIR"
  (
    flock 9
    cargo build --release -p haptic-f405 --target thumbv7em-none-eabihf --bin haptic-f405 \
      --features "$features" "$@" \
      && cp "$TARGET_DIR/thumbv7em-none-eabihf/release/haptic-f405" "$elf.tmp" \
      && mv "$elf.tmp" "$elf"
  ) 9> "$TARGET_DIR/.board-build.lock"
}

qemu_runner() {
  local runner
  runner=$(sed -n "/^\[target\.$1\]/,/^runner/s/^runner = \"\(.*\)\"$/\1/p" .cargo/config.toml)
  [ -n "$runner" ] || { say "no runner for $1 in .cargo/config.toml"; return 1; }
  echo "$runner"
}
