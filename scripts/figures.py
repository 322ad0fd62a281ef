#!/usr/bin/env python3
"""The figures quoted in README.md and docs/**/*.md, held to what the code prints.

A figure in a doc is marked `<!-- fig:KEY -->VALUE<!-- /fig -->` (the markers do not
render). KEY names a value printed by the test command: every line of its logs of the
form `TAG k1=v1 k2=v2 …` (BENCH, MEM, FIT, SIZE, SUMMARY, SWEEP, PROPERTY, REPLAY,
TABLE, …) gives one figure per numeric field, keyed
`TAG.<the non-numeric values, in order>.<field>`, e.g. `BENCH.m4f.spring.instructions`
or `SWEEP.wide.max_error_rel`; a SUMMARY line of a demo log is keyed by its core
(`SUMMARY.m4f.steady_force_n`), a board's by its name (`SUMMARY.f405.fault_tick`).

  figures.py check    fail (exit 1) when a marked value differs from what was printed,
                      or when nothing printed its key; one line each
  figures.py update   rewrite the marked values from the logs
  figures.py list     print every figure the logs hold

A log excerpt in a doc is marked `<!-- excerpt:LOG -->` just above its fenced block:
each of the block's lines but those with `…` (elided) must be a line of
target/qemu/LOG as it was printed, in the same order (`check` and `update` both fail
otherwise: an excerpt is copied by hand, from the log).

The logs: target/qemu/*.txt and *.log (the firmware, the bench, the sizes) and
target/logs/test/host-tests.log (the host tests, run with --show-output).
"""
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
EXCERPT = re.compile(r"<!-- excerpt:([A-Za-z0-9_.\-]+) -->\n```[a-z]*\n(.*?)\n```", re.S)
MARK = re.compile(r"<!-- fig:([A-Za-z0-9_.\-]+) -->(.*?)<!-- /fig -->")
LINE = re.compile(r"^(?:INFO\s+)?([A-Z][A-Z_]+) ((?:\S+=\S+ ?)+)$")
NUMBER = re.compile(r"^-?[0-9][0-9.]*(e[-+]?[0-9]+)?(/100)?$")


def figures() -> dict:
    out = {}
    sources = sorted((ROOT / "target/qemu").glob("*.txt")) + sorted((ROOT / "target/qemu").glob("*.log"))
    # Not the logs of the tests that break a run on purpose (a breached budget, a
    # truncated bench): their figures are another build's.
    sources = [p for p in sources if p.name != "budget-test.log" and "-truncated" not in p.name]
    sources.append(ROOT / "target/logs/test/host-tests.log")
    for path in sources:
        if not path.exists():
            continue
        core = re.match(r"demo-([\w-]+)\.log", path.name)
        for raw in path.read_text(errors="replace").splitlines():
            m = LINE.match(raw.strip())
            if not m:
                continue
            tag, fields = m.group(1), [kv.split("=", 1) for kv in m.group(2).split()]
            ident = [v for k, v in fields if not NUMBER.match(v)]
            if tag == "SUMMARY":
                board = [v for k, v in fields if k == "board"]
                if core:
                    ident = [core.group(1)]
                elif board:
                    ident = board
                else:
                    continue
            for k, v in fields:
                if NUMBER.match(v):
                    out[".".join([tag] + ident + [k])] = v
    return out


# Instruction counts come from SysTick under -icount, calibrated and averaged: a count
# can move by one between runs of the same binary. Those figures match within one count
# or 0.2 %. A firmware's size depends on where it was built: the paths of the checkout
# and of CARGO_HOME end up in it (panic locations), so a fresh clone elsewhere measured
# 24 to 72 bytes more than the committed figures; sizes match within 0.5 %. Every other
# figure to the character.
JITTER = ("BENCH.", "FIT.", "BUDGET.", "RATIO.", "TICK.")
# A QEMU run's worst tick is SysTick's count too (a fresh clone's board firmware measured
# one more than the committed figure).
JITTER_FIELDS = (".worst_tick_instructions",)
PATH_DEPENDENT = ("SIZE.",)


def same(key: str, doc: str, printed: str) -> bool:
    if doc == printed:
        return True
    if not (key.startswith(JITTER + PATH_DEPENDENT) or key.endswith(JITTER_FIELDS)):
        return False
    try:
        a, b = float(doc), float(printed)
    except ValueError:
        return False
    if key.startswith(PATH_DEPENDENT):
        return abs(a - b) <= 0.005 * abs(b)
    return abs(a - b) <= max(1.0, 0.002 * abs(b))


def excerpts(doc: Path, text: str) -> int:
    """The excerpts of `doc` that its logs do not print: one line each; their count."""
    bad = 0
    for m in EXCERPT.finditer(text):
        log = ROOT / "target/qemu" / m.group(1)
        if not log.exists():
            print(f"{doc.relative_to(ROOT)}: excerpt of {m.group(1)}: no such log (run the test command)")
            bad += 1
            continue
        printed = [l.rstrip("\r") for l in log.read_text(errors="replace").splitlines()]
        at = 0
        for line in m.group(2).splitlines():
            if "…" in line or not line.strip():
                continue
            try:
                at = printed.index(line, at) + 1
            except ValueError:
                print(f"{doc.relative_to(ROOT)}: excerpt of {m.group(1)}: not printed there (in this order): {line}")
                bad += 1
    return bad


def docs():
    return [ROOT / "README.md"] + sorted((ROOT / "docs").rglob("*.md"))


def main() -> int:
    mode = sys.argv[1] if len(sys.argv) > 1 else "check"
    if mode not in ("check", "update", "list") or len(sys.argv) > 2:
        print("usage: scripts/figures.py [check|update|list]", file=sys.stderr)
        return 2
    figs = figures()
    if mode == "list":
        for k in sorted(figs):
            print(f"{k} = {figs[k]}")
        return 0
    bad = 0
    marks = 0
    stale = 0
    for doc in docs():
        text = doc.read_text()
        def repl(m):
            nonlocal bad, marks
            marks += 1
            key, value = m.group(1), m.group(2)
            if key not in figs:
                print(f"{doc.relative_to(ROOT)}: {key}: nothing printed this figure")
                bad += 1
                return m.group(0)
            if mode == "check" and not same(key, value, figs[key]):
                print(f"{doc.relative_to(ROOT)}: {key}: the doc says {value}, the code prints {figs[key]} (scripts/figures.py update)")
                bad += 1
            return f"<!-- fig:{key} -->{figs[key]}<!-- /fig -->"
        new = MARK.sub(repl, text)
        stale += excerpts(doc, text)
        if mode == "update" and new != text:
            doc.write_text(new)
            print(f"updated {doc.relative_to(ROOT)}")
    print(f"figures: {marks} quoted, {marks - bad} as printed, {bad} not; {stale} excerpt lines not printed")
    return 1 if bad or stale else 0


if __name__ == "__main__":
    sys.exit(main())
