#!/usr/bin/env python3
"""Flash and static RAM of a firmware ELF (llvm-size from rustup's llvm-tools), held to a
budget: prints `SIZE target=<t> bin=<b> flash=<bytes> ram=<bytes>` and exits 1 beyond it.

Usage: size.py ELF TARGET BIN FLASH_MAX RAM_MAX"""
import subprocess
import sys
from pathlib import Path


def tool(name: str) -> str:
    sysroot = subprocess.run(["rustc", "--print", "sysroot"], capture_output=True, text=True, check=True).stdout.strip()
    host = [l.split()[1] for l in subprocess.run(["rustc", "-vV"], capture_output=True, text=True, check=True).stdout.splitlines() if l.startswith("host:")][0]
    return str(Path(sysroot) / "lib/rustlib" / host / "bin" / name)


def main() -> int:
    args = sys.argv[1:]
    if len(args) != 5 or not args[3].isdigit() or not args[4].isdigit():
        print("usage: size.py ELF TARGET BIN FLASH_MAX RAM_MAX (the budgets in bytes)", file=sys.stderr)
        return 2
    elf, target, binary, flash_max, ram_max = args[0], args[1], args[2], int(args[3]), int(args[4])
    if not Path(elf).is_file():
        print(f"size: {elf}: no such file (build the release firmware first)", file=sys.stderr)
        return 2
    out = subprocess.run([tool("llvm-size"), "-A", elf], capture_output=True, text=True, check=True).stdout
    sec = {}
    for line in out.splitlines():
        p = line.split()
        if len(p) >= 3 and p[0].startswith(".") and p[1].isdigit():
            sec[p[0]] = int(p[1])
    flash = sum(sec.get(s, 0) for s in (".vector_table", ".text", ".rodata", ".data", ".gnu.sgstubs"))
    ram = sum(sec.get(s, 0) for s in (".data", ".bss", ".uninit"))
    print(f"SIZE target={target} bin={binary} flash={flash} ram={ram} flash_max={flash_max} ram_max={ram_max}")
    if flash > flash_max or ram > ram_max:
        print(f"size: {target} {binary}: flash {flash} B (at most {flash_max}) or RAM {ram} B (at most {ram_max}) over budget")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
