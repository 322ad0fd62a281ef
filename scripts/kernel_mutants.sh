#!/usr/bin/env bash
# Shows that the bench firmware's kernel and arm checks (firmware/src/bin/bench/
# kernel_check.rs, arm_check.rs) catch faults in the M4F's assembly (the loops,
# src/arith/wide_dsp/; the arm's pose and drive, src/arm/pose_dsp.rs and drive_dsp.rs):
# puts one fault at a time into a scratch worktree of HEAD, runs the M4F bench up to its
# KERNEL and ARMCHECK lines and prints `MUTANT <fault>: <n> of <states> states differ`
# (for the arm's: of its comparisons, two a pose and one each other force); the last line
# counts the faults caught. Not in the test command
# (about 25 s per fault once built; the first build takes a minute or two).
# Usage: scripts/kernel_mutants.sh
set -euo pipefail
cd "$(dirname "$0")/.."
T=thumbv7em-none-eabihf
root=$(pwd)
source scripts/lib.sh  # build_decoder, $DECODER
[[ $DECODER = /* ]] || DECODER="$root/$DECODER"
work=$(mktemp -d)
trap 'git worktree remove --force "$work" >/dev/null 2>&1 || rm -rf "$work"' EXIT
git worktree add --detach "$work" HEAD >/dev/null
build_decoder --quiet
export CARGO_TARGET_DIR="$root/target/mutants"
srcs=("$work/src/arith/wide_dsp/spring_loop.rs" "$work/src/arith/wide_dsp/integrate.rs"
  "$work/src/arm/pose_dsp.rs" "$work/src/arm/drive_dsp.rs")
for f in "${srcs[@]}"; do cp "$f" "$f.orig"; done

# name | text to replace (its first occurrence) | replacement
# (The unmasked shift is the table header's own, read through the segments pointer at
# [sp, #12]: −20 is `RawTable::shift`'s offset from its first segment.)
mutants=(
  "edge vector hold one bit narrower|ssat r0, #25, r0|ssat r0, #24, r0"
  "a r hold one bit narrower|usat r9, #25, r9|usat r9, #24, r9"
  "Newton factor hold one bit narrower|usat r8, #24, r8|usat r8, #23, r8"
  "warm start hold one bit narrower|usat r10, #30, r10|usat r10, #29, r10"
  "force hold one bit narrower|\"ssat r5, #27, r5|\"ssat r5, #26, r5"
  "lower line's product hold one bit narrower|\"ssat r5, #20, r5|\"ssat r5, #19, r5"
  "lower line's sum not saturating|\"qadd r5, r5, r3|\"add r5, r5, r3"
  "lower line's difference not saturating|\"qsub r3, r9, r3|\"sub r3, r9, r3"
  "upper line's difference not saturating|\"qsub r3, r9, r5|\"sub r3, r9, r5"
  "tau shifted arithmetically|\"lsr r3, r3, #1|\"asr r3, r3, #1"
  "coefficients' shift not masked|\"ldr r3, [sp, #16]|\"ldr r3, [sp, #12]\\n\", \"ldr r3, [r3, #-20]"
  "push hold one bit narrower|#27, \", \$w|#26, \", \$w"
  "ground damping added, not subtracted|\"smmlsr \", \$w, \", \", \$va|\"smmlar \", \$w, \", \", \$va"
  "two-node law product added, not subtracted|\"smmlsr \",|\"smmlar \","
  "gentle lower line's product rounded|\"smmul r3, r5, r3\\n\",)|\"smmulr r3, r5, r3\\n\",)"
  "integrator velocity hold one bit narrower|ssat r8, #23, r8|ssat r8, #22, r8"
  "integrator displacement hold one bit narrower|ssat r1, #31, r1|ssat r1, #30, r1"
  "accumulator cleared at the wrong offset|\"str r3, [lr, #8]\"|\"str r3, [lr, #4]\""
  "symplectic position step from the old velocity|\"add r3, r6, r6\"|\"add r3, r3, r6\""
  "paper's position step from the new velocity|\"add r4, r4, r8\"|\"add r4, r8, r8\""
  "graded corner's segment bits one lower|ubfx r5, r3, #29, #2|ubfx r5, r3, #28, #2"
  "graded corner's tau one bit lower|ubfx r3, r3, #14, #15|ubfx r3, r3, #13, #15"
  "graded corner's octave not in the index|add r8, r8, r5, lsl #2|add r8, r8, r5, lsl #3"
  "graded corner's strain difference reversed|sub r3, r3, r9\\n|sub r3, r9, r3\\n"
  "graded corner's line above never taken|blt 54b|b 54b"
  "b's velocity read one word off|ldrd r11, lr, [r4], #8|ldrd r11, lr, [r4, #4]!"
  "pose: cos's upper point one word off|ldr r9, [r5, #1028]|ldr r9, [r5, #1024]"
  "pose: sin's interpolation one bit high|add r3, r3, r8, asr #7|add r3, r3, r8, asr #6"
  "pose: a phase's fraction one bit short|lsr r4, r4, #16|lsr r4, r4, #17"
  "pose: the joints' range one phase off at its edge|\"sub r5, r4, r5\\n\",|\"sub r5, r4, r5\\n\", \"sub r5, r5, #1\\n\","
  "pose: C's share of the reach dropped|smmla r10, r4, r3, r10|smmul r10, r4, r3"
  "pose: C's share of the height added|sub lr, lr, r4|add lr, lr, r4"
  "pose: the probe's hold one bit wider|ssat r4, #24, r3|ssat r4, #25, r3"
  "pose: OUTSIDE read from the V flag, not Q|ubfx r3, r3, #27, #1|ubfx r3, r3, #28, #1"
  "drive: A's torque shifted one bit short|lsr r8, r8, #27|lsr r8, r8, #26"
  "drive: v's difference reversed|sub r10, r10, r11|sub r10, r11, r10"
  "drive: a duty's overflow check one bit short|cmp r8, r5, asr #31\\n|cmp r8, r5, asr #30\\n"
  "drive: a saturated duty's value one bit off|eorne r5, r5, #0x80000000\\n|eorne r5, r5, #0x40000000\\n"
  "drive: a duty's shift down logical|asr r5, r5, r9\\n|lsr r5, r5, r9\\n"
  "drive: 100 % offset halved in the scaling's check|add r4, r5, #0x10000\\n|add r4, r5, #0x8000\\n"
)
echo "... building the M4F bench once in a scratch worktree (a minute or two from clean)" >&2
(cd "$work" && cargo build --release -p mccs-firmware --target $T --bin bench)
caught=0
for m in "${mutants[@]}"; do
  IFS='|' read -r name from to <<< "$m"
  for f in "${srcs[@]}"; do cp "$f.orig" "$f"; done
  python3 - "$from" "$to" "${srcs[@]}" <<'EOF'
import sys
a, b, *paths = sys.argv[1:]
for p in paths:
    s = open(p).read()
    if a in s:
        open(p, "w").write(s.replace(a, b, 1))
        break
else:
    sys.exit(f"kernel_mutants: '{a}' is in none of {paths}")
EOF
  echo "... $name: building and running the M4F bench" >&2
  (cd "$work" && cargo build --quiet --release -p mccs-firmware --target $T --bin bench)
  line=$( (cd "$work" && timeout --foreground 300 cargo run --quiet --release -p mccs-firmware \
      --target $T --bin bench < /dev/null 2>/dev/null || true) \
    | "$DECODER" "$CARGO_TARGET_DIR/$T/release/bench" | grep -E '^(KERNEL|ARMCHECK) ' || true)
  # The kernel's faults stop the bench at its KERNEL line; the arm's show in ARMCHECK.
  case $name in
    pose:* | drive:*)
      line=$(grep '^ARMCHECK' <<< "$line" || true)
      n=$(sed -n 's/.*mismatches=\([0-9]*\).*/\1/p' <<< "$line")
      # Each pose is checked twice (its pose, its drive), each other force once.
      of=$(sed -n 's/.*poses=\([0-9]*\) full_forces=\([0-9]*\) scale_edges=\([0-9]*\).*/\1 \2 \3/p' <<< "$line" \
        | awk '{print 2 * $1 + $2 + $3}')
      echo "MUTANT $name: ${n:-no check line, so none} of ${of:-the} comparisons differ" ;;
    *)
      line=$(grep -m1 '^KERNEL' <<< "$line" || true)
      n=$(sed -n 's/.*mismatches=\([0-9]*\).*/\1/p' <<< "$line")
      of=$(sed -n 's/.*states=\([0-9]*\).*/\1/p' <<< "$line")
      echo "MUTANT $name: ${n:-no check line, so none} of ${of:-the} states differ" ;;
  esac
  if [ -n "$n" ] && [ "$n" != 0 ]; then caught=$((caught + 1)); fi
done
echo "$caught of ${#mutants[@]} faults caught"
