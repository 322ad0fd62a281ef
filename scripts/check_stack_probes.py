#!/usr/bin/env python3
"""Flags x86-64 functions whose stack probe loop may clobber a live r11.

An x86-64 build with link-time optimisation lets LLVM move a function's first checks
ahead of its prologue (shrink-wrapping). For a frame over 32 KiB the prologue probes
the stack in a loop that takes r11 as its scratch register without checking that it is
free (an LLVM defect; llvm/llvm-project#198699 is the same on RISC-V). A value the
moved checks left in r11 is then lost: `Solver::window_as` lost the tissue's height
this way until its frame moved into `build_window` (src/solver/roaming.rs).

Reads the assembly of a release build (scripts/long.sh makes it with
`cargo rustc --release -p mccs-host --bin mccs -- --emit asm`) and lists every function
that writes r11 before its probe loop (`mov r11, rsp`). A heuristic: the write may be on
another path than the loop's, so a hit is for a person to read. Exits 1 on any hit, and
when no function has a probe loop at all (the check would see nothing).

    scripts/check_stack_probes.py FILE.s
"""
import re
import sys


def suspects(path):
    """The functions that write r11 before their probe loop, and how many have one."""
    hits, probed, name, body = [], [], None, []

    def check():
        for i, line in enumerate(body):
            if re.search(r"\bmov\s+r11, rsp\b", line):
                probed.append(name)
                writes = [b.strip() for b in body[:i] if re.match(r"^\s*\w+\s+r11[dwb]?\b", b)]
                if writes:
                    hits.append((name, writes[:2]))
                return

    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            m = re.match(r"^(_\S+):\s*$", line)
            if m:
                if name:
                    check()
                name, body = m.group(1), []
            elif name and not re.match(r"^\s*(\.|#)", line):
                body.append(line.rstrip())
    if name:
        check()
    return hits, len(probed)


def main():
    if len(sys.argv) != 2:
        print("usage: " + __doc__.strip().splitlines()[-1].strip(), file=sys.stderr)
        return 2
    try:
        hits, probed = suspects(sys.argv[1])
    except OSError as e:
        print(f"check_stack_probes: {sys.argv[1]}: {e.strerror}", file=sys.stderr)
        return 2
    for name, writes in hits:
        print(f"STACKPROBE r11 written before the probe loop: {name} ({'; '.join(writes)})")
    # (No probe loop at all would make the check vacuous: that fails too.)
    fail = bool(hits) or probed == 0
    print(f"STACKPROBE probed={probed} functions={len(hits)} result={'fail' if fail else 'ok'}")
    return 1 if fail else 0


if __name__ == "__main__":
    sys.exit(main())
