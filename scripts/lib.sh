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
#                               clippy-host stage leaves it out.

LOG_DIR=${LOG_DIR:-target/logs}
mkdir -p "$LOG_DIR"
STAGES=()

# Where cargo builds: $CARGO_TARGET_DIR when it is set, as cargo does.
TARGET_DIR=${CARGO_TARGET_DIR:-target}
DECODER=$TARGET_DIR/tool/defmt-log
build_decoder() {
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
