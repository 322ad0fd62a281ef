#!/usr/bin/env bash
# Runs the STM32F405 board firmware in QEMU (netduinoplus2) in the foreground with its
# host link (USART2, the machine's second -serial) on the unix socket SOCKET, QEMU the
# server: connect with `mccs link --connect unix:SOCKET …` or the client library. The
# log, decoded, on stdout. Ends with QEMU (Ctrl-C, or the caller's kill).
#
#   scripts/qemu-link.sh [--sim [--one-dof] | --arm] [--icount-shift N] SOCKET
#
#   (none)        the 1-DOF board: QEMU's SPI has no encoder behind it, so the device
#                 is in its safe state after tick 9 (a replay, a tissue load and the
#                 link's rules run as on a board);
#   --arm         the arm board: never homed in QEMU (zero duty);
#   --sim         the arm board on a simulated arm (--features arm,sim): homed at start,
#                 its hand palpating the tissue over and over: the live loop end to end;
#   --sim --one-dof   the 1-DOF board on a simulated lever pressing the tissue;
#   --icount-shift N  an instruction takes 2^N ns (default 3: 125,000 instructions a
#                 1 kHz tick, the M4F at 168 MHz; 4 halves the core: its ticks overrun).
#
# QEMU_EXTRA, if set, is added to QEMU's options (the link tests open a QMP socket with
# it, to read the board's RAM: how deep its stack went).
#
# Time counts instructions (`-icount shift=N,sleep=off`, as every QEMU run here): an idle
# core's next tick comes at once, so the device's ticks run as fast as QEMU runs the
# tick's instructions — about 1.3 ticks a millisecond of the host's on the simulated arm
# (`sleep=on` stops the clock while the core waits for an interrupt in QEMU 7.2: no tick
# would come). The link's 100 ms timeout is 100 of the device's ticks: a host keeps
# talking (the client's keepalive: every 25 ms).
set -euo pipefail
cd "$(dirname "$0")/.."
usage() {
  echo "usage: scripts/qemu-link.sh [--sim [--one-dof] | --arm] [--icount-shift N] SOCKET" >&2
  exit 2
}
features=qemu-link sim=0 one_dof=0 shift=3 socket=
while [ $# -gt 0 ]; do
  case "$1" in
    --sim) sim=1 ;;
    --one-dof) one_dof=1 ;;
    --arm) features=qemu-link,arm ;;
    --icount-shift) [ $# -ge 2 ] || usage; shift=$2; shift ;;
    -*) echo "qemu-link: unknown option '$1'" >&2; usage ;;
    *) [ -z "$socket" ] || usage; socket=$1 ;;
  esac
  shift
done
[ -n "$socket" ] || usage
case "$shift" in [0-9]) ;; *) echo "qemu-link: --icount-shift must be 0 … 9, not '$shift'" >&2; exit 2 ;; esac
if [ "$sim" = 1 ]; then
  if [ "$one_dof" = 1 ]; then features=qemu-link,sim; else features=qemu-link,sim,arm; fi
elif [ "$one_dof" = 1 ]; then
  echo "qemu-link: --one-dof goes with --sim" >&2
  exit 2
fi
LOG_DIR=target/logs/qemu-link
source scripts/lib.sh  # run_stage, build_decoder, $DECODER, $TARGET_DIR
run_stage build-decoder build_decoder
# (One ELF per feature set, so that runs of several variants side by side do not race.)
run_stage "build-firmware-${features//,/-}" board_build "$features"
elf=$(board_elf "$features")
rm -f "$socket"
echo "qemu-link: running it in QEMU (netduinoplus2, --features $features), its link on unix:$socket" >&2
qemu-system-arm -machine netduinoplus2 -display none -monitor none \
  -semihosting-config enable=on,target=native -icount "shift=$shift,sleep=off" ${QEMU_EXTRA:-} \
  -serial null -chardev "socket,id=link,path=$socket,server=on,wait=off" -serial chardev:link \
  -kernel "$elf" < /dev/null 2> >(grep -v "Timer with period zero" >&2) \
  | "$DECODER" "$elf"
