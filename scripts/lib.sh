# Shared by the scripts (sourced): stages that say what they do, tick while they run,
# log to a file, and time themselves.
#
#   run_stage NAME COMMAND...   runs COMMAND with its output in $LOG_DIR/NAME.log; prints
#                               "… NAME (12 s)" every 10 s while it runs, then
#                               "ok   NAME (34 s)" or "FAIL NAME (34 s): see LOG";
#                               returns COMMAND's status.
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

run_stage() {
  local name=$1
  shift
  local log="$LOG_DIR/$name.log"
  local start=$SECONDS
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
  local took=$((SECONDS - start))
  if [ "$status" = 0 ]; then
    say "ok   $name ($took s)"
    STAGES+=("ok|$name|$took")
  else
    say "FAIL $name ($took s): exit $status; see $log"
    tail -n 15 "$log" | sed 's/^/     | /' >&2
    STAGES+=("FAIL|$name|$took")
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
