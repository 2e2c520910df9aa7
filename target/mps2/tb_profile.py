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

Usage: tb_profile.py LOG ELF --particle-steps N [--skip FUNCTION] [--addr2line TOOL]
Prints instructions per particle-step by function and by source line of the
block start (the lines of the particle filter's loops)."""
import argparse
import collections
import re
import subprocess
import sys

IN_RE = re.compile(r"^IN:\s*(\S*)")
INSN_RE = re.compile(r"^0x([0-9a-f]+):")
TRACE_RE = re.compile(r"^Trace \d+: (0x[0-9a-f]+) \[[0-9a-f]+/([0-9a-f]+)/")


LONG_RE = re.compile(r"\b(vdiv|vsqrt)\.f32\b")


def parse(path):
    """Returns {(function, start pc): executed instructions}, unattributed
    count, and {(function, start pc): [executed vdiv.f32, executed vsqrt.f32]}."""
    blocks = {}  # host address -> (function, start pc, instruction count, divisions, square roots)
    longs = collections.defaultdict(lambda: [0, 0])
    pending = None  # the last translated block, waiting for its first execution
    counts = collections.Counter()
    unattributed = 0
    with open(path, errors="replace") as f:
        it = iter(f)
        for line in it:
            m = IN_RE.match(line)
            if m:
                fn, first, n, nd, ns = m.group(1) or "?", None, 0, 0, 0
                for l2 in it:
                    if not l2.strip():
                        break
                    mi = INSN_RE.match(l2)
                    if mi:
                        n += 1
                        if first is None:
                            first = int(mi.group(1), 16)
                        ml = LONG_RE.search(l2)
                        if ml:
                            nd += ml.group(1) == "vdiv"
                            ns += ml.group(1) == "vsqrt"
                pending = (fn, first, n, nd, ns)
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
                    continue
                counts[(b[0], b[1])] += b[2]
                if b[3] or b[4]:
                    longs[(b[0], b[1])][0] += b[3]
                    longs[(b[0], b[1])][1] += b[4]
    return counts, unattributed, longs


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("log")
    ap.add_argument("elf")
    ap.add_argument("--particle-steps", type=int, required=True)
    ap.add_argument("--periods", type=int, default=0, help="control periods of the run (for the per-period counts)")
    ap.add_argument("--addr2line", default="arm-none-eabi-addr2line")
    ap.add_argument("--top", type=int, default=12)
    ap.add_argument("--skip", action="append", default=[], help="leave out a function (e.g. the calibration loop)")
    a = ap.parse_args()
    if a.particle_steps < 1:
        sys.exit("tb_profile: --particle-steps must be >= 1")
    counts, unattributed, longs = parse(a.log)
    counts = collections.Counter({k: c for k, c in counts.items() if k[0] not in a.skip})
    n_div = sum(v[0] for k, v in longs.items() if k[0] not in a.skip)
    n_sqrt = sum(v[1] for k, v in longs.items() if k[0] not in a.skip)
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
    by_fn_div = collections.Counter()
    for (fn, _), v in longs.items():
        if fn not in a.skip:
            by_fn_div[fn] += v[0]
    print(f"    executed vdiv.f32 per particle-step {n_div / per:.3f}, vsqrt.f32 {n_sqrt / per:.3f}; by function: "
          + ", ".join(f"{fn} {c / per:.3f}" for fn, c in by_fn_div.most_common(4)))
    if a.periods > 0:
        print(f"long_ops per_particle_step_div={n_div / per:.4f} per_particle_step_sqrt={n_sqrt / per:.4f} "
              f"per_period_div={n_div / a.periods:.2f} per_period_sqrt={n_sqrt / a.periods:.2f}")


if __name__ == "__main__":
    main()
