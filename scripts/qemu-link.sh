#!/usr/bin/env bash
# Runs the STM32F405 board firmware (--features qemu-link) in QEMU in the foreground with its
# host link (USART2, the machine's second -serial) on the unix socket SOCKET, QEMU the
# server: connect with `mccs link --connect unix:SOCKET …`. The log, decoded, on stdout.
# Time is counted in instructions (-icount shift=3,sleep=off, as every QEMU run here):
# an idle firmware's next tick comes at once, so the device's ticks run faster than the
# host's clock, and the link's 100 ms watchdog is 100 of the device's ticks (a few ms of
# the host's silence: a host keeps talking, or re-arms). Ends with QEMU (Ctrl-C, or
# the caller's kill); QEMU's encoder reads zeros, so the live device is in its safe
# state after tick 9: a replay, a tissue load and the link's rules run as on a board.
#   scripts/qemu-link.sh SOCKET
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -ne 1 ] || [ -z "$1" ]; then
  echo "usage: scripts/qemu-link.sh SOCKET (a path for the unix socket QEMU creates)" >&2
  exit 2
fi
socket=$1
LOG_DIR=target/logs/qemu-link
source scripts/lib.sh  # run_stage, build_decoder, $DECODER, $TARGET_DIR
run_stage build-decoder build_decoder
run_stage build-firmware cargo build --release -p haptic-f405 --target thumbv7em-none-eabihf \
  --bin haptic-f405 --features qemu-link
elf=$TARGET_DIR/thumbv7em-none-eabihf/release/haptic-f405
rm -f "$socket"
echo "qemu-link: running it in QEMU (netduinoplus2), its link on unix:$socket" >&2
qemu-system-arm -machine netduinoplus2 -display none -monitor none \
  -semihosting-config enable=on,target=native -icount shift=3,sleep=off \
  -serial null -chardev "socket,id=link,path=$socket,server=on,wait=off" -serial chardev:link \
  -kernel "$elf" < /dev/null 2> >(grep -v "Timer with period zero" >&2) \
  | "$DECODER" "$elf"
