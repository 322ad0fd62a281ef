#!/usr/bin/env bash
# Installs what the project needs on a fresh machine: the three thumb targets, rustup's
# llvm-tools, Debian's qemu-system-arm (as root), and defmt-print (to decode the
# firmware's logs). Sourced by
# scripts/demo.sh and scripts/test.sh.
set -euo pipefail

need_targets=(thumbv6m-none-eabi thumbv7m-none-eabi thumbv7em-none-eabihf)
have_targets=$(rustup target list --installed)
for t in "${need_targets[@]}"; do
  if ! grep -qx "$t" <<<"$have_targets"; then
    echo "setup: rustup target add $t" >&2
    rustup target add "$t" >&2
  fi
done

if ! rustup component list --installed | grep -q '^llvm-tools'; then
  echo "setup: rustup component add llvm-tools (llvm-objdump, for the tick-path check)" >&2
  rustup component add llvm-tools >&2
fi

if ! command -v qemu-system-arm >/dev/null 2>&1; then
  if [ "$(id -u)" = 0 ]; then
    echo "setup: installing Debian's qemu-system-arm" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq >&2
    apt-get install -y -qq qemu-system-arm >/dev/null
  else
    echo "setup: qemu-system-arm is missing and this is not root: run 'sudo apt-get install qemu-system-arm' and try again" >&2
    exit 1
  fi
fi

if ! command -v defmt-print >/dev/null 2>&1; then
  echo "setup: cargo install defmt-print (a few minutes, once)" >&2
  cargo install defmt-print --version 1.2.0 --locked --quiet >&2
fi
