#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Where the instructions go: a profile of the replay image from QEMU's
translation-block log (make target-bench, docs/target.md).

QEMU run with `-d in_asm,exec,nochain -D LOG` writes every translated block
(`IN:` and its guest instructions) and, with chaining off, one `Trace` line
per block execution. Instructions executed = sum over executions of the
block's instruction count. Blocks are keyed by their host address, which
QEMU reuses only after a translation-cache flush (none in these short runs;
a block whose translation was not seen is counted as unattributed).
Two corrections make the count that of the executed instructions (QEMU 7.2's
messages under -d exec): "Stopped execution of TB chain before" a block that
was logged but not started (the instruction budget of -icount ran out at its
start: about every 65 000 instructions) takes that execution back, and
"cpu_io_recompile: rewound execution of TB to PC" (a device read, such as
SysTick's, in the middle of a block: the block is cut there and its rest runs
as new blocks) takes back the block's instructions from PC on.

Usage: tb_profile.py LOG ELF --particle-steps N [--base LOG0] [--long-ops-only]
                     [--skip FUNCTION] [--addr2line TOOL]
Prints instructions per particle-step by function and by source line of the
block start (the lines of the particle filter's loops), and the executed
vdiv.f32 / vsqrt.f32 that the cycle estimate charges. With --base, a log of
the same stream's priming period alone (k = 0, same m): its long
instructions are subtracted from this log's, so that they are those of the
periods k >= 1, which --particle-steps counts; the machine-readable line
`long_ops div=D sqrt=S` gives those two counts. --long-ops-only prints that
line only (no instruction profile)."""
import argparse
import collections
import re
import subprocess
import sys

IN_RE = re.compile(r"^IN:\s*(\S*)")
INSN_RE = re.compile(r"^0x([0-9a-f]+):")
TRACE_RE = re.compile(r"^Trace \d+: (0x[0-9a-f]+) \[[0-9a-f]+/([0-9a-f]+)/")


LONG_RE = re.compile(r"\b(vdiv|vsqrt)\.f32\b")
STOP_RE = re.compile(r"^Stopped execution of TB chain before (0x[0-9a-f]+) \[([0-9a-f]+)\]")
REWIND_RE = re.compile(r"^cpu_io_recompile: rewound execution of TB to ([0-9a-f]+)")


def parse(path):
    """Returns {(function, start pc): executed instructions}, unattributed
    count, and {(function, start pc): [executed vdiv.f32, executed vsqrt.f32]}."""
    # host address -> (function, start pc, [(pc, is vdiv, is vsqrt) per instruction])
    blocks = {}
    longs = collections.defaultdict(lambda: [0, 0])
    pending = None  # the last translated block, waiting for its first execution
    counts = collections.Counter()
    unattributed = 0
    last = None  # the block of the last counted execution

    def add(b, insns, sign):
        key = (b[0], b[1])
        counts[key] += sign * len(insns)
        nd = sum(i[1] for i in insns)
        ns = sum(i[2] for i in insns)
        if nd or ns:
            longs[key][0] += sign * nd
            longs[key][1] += sign * ns

    with open(path, errors="replace") as f:
        it = iter(f)
        for line in it:
            m = IN_RE.match(line)
            if m:
                fn, insns = m.group(1) or "?", []
                for l2 in it:
                    if not l2.strip():
                        break
                    mi = INSN_RE.match(l2)
                    if mi:
                        ml = LONG_RE.search(l2)
                        kind = ml.group(1) if ml else ""
                        insns.append((int(mi.group(1), 16), kind == "vdiv", kind == "vsqrt"))
                pending = (fn, insns[0][0] if insns else None, insns)
                continue
            m = TRACE_RE.match(line)
            if m:
                host, pc = m.group(1), int(m.group(2), 16)
                if pending is not None and pending[1] == pc:
                    blocks[host] = pending
                    pending = None
                b = blocks.get(host)
                if b is None or b[1] != pc:
                    unattributed += 1
                    last = None
                    continue
                add(b, b[2], 1)
                last = b
                continue
            m = STOP_RE.match(line)
            if m:
                b = blocks.get(m.group(1))
                if b is not None and b is last and b[1] == int(m.group(2), 16):
                    add(b, b[2], -1)  # logged, not started
                last = None
                continue
            m = REWIND_RE.match(line)
            if m and last is not None:
                pc = int(m.group(1), 16)
                add(last, [i for i in last[2] if i[0] >= pc], -1)  # cut at the device read
                last = None
    return counts, unattributed, longs


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("log")
    ap.add_argument("elf")
    ap.add_argument("--particle-steps", type=int, required=True)
    ap.add_argument("--base", help="log of the priming period alone: long instructions counted from k = 1")
    ap.add_argument("--long-ops-only", action="store_true", help="print the long_ops line only")
    ap.add_argument("--addr2line", default="arm-none-eabi-addr2line")
    ap.add_argument("--top", type=int, default=12)
    ap.add_argument("--skip", action="append", default=[], help="leave out a function (e.g. the calibration loop)")
    a = ap.parse_args()
    if a.particle_steps < 1:
        sys.exit("tb_profile: --particle-steps must be >= 1")
    counts, unattributed, longs = parse(a.log)
    # the long instructions by function, less the priming-only run's
    by_fn_long = collections.defaultdict(lambda: [0, 0])
    for (fn, _), v in longs.items():
        by_fn_long[fn][0] += v[0]
        by_fn_long[fn][1] += v[1]
    if a.base:
        for (fn, _), v in parse(a.base)[2].items():
            by_fn_long[fn][0] -= v[0]
            by_fn_long[fn][1] -= v[1]
    by_fn_long = {fn: v for fn, v in by_fn_long.items() if fn not in a.skip}
    n_div = sum(v[0] for v in by_fn_long.values())
    n_sqrt = sum(v[1] for v in by_fn_long.values())
    machine_line = f"long_ops div={n_div} sqrt={n_sqrt}"
    if a.long_ops_only:
        print(machine_line)
        return
    counts = collections.Counter({k: c for k, c in counts.items() if k[0] not in a.skip})
    total = sum(counts.values())
    if total == 0:
        sys.exit(f"tb_profile: no executed blocks in {a.log}")
    per = float(a.particle_steps)
    by_fn = collections.Counter()
    for (fn, _), c in counts.items():
        by_fn[fn] += c
    print(f"  profile ({total} instructions, {unattributed} block executions unattributed), "
          f"per particle-step = instructions / {a.particle_steps}:")
    for fn, c in by_fn.most_common(a.top):
        if c / per >= 0.1:
            print(f"    {fn:28s} {c / per:7.1f}")
    # source lines of the hottest blocks
    hot = sorted(counts.items(), key=lambda kv: -kv[1])[: a.top]
    pcs = [f"{pc:#x}" for (_, pc), _ in hot]
    out = subprocess.run([a.addr2line, "-e", a.elf, *pcs], check=True, capture_output=True, text=True)
    lines = out.stdout.splitlines()
    print("    hottest blocks (start address, source line of the block start):")
    for ((fn, pc), c), src in zip(hot, lines):
        src = re.sub(r".*/(firmware|hal|sim|tests)/", r"\1/", src)
        print(f"      {pc:#07x} {fn:20s} {c / per:7.1f}  {src}")
    # the long-latency FPU instructions the cycle estimate charges (docs/target.md)
    by_fn_div = collections.Counter({fn: v[0] for fn, v in by_fn_long.items() if v[0]})
    span = "periods k >= 1: this run less its priming period; the fixed part included" if a.base else "the whole run"
    print(f"    executed vdiv.f32 per particle-step {n_div / per:.3f}, vsqrt.f32 {n_sqrt / per:.3f} ({span}); "
          "by function: " + ", ".join(f"{fn} {c / per:.3f}" for fn, c in by_fn_div.most_common(4)))
    print(machine_line)


if __name__ == "__main__":
    main()
