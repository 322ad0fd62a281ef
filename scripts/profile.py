#!/usr/bin/env python3
"""Where a firmware's instructions go, per function, from QEMU's own execution log.

    scripts/profile.py m4f|m3|m0 [bin] [--top N] [--lines] [--mix PATTERN]

Builds the release firmware `bin` (default `haptic`) for the core, runs it in QEMU with
the runner's `-icount` and `-d in_asm,exec,nochain` (every translated block once, every
executed block each time), and prints the instructions executed per function, most
first, with each one's share of the whole run; with `--lines`, per source line instead
(the innermost inlined frame of each instruction, by `llvm-symbolizer`: what the code
inlined into one function does). The counts are QEMU's translated
instructions, the same measure as the bench's (no cycles). A long run logs a line per
executed block: the log is read through a pipe, never stored (the haptic demo's 4000
ticks take about a minute on this machine).

With `--mix PATTERN`, the instructions executed in the functions whose name contains
PATTERN instead, per mnemonic and per call (the calls are the runs of the function's
first executed block, its entry; the run stops once 256 calls have returned): `scripts/profile.py m0 bench --mix entry::spring` is where the M0's one
spring goes (docs/performance.md, "Where a spring's instructions go (M0)").
"""
import collections
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading

TARGETS = {"m4f": "thumbv7em-none-eabihf", "m3": "thumbv7m-none-eabi", "m0": "thumbv6m-none-eabi"}
MACHINES = {
    "m4f": ["-machine", "netduinoplus2", "-icount", "shift=3,sleep=off"],
    "m3": ["-machine", "lm3s6965evb", "-icount", "shift=5,sleep=off"],
    "m0": ["-machine", "microbit", "-icount", "shift=5,sleep=off"],
}


USAGE = "usage: scripts/profile.py m4f|m3|m0 [bin] [--top N] [--lines] [--mix PATTERN]"


def usage(why):
    print(f"{USAGE} ({why})", file=sys.stderr)
    sys.exit(2)


def option_value(name):
    """The value after option `name`, or None when it is absent."""
    if name not in sys.argv:
        return None
    i = sys.argv.index(name)
    if i + 1 >= len(sys.argv) or sys.argv[i + 1].startswith("--"):
        usage(f"{name} needs a value")
    return sys.argv[i + 1]


def main():
    known = {"--top", "--lines", "--mix"}
    for a in sys.argv[1:]:
        if a.startswith("--") and a not in known:
            usage(f"unknown option {a}")
    top_arg, mix = option_value("--top"), option_value("--mix")
    top = 40
    if top_arg is not None:
        if not top_arg.isdigit() or int(top_arg) == 0:
            usage(f"--top must be a positive integer, not '{top_arg}'")
        top = int(top_arg)
    by_line = "--lines" in sys.argv
    values = {sys.argv.index(o) + 1 for o in ("--top", "--mix") if o in sys.argv}
    args = [a for i, a in enumerate(sys.argv) if i > 0 and i not in values and not a.startswith("--")]
    if not args or args[0] not in TARGETS:
        usage("the core first")
    if len(args) > 2:
        usage(f"one bin at most, not {args[1:]}")
    core, binary = args[0], (args[1] if len(args) > 1 else "haptic")
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    target = TARGETS[core]
    print(f"profile: building {binary} for {core}", file=sys.stderr)
    subprocess.run(["cargo", "build", "--quiet", "--release", "-p", "mccs-firmware",
                    "--target", target, "--bin", binary], cwd=root, check=True)
    elf = os.path.join(root, "target", target, "release", binary)
    with tempfile.TemporaryDirectory() as d:
        fifo = os.path.join(d, "qemu.log")
        os.mkfifo(fifo)
        cmd = ["qemu-system-arm", *MACHINES[core], "-display", "none", "-serial", "null",
               "-monitor", "none", "-semihosting-config", "enable=on,target=native",
               "-d", "in_asm,exec,nochain", "-D", fifo, "-kernel", elf]
        print(f"profile: running it in QEMU, every executed block logged (a minute or so)",
              file=sys.stderr)
        qemu = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
        sizes, names, addrs, runs = {}, {}, {}, collections.Counter()
        mnemonics, seen, entry = {}, {}, None
        trace = re.compile(r"^Trace \d+: 0x[0-9a-f]+ \[[0-9a-f]+/([0-9a-f]+)/")
        with open(fifo) as log:
            block, count, name = None, 0, "?"
            for line in log:
                if line.startswith("Trace"):
                    m = trace.match(line)
                    if m:
                        pc = int(m.group(1), 16)
                        runs[pc] += 1
                        # With --mix: the function's first executed block is its
                        # entry; once 256 calls have run (the bench measures each case
                        # over 256) and the last has returned, the rest of the run is
                        # not needed.
                        if mix is not None and pc not in seen:
                            seen[pc] = pattern_in(mix, names.get(pc, ""))
                            if seen[pc] and entry is None:
                                entry = pc
                        if entry is not None and runs[entry] >= 256 and not seen[pc]:
                            qemu.kill()
                            break
                elif line.startswith("IN:"):
                    name = line[3:].strip() or "?"
                    block, count = None, 0
                elif line.startswith("0x"):
                    pc = int(line.split(":")[0], 16)
                    if block is None:
                        block, addrs[pc] = pc, []
                    addrs[block].append(pc)
                    mnemonics[pc] = mnemonic(line)
                    count += 1
                    sizes[block], names[block] = count, name
        qemu.wait()
    if mix is not None:
        print_mix(core, binary, mix, names, addrs, runs, mnemonics, entry)
        return
    per = collections.Counter()
    if by_line:
        each = collections.Counter()
        for pc, n in runs.items():
            for a in addrs.get(pc, []):
                each[a] += n
        where = symbolize(elf, sorted(each))
        for a, n in each.items():
            per[where.get(a, f"0x{a:08x}")] += n
    else:
        for pc, n in runs.items():
            per[names.get(pc, f"0x{pc:08x}")] += n * sizes.get(pc, 0)
    total = sum(per.values())
    print(f"PROFILE core={core} bin={binary} instructions={total}")
    for name, n in per.most_common(top):
        print(f"{n:>12} {100.0 * n / max(total, 1):6.2f} %  {demangle(name)}")


