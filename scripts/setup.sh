#!/usr/bin/env bash
# Installs what the project needs on a fresh machine and says so: the three thumb
# targets, rustup's clippy and rustfmt (the test command's lints and format check) and
# llvm-tools (for the tick-path check), and Debian's qemu-system-arm and chromium (as
# root; chromium for `mccs view`'s browser test).
# Sourced by scripts/demo.sh and scripts/test.sh.
set -euo pipefail

need_targets=(thumbv6m-none-eabi thumbv7m-none-eabi thumbv7em-none-eabihf)
have_targets=$(rustup target list --installed)
missing=()
for t in "${need_targets[@]}"; do
  grep -qx "$t" <<< "$have_targets" || missing+=("$t")
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "setup: rustup target add ${missing[*]}" >&2
  rustup target add "${missing[@]}" >&2
fi

for component in clippy rustfmt; do
  if ! rustup component list --installed | grep -q "^$component"; then
    echo "setup: rustup component add $component (the test command's lints and format check)" >&2
    rustup component add "$component" >&2
  fi
done

if ! rustup component list --installed | grep -q '^llvm-tools'; then
  echo "setup: rustup component add llvm-tools (llvm-objdump and llvm-size)" >&2
  rustup component add llvm-tools >&2
fi

if ! command -v qemu-system-arm > /dev/null 2>&1; then
  if [ "$(id -u)" = 0 ]; then
    echo "setup: installing Debian's qemu-system-arm (apt-get, about a minute)" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq > /dev/null
    apt-get install -y -qq qemu-system-arm > /dev/null
  else
    echo "setup: qemu-system-arm is missing and this is not root: run 'sudo apt-get install qemu-system-arm' and try again" >&2
    exit 1
  fi
fi

if ! command -v chromium > /dev/null 2>&1; then
  if [ "$(id -u)" = 0 ]; then
    echo "setup: installing Debian's chromium (apt-get, a minute or two: the browser test of mccs view)" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq > /dev/null
    apt-get install -y -qq --no-install-recommends chromium > /dev/null
  else
    # (Only the test command's browser stage needs it: the demo goes on without.)
    echo "setup: chromium is missing and this is not root: 'sudo apt-get install chromium' for the browser test of mccs view" >&2
  fi
fi
