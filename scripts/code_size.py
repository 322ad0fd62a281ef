#!/usr/bin/env python3
"""The flash a function costs a firmware: the code only it reaches.

From the ELF's disassembly (llvm-objdump, as scripts/check_tick_path.py reads it), the
functions reachable from ROOT by direct calls and tail calls, less those the rest of the
program reaches without passing through ROOT (from the reset handler and the exception
and interrupt handlers); their sizes summed from the symbol table (llvm-nm). Data they
read (constants in .rodata) is not counted: the figure is code. Prints
`CODE core=<core> root=<name> bytes=<n> functions=<k>`.

Usage: code_size.py ELF CORE ROOT_REGEX NAME
"""
import re
import subprocess
import sys
from pathlib import Path


def tool(name: str) -> str:
    sysroot = subprocess.run(["rustc", "--print", "sysroot"], capture_output=True, text=True, check=True).stdout.strip()
    path = Path(sysroot) / "lib/rustlib/x86_64-unknown-linux-gnu/bin" / name
    if not path.exists():
        sys.exit(f"code_size: {name} missing: rustup component add llvm-tools")
    return str(path)


CALL = re.compile(r"\b(bl|blx|b|b\.w|bne|beq|b\w\w)(\.w)?\s+0x[0-9a-f]+ <([^>+]+)(\+0x[0-9a-f]+)?>")


def calls(elf: str) -> dict:
    text = subprocess.run([tool("llvm-objdump"), "-d", "-C", "--no-show-raw-insn", elf],
                          capture_output=True, text=True, check=True).stdout
    graph: dict[str, set] = {}
    current = None
    for line in text.splitlines():
        m = re.match(r"^[0-9a-f]+ <(.+)>:$", line)
        if m:
            current = m.group(1)
            graph.setdefault(current, set())
        elif current is not None:
            c = CALL.search(line.split(":", 1)[-1])
            if c and c.group(4) is None and c.group(3) != current:
                graph[current].add(c.group(3))
    return graph


def sizes(elf: str) -> dict:
    out = subprocess.run([tool("llvm-nm"), "-S", "-C", "--defined-only", elf],
                         capture_output=True, text=True, check=True).stdout
    got = {}
    for line in out.splitlines():
        parts = line.split(None, 3)
        if len(parts) == 4 and parts[2] in "tT":
            got[parts[3]] = max(got.get(parts[3], 0), int(parts[1], 16))
    return got


def reach(graph: dict, roots, stop=None) -> set:
    seen, todo = set(), list(roots)
    while todo:
        f = todo.pop()
        if f in seen or (stop is not None and stop.search(f)):
            continue
        seen.add(f)
        todo.extend(graph.get(f, ()))
    return seen


def main() -> int:
    if len(sys.argv) != 5:
        print("usage: code_size.py ELF CORE ROOT_REGEX NAME", file=sys.stderr)
        return 2
    elf, core, root, name = sys.argv[1:]
    if not Path(elf).is_file():
        print(f"code_size: {elf}: no such file (build the release firmware first)", file=sys.stderr)
        return 2
    graph, size = calls(elf), sizes(elf)
    root_re = re.compile(root)
    roots = [f for f in graph if root_re.search(f)]
    if not roots:
        print(f"code_size: {elf}: no function matches {root}", file=sys.stderr)
        return 1
    # Every entry into the program: the reset handler, and the handlers the vector table
    # names (cortex-m-rt's names, and every function nothing calls).
    called = set().union(*graph.values())
    entries = [f for f in graph if f == "Reset" or f not in called]
    rest = reach(graph, [e for e in entries if not root_re.search(e)], root_re)
    only = reach(graph, roots) - rest
    total = sum(size.get(f, 0) for f in only)
    print(f"CODE core={core} root={name} bytes={total} functions={len(only)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
