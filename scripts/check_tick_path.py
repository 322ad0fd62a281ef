#!/usr/bin/env python3
"""Static check of the per-tick path of a release firmware ELF.

From its disassembly (llvm-objdump from rustup's llvm-tools), follow every direct call
and tail call out of the SysTick handler — leaving out the first-run initialisation
(`haptic::firmware::init`), which builds the controller before the ticks start — and
fail if anything reached is, or contains, one of:

- a panic path (`panic`, `unwrap_failed`, `expect_failed`, bounds-check panics),
- an integer-division helper (`__aeabi_*div*`, `__udivsi3`, …),
- a soft-float helper (`__aeabi_f*`, `__aeabi_d*`, `__*sf*`, `__*df*`),
- a hardware floating-point instruction (`v….f32` / `v….f64`),
- an indirect call (whose target this check cannot see).

Usage: check_tick_path.py ELF [ENTRY [INIT]]   (prints the reachable functions; exit 1 on
a find). ENTRY is the tick's handler (default SysTick); INIT a regular expression naming
its first-run initialisation (default `haptic::firmware::init`). The board firmware:
`check_tick_path.py target/thumbv7em-none-eabihf/release/haptic-f405 TIM2 haptic_f405::firmware::init`.
"""
import re
import subprocess
import sys
from pathlib import Path


def objdump() -> str:
    sysroot = subprocess.run(["rustc", "--print", "sysroot"], capture_output=True, text=True, check=True).stdout.strip()
    tool = Path(sysroot) / "lib/rustlib/x86_64-unknown-linux-gnu/bin/llvm-objdump"
    if not tool.exists():
        sys.exit("check_tick_path: llvm-objdump missing: rustup component add llvm-tools")
    return str(tool)


FORBIDDEN_NAME = re.compile(
    r"panic|unwrap_failed|expect_failed|slice_(start|end)_index|"
    r"__aeabi_\w*div|__(u)?(div|mod)[sd]i3|"
    r"__aeabi_[fd]\w+|__\w+[sd]f[23]\b|__(extend|trunc)\w*f2|__fix\w*[sd]f|__float\w*[sd]f"
)
FLOAT_INSN = re.compile(r"^\s*v[a-z0-9]+(\.[a-z]+)*\.f(32|64)\b")


def main() -> int:
    if not 2 <= len(sys.argv) <= 4:
        print("usage: check_tick_path.py ELF [ENTRY [INIT]]", file=sys.stderr)
        return 2
    elf = sys.argv[1]
    if not Path(elf).is_file():
        print(f"check_tick_path: {elf}: no such file (build the release firmware first)", file=sys.stderr)
        return 2
    entry = sys.argv[2] if len(sys.argv) > 2 else "SysTick"
    text = subprocess.run([objdump(), "-d", "-C", "--no-show-raw-insn", elf], capture_output=True, text=True, check=True).stdout
    funcs: dict[str, list[str]] = {}
    current = None
    for line in text.splitlines():
        m = re.match(r"^[0-9a-f]+ <(.+)>:$", line)
        if m:
            current = m.group(1)
            funcs.setdefault(current, [])
        elif current is not None and line.strip():
            funcs[current].append(line)
    if entry not in funcs:
        print(f"check_tick_path: {elf}: no function {entry}")
        return 1
    skip = re.compile((sys.argv[3] if len(sys.argv) > 3 else r"haptic::firmware::init") + r"\b")
    seen, todo, problems = set(), [entry], []
    while todo:
        f = todo.pop()
        if f in seen or skip.search(f):
            continue
        seen.add(f)
        if FORBIDDEN_NAME.search(f):
            problems.append(f"reaches {f}")
        for insn in funcs.get(f, []):
            body = insn.split(":", 1)[-1]
            if FLOAT_INSN.match(body):
                problems.append(f"{f}: floating point: {body.strip()}")
            m = re.search(r"\b(bl|blx|b|b\.w|bne|beq|b\w\w)(\.w)?\s+0x[0-9a-f]+ <([^>+]+)(\+0x[0-9a-f]+)?>", body)
            if m and m.group(4) is None and m.group(3) != f:
                todo.append(m.group(3))
            if re.search(r"\bblx\s+r\d+", body) or re.search(r"\bbx\s+r(?!14\b)\d+", body.replace("lr", "r14")):
                problems.append(f"{f}: indirect call: {body.strip()}")
    for f in sorted(seen):
        print(f"  {f}")
    if problems:
        for p in sorted(set(problems)):
            print(f"FAIL {p}")
        return 1
    print(f"tick path of {elf}: {len(seen)} functions, no panic path, no division or float helper, no float instruction")
    return 0


if __name__ == "__main__":
    sys.exit(main())