def mnemonic(line):
    """The mnemonic of one line of QEMU's `in_asm` log (`0x…:  <encoding>  <mnemonic> …`),
    without the condition or width suffix (`ldr.w` is `ldr`)."""
    words = line.split(":", 1)[1].split()
    words = [w for w in words if not re.fullmatch(r"[0-9a-f]{4}|[0-9a-f]{8}", w)]
    return words[0].split(".")[0] if words else "?"


def pattern_in(pattern, name):
    """Whether a block's function name contains `pattern` (demangled)."""
    return pattern in demangle(name)


def print_mix(core, binary, pattern, names, addrs, runs, mnemonics, entry):
    """The instructions executed in the functions named like `pattern`, per mnemonic and
    per call, most first."""
    blocks = [pc for pc in runs if pattern_in(pattern, names.get(pc, ""))]
    if not blocks:
        sys.exit(f"profile: no executed function matches {pattern!r}")
    calls = runs[entry]
    each = collections.Counter()
    for pc in blocks:
        for a in addrs.get(pc, []):
            each[mnemonics.get(a, "?")] += runs[pc]
    total = sum(each.values())
    function = demangle(names[entry])
    print(f"MIX core={core} bin={binary} function={function} calls={calls} "
          f"instructions_per_call={total / calls:.1f}")
    for m, n in each.most_common():
        print(f"{n / calls:>8.1f}  {m}")


def symbolize(elf, addresses):
    """`file:line` of each address's innermost inlined frame (paths from `src/`)."""
    if shutil.which("llvm-symbolizer") is None:
        sys.exit("profile: --lines needs llvm-symbolizer (Debian: apt-get install llvm)")
    out = subprocess.run(["llvm-symbolizer", "--obj", elf, "--inlining", "--no-demangle",
                          "--output-style=JSON"],
                         input="".join(f"0x{a:x}\n" for a in addresses), text=True,
                         capture_output=True, check=True).stdout
    where = {}
    for a, line in zip(addresses, out.splitlines()):
        frames = json.loads(line).get("Symbol", [])
        if frames:
            f = frames[0]
            path = f.get("FileName", "?")
            # The crate's folder and the path in it: core/src/…, main/src/… (this repo).
            i = path.rfind("/src/")
            path = path[path.rfind("/", 0, i) + 1:] if i > 0 else os.path.basename(path)
            where[a] = f"{path}:{f.get('Line', 0)}"
    return where


def demangle(name):
    """The Rust path of a legacy-mangled symbol, without its hash."""
    m = re.match(r"_ZN(.*)17h[0-9a-f]{16}E$", name)
    if not m:
        return name
    out, s = [], m.group(1)
    while s and s[0].isdigit():
        n = int(re.match(r"\d+", s).group(0))
        s = s[len(str(n)):]
        out.append(s[:n])
        s = s[n:]
    return "::".join(out).replace("$LT$", "<").replace("$GT$", ">").replace("$u20$", " ") \
        .replace("$C$", ",").replace("..", "::").replace("$RF$", "&").replace("_$", "$")


if __name__ == "__main__":
    main()
