# SPDX-License-Identifier: Apache-2.0
"""Detection limits of the diagnosis (docs/detection-limits.md, `make
detection-limits`).

For each cause with a generator (GENERATORS, from each registry cause's
DETECTION: br_simlog's option for an effect of size s), at two force-noise levels (the EMPS log's, as the noise
floor measures it from ../shared/data/emps/emps_estimation.csv, and a quiet
log's, QUIET_N): the smallest size of the cause's ladder (geometric, ratio
sqrt 2) detected in at least 95 % of N logs. Each log is made by br_simlog
(seeds fixed: the same logs on every run) and diagnosed from the log alone
(selection.diagnose); the cause is detected when it is among the findings.

The limit is found by bisection on the ladder, assuming the detection rate
grows with the size: a probed size passes when at most N - ceil(0.95 N) of its
N logs miss the cause (N = 20: 19 of 20), and its logs stop at the first miss
more than that (the size fails). The limit lies between the largest failing
probe below it and itself. Beside each limit: N, the count detected and the
one-sided 95 % Clopper-Pearson lower bound of the detection rate (with N of N
detected it is 0.05^(1/N): 86 % for N = 20; a "95 %" limit is the observed
rate, not a guaranteed one).

Then the limit is proven (--n-verify M, default 59): M logs at the limit (its
first N are the bisection's), all of which must detect the cause; on a miss
the next size up the ladder is tried the same way. M of M detected gives a
one-sided 95 % Clopper-Pearson lower bound of 0.05^(1/M): 95.05 % for M = 59,
so the proven limit is a size whose detection rate is at least 95 % at 95 %
confidence (still under the assumption that the rate grows with the size).

On N_NOMINAL nominal logs per noise level: the false-positive rate (any
finding) and the rate of the verdict "unexplained", each with its one-sided
95 % Clopper-Pearson upper bound (0 of 100: 3.0 %; 0 of 150: 2.0 %).

--jobs 1 runs everything in this process; --jobs K spreads the (cause, noise)
bisections and the nominal logs over K processes. Each log's result is appended
to WORK/cache.jsonl, keyed with a digest of the diagnosis's sources and of
br_simlog: an interrupted run started again with the same --work skips the
logs it already has, never a result of other code (--fresh forgets them all);
the wall time reported
is the last run's.

Usage: detection_limits.py --simlog BIN --work DIR [--n N] [--n-verify M] [--n-nominal N] [--jobs K]
                           [--md OUT.md] [--png OUT.png] [--json OUT.json]
"""
import argparse
import hashlib
import json
import math
import multiprocessing as mp
import os
import resource
import subprocess
import sys
import time

import numpy as np
from scipy import stats

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "python"))
from bristle.diagnose import causes, logreader, noise, physical, report, selection, signals  # noqa: E402

EMPS_LOG = os.path.join(REPO, "..", "shared", "data", "emps", "emps_estimation.csv")
QUIET_N = 0.02
RATE = 0.95
CONF = 0.95
MASTER_SEED = 20261123
FC_N, SIGMA2 = 7.0, 50.0   # the reference machine's Coulomb and viscous levels (machines/reference.json)
LADDER_LEN = 15            # bisection: 4 probes pin the limit to one step of the ladder


def ladder(lo):
    """LADDER_LEN sizes from lo, ratio sqrt 2 (lo .. 128 lo)."""
    return lo * np.sqrt(2.0) ** np.arange(LADDER_LEN)


# cause: (size name, unit, ladder, flags(size)); sizes of the effect, from each
# registry cause's DETECTION (python/bristle/diagnose/causes/)
def lugre_presliding_scale_m():
    """LuGre's presliding displacement Fs / sigma0 on the reference machine (machines/reference.json)."""
    with open(os.path.join(REPO, "machines", "reference.json")) as f:
        fr = json.load(f)["friction"]
    return fr["Fs_N"] / fr["sigma0_Npm"]


def lugre_presliding_zeta():
    """The damping ratio of LuGre's presliding mode on the reference machine (machines/reference.json):
    the bristle's stiffness sigma0 and damping sigma1 on the moving mass at the load, M + J / L^2
    (L = lead / 2 pi): the diagnosis's damping ratio (physical.py, eq. P1)."""
    with open(os.path.join(REPO, "machines", "reference.json")) as f:
        m = json.load(f)
    mech, fr = m["mechanics"], m["friction"]
    lead = mech["lead_m_per_rev"] / (2.0 * math.pi)
    meff = mech["table_mass_kg"] + mech["inertia_kgm2"] / lead ** 2
    return physical.damping_ratio({"sigma0_Npm": fr["sigma0_Npm"], "sigma1_Nspm": fr["sigma1_Nspm"],
                                   "Meff_kg": meff})


REF_LEVELS = {"Fc_N": FC_N, "sigma2_Nspm": SIGMA2, "presliding_scale_m": lugre_presliding_scale_m(),
              "presliding_zeta": lugre_presliding_zeta()}


def _generator(det):
    what, unit, lo, flags = det
    return what, unit, ladder(lo), lambda s: flags(s, REF_LEVELS)


GENERATORS = {m.NAME: _generator(m.DETECTION) for m in causes.REGISTRY if hasattr(m, "DETECTION")}

# the logs a cause's sizes and its nominal logs are made of: br_simlog's identification run, or with
# its reversal segment (--reversals 1, docs/simlog.md), the log docs/diagnose.md asks for presliding
LOGS = {"ident": [], "ident with the reversal segment": ["--reversals", "1"]}
CAUSE_LOGS = {m.NAME: m.DETECTION_LOG for m in causes.REGISTRY if hasattr(m, "DETECTION_LOG")}
# causes with their own block of the page (their own logs): a run of them alone rewrites only their block
BLOCKS = ("presliding_hysteresis",)
# the Maxwell-slip plant's element set relative to its largest breakaway (the cause's own)
PS_NAME = "presliding_hysteresis"
GMS_SHAPE = causes.get(PS_NAME).DETECTION_SHAPE


def logs_of(cause):
    return CAUSE_LOGS.get(cause, "ident")


def gms_elements(ratio):
    """br_simlog's --gms for an element set whose largest breakaway is ratio times LuGre's Fs/sigma0."""
    return GENERATORS["presliding_hysteresis"][3](ratio)[1]


def emps_noise():
    if not os.path.isfile(EMPS_LOG):
        raise SystemExit(f"error: {EMPS_LOG} is missing (docs/diagnose.md says where the EMPS log comes from)")
    return noise.measure(signals.Prepared(logreader.read_log(EMPS_LOG))).sigma_N


def _cache_path(work):
    return os.path.join(work, "cache.jsonl")


def load_cache(work):
    """Logs already diagnosed by an earlier run into the same --work directory (the seeds are fixed, so a
    log's key names the same log): key -> (verdict, findings)."""
    out = {}
    try:
        with open(_cache_path(work)) as f:
            for line in f:
                try:
                    d = json.loads(line)
                except json.JSONDecodeError:
                    continue   # a line cut by an interrupted run
                out[d["key"]] = (d["verdict"], d["findings"])
                SECONDS[d["key"]] = d.get("s", 0.0)
                if "ps_m" in d:
                    PS_M[d["key"]] = d["ps_m"]
    except FileNotFoundError:
        pass
    return out


CACHE = {}
USED = set()
SECONDS = {}   # key -> wall seconds of that log (br_simlog + diagnosis), this run's or the cached run's
PS_M = {}      # key -> presliding_m of the log's finding of presliding_hysteresis
LAST_PS_M = [None]   # run()'s last log's PS_M (None: no such finding), for probe()


def code_digest():
    """A digest of what decides a log's result: the diagnosis's Python sources
    and br_simlog's binary. A cached result of other code is never reused."""
    h = hashlib.sha256()
    root = os.path.join(REPO, "python", "bristle", "diagnose")
    for d, _, files in sorted(os.walk(root)):
        for f in sorted(files):
            if f.endswith(".py"):
                with open(os.path.join(d, f), "rb") as fh:
                    h.update(f.encode() + b"\0" + fh.read())
    return h.hexdigest()[:16]


DIGEST = {}


def run_digest(simlog):
    """The digest a log's cache key ends with: the diagnosis's code and br_simlog's binary."""
    with open(simlog, "rb") as fh:
        return code_digest() + hashlib.sha256(fh.read()).hexdigest()[:16]


def run(simlog, work, key, flags, sigma, seed):
    """One log: br_simlog, then the diagnosis. Returns (verdict, findings)."""
    if simlog not in DIGEST:
        DIGEST[simlog] = run_digest(simlog)
    ck = f"{key}|{' '.join(flags)}|{sigma:.6g}|{seed}|{DIGEST[simlog]}"
    USED.add(ck)
    if ck in CACHE:
        LAST_PS_M[0] = PS_M.get(ck)
        return CACHE[ck]
    t0 = time.time()
    path = os.path.join(work, f"{key}.csv")
    subprocess.run([simlog, "--out", path, "--seed", str(seed), "--force-noise", f"{sigma:.6g}"] + flags,
                   check=True)
    prep = signals.Prepared(logreader.read_log(path))
    diag = selection.diagnose(prep)
    verdict, _ = report.verdict(prep, diag, noise.measure(prep, diag.nominal))
    os.remove(path)
    found = [c.cause for c, _ in diag.findings]
    line = {"key": ck, "verdict": verdict, "findings": found}
    # what a finding of presliding_hysteresis measured (presliding_table: its presliding_m against the plant's)
    line.update({"ps_m": c.fit.cause_params(c.cause)["presliding_m"] for c, _ in diag.findings if c.cause == PS_NAME})
    LAST_PS_M[0] = PS_M[ck] = line.get("ps_m")
    with open(_cache_path(work), "a") as f:
        SECONDS[ck] = round(time.time() - t0, 3)
        f.write(json.dumps({**line, "s": SECONDS[ck]}) + "\n")
    CACHE[ck] = (verdict, found)   # the verification reuses the bisection's logs in this process
    return verdict, found


def hash_seed(*k):
    return 1 + int(np.random.default_rng([MASTER_SEED, *k]).integers(1, 2 ** 30))


def cp_lower(k, n, conf=CONF):
    """One-sided Clopper-Pearson lower bound of a rate with k of n."""
    return 0.0 if k == 0 else float(stats.beta.ppf(1.0 - conf, k, n - k + 1))


def cp_upper(k, n, conf=CONF):
    """One-sided Clopper-Pearson upper bound of a rate with k of n."""
    return 1.0 if k == n else float(stats.beta.ppf(conf, k + 1, n - k))


def misses_allowed(n):
    return n - math.ceil(RATE * n - 1e-9)


def probe(simlog, work, li, lname, sigma, ci, cause, si, size, flags, n, allowed=None):
    """Up to n logs of cause at size; stops once the misses exceed `allowed`
    (default: what RATE allows of n)."""
    if allowed is None:
        allowed = misses_allowed(n)
    k = m = 0
    others = 0
    ps_m = []
    for j in range(n):
        LAST_PS_M[0] = None
        _, found = run(simlog, work, f"{lname}-{cause}-{si}-{j}", LOGS[logs_of(cause)] + flags(size), sigma,
                       hash_seed(li, ci + 1, si, j))
        if cause in found:
            k += 1
            if LAST_PS_M[0] is not None:
                ps_m.append(LAST_PS_M[0])
        else:
            m += 1
        others += any(c != cause for c in found)
        if m > allowed:
            break
    out = {"size": float(size), "detected": k, "logs": k + m, "other_findings": others, "passed": m <= allowed}
    if ps_m:
        out["ps_m"] = ps_m   # the detections' presliding_m (presliding_table)
    return out


def bisect_task(args):
    """The bisection of one (noise level, cause) on its ladder."""
    simlog, work, li, lname, sigma, ci, cause, n, n_verify = args
    _, _, lad, flags = GENERATORS[cause]
    lo, hi = -1, len(lad)          # lad[lo] fails (or below the ladder), lad[hi] passes (or above)
    probes = []
    while hi - lo > 1:
        mid = (lo + hi) // 2
        p = probe(simlog, work, li, lname, sigma, ci, cause, mid, lad[mid], flags, n)
        probes.append(p)
        if p["passed"]:
            hi = mid
        else:
            lo = mid
    # the proof: n_verify logs, no miss, from the limit up the ladder
    verify, v = [], hi
    while n_verify > 0 and v < len(lad):
        p = probe(simlog, work, li, lname, sigma, ci, cause, v, lad[v], flags, n_verify, allowed=0)
        verify.append(p)
        if p["passed"]:
            break
        v += 1
    proven = n_verify > 0 and v < len(lad)
    return ("cause", lname, cause, {"probes": sorted(probes, key=lambda p: p["size"]),
                                    "limit_index": hi if hi < len(lad) else None,
                                    "limit": float(lad[hi]) if hi < len(lad) else None,
                                    "verify": verify,
                                    "proven_index": v if proven else None,
                                    "proven": float(lad[v]) if proven else None,
                                    "ladder": [float(x) for x in lad]})


def nominal_task(args):
    simlog, work, li, lname, sigma, kind, j0, j1 = args
    # the identification logs keep their first keys and seeds; another kind of log has its own
    ki = list(LOGS).index(kind)
    tag = "" if ki == 0 else f"{ki}-"
    out = []
    for j in range(j0, j1):
        out.append(run(simlog, work, f"{lname}-none-{tag}{j}", LOGS[kind], sigma, hash_seed(li, 0, ki, j)))
    return ("nominal", lname, (kind, j0, j1), out)


def study(simlog, work, levels, n, n_nominal, jobs, causes, n_verify):
    todo = []
    for li, (lname, sigma) in enumerate(levels):
        for ci, cause in enumerate(GENERATORS):
            if cause in causes:
                todo.append((bisect_task, (simlog, work, li, lname, sigma, ci, cause, n, n_verify)))
    step = 10
    kinds = [k for k in LOGS if any(logs_of(c) == k for c in causes)]
    for j0 in range(0, n_nominal, step):
        for li, (lname, sigma) in enumerate(levels):
            for kind in kinds:
                todo.append((nominal_task, (simlog, work, li, lname, sigma, kind, j0, min(j0 + step, n_nominal))))
    res = {"cause": {}, "nominal": {}}

    def take(r_used):
        r, used = r_used
        USED.update(used)
        SECONDS.update(used)
        kind, lname, key, val = r
        if kind == "cause":
            res["cause"][(lname, key)] = val
            lim = val["limit"]
            print(f"  {lname} {key}: limit {lim if lim is not None else 'not within the ladder'} ("
                  + ", ".join(f"{p['size']:.3g}: {p['detected']}/{p['logs']}" for p in val["probes"]) + "); proven "
                  + f"{val['proven']} ("
                  + ", ".join(f"{p['size']:.3g}: {p['detected']}/{p['logs']}" for p in val["verify"]) + ")",
                  flush=True)
        else:
            res["nominal"].setdefault(lname, {})[key] = val
            print(f"  {lname} nominal logs ({key[0]}) {key[1]}..{key[2] - 1}: "
                  f"{sum(bool(f) for _, f in val)} with a finding", flush=True)

    if jobs <= 1:
        for fn, a in todo:
            take(_call((fn, a)))
    else:
        with mp.Pool(jobs) as pool:
            for r in pool.imap_unordered(_call, todo, chunksize=1):
                take(r)
    return res


def _call(t):
    """A task's result and the wall seconds of the logs it used: a pool worker's USED and SECONDS are
    its own, so they travel back with the result."""
    fn, a = t
    before = set(USED)
    r = fn(a)
    return r, {k: SECONDS.get(k, 0.0) for k in USED - before}


def nominal_stats(nom):
    """False positives (any finding, and per cause) and the verdict unexplained of nominal logs'
    (verdict, findings), with their one-sided upper bounds."""
    fp = sum(bool(f) for _, f in nom)
    un = sum(v == "unexplained" for v, _ in nom)
    found = {}
    for _, f in nom:
        for c in f:
            found[c] = found.get(c, 0) + 1
    return {"nominal_logs": len(nom), "false_positives": fp, "false_positive_upper": cp_upper(fp, len(nom)),
            "false_positive_causes": found, "unexplained": un, "unexplained_upper": cp_upper(un, len(nom))}


def summarize(res, levels, n, n_nominal, causes, n_verify):
    s = {"levels": {}, "n": n, "n_nominal": n_nominal, "n_verify": n_verify, "rate": RATE, "conf": CONF}
    for lname, sigma in levels:
        lv = {"force_noise_N": sigma, "nominal": {}, "causes": {}}
        for kind in LOGS:
            nom = [v for k, vals in sorted(res["nominal"].get(lname, {}).items()) if k[0] == kind for v in vals]
            if nom:
                lv["nominal"][kind] = nominal_stats(nom)
        for cause in GENERATORS:
            if cause not in causes:
                continue
            c = res["cause"][(lname, cause)]
            at = next((p for p in c["probes"] if c["limit"] is not None and p["size"] == c["limit"]), None)
            below = [p for p in c["probes"] if not p["passed"] and (c["limit"] is None or p["size"] < c["limit"])]
            c["at_limit"] = at
            c["at_limit_lower"] = cp_lower(at["detected"], at["logs"]) if at else None
            c["failed_below"] = below[-1] if below else None
            pv = c["verify"][-1] if c.get("proven") is not None else None
            c["proven_lower"] = cp_lower(pv["detected"], pv["logs"]) if pv else None
            lv["causes"][cause] = c
        s["levels"][lname] = lv
    return s


def _fmt(x, unit):
    return f"{x:.3g} {unit}".rstrip()


BANNER = "<!-- generated by sim/studies/detection_limits.py; do not edit -->"
# a block's first and last lines in the page
BLOCK_BEGIN = "<!-- block {}: generated by sim/studies/detection_limits.py --causes {}; do not edit -->"
BLOCK_END = "<!-- end block {} -->"
# what a block's logs and size are, and why that size (docs/detection-limits.md)
BLOCK_TEXT = {"presliding_hysteresis": (
    "br_simlog identification logs of the reference machine (3 cycles) with the reversal segment "
    "(`--reversals 1`, docs/simlog.md), the log docs/diagnose.md asks a user to record for this cause, "
    "whose plant's friction is a Maxwell-slip element set instead of LuGre (`--gms`: four equal elements "
    "breaking away at 0.1, 0.25, 0.5 and 1 times d_max, the demo's hardware-like shape and slip law). "
    "The size is d_max over LuGre's presliding displacement Fs/sigma0 ({scale_um:.3g} um on "
    "machines/reference.json): "
    "at a fixed shape it sets the travel over which the element set's piecewise-linear, multi-scale swing "
    "differs from the single bristle, whose stiffness the nominal fit chooses (sigma0 is fitted, so a "
    "length alone is no difference: the shape is). Each element's damping gives its mode on the moving "
    "mass the damping ratio of LuGre's bristle mode on the reference machine (`--gms-zeta {zeta:.3g}`: "
    "sigma1 / (2 sqrt(sigma0 M)), sigma1_i = 2 zeta sqrt(k_i M), docs/modules/plant.md), so the plant's "
    "presliding dynamics change with the size in their length scale only, not in their damping: with the "
    "demo's fixed 2000 N s/m per element the smallest sizes made a lightly damped mode (ratio 0.02 at "
    "0.02) whose chatter the diagnosis named, with a presliding_m 25 times the plant's (docs/diagnose.md, "
    "presliding_hysteresis). Same bisection, proof and bounds as the table above; "
    "the nominal logs are LuGre logs with the same reversal segment, where the cause is tested (the "
    "identification logs above are below its gate, MIN_PRESLIDING_SAMPLES).")}


def run_line(s, command, wall_s):
    n = s["n"]
    return (f"Command: `{command}` ({n} logs per probed size, {s['n_nominal']} nominal logs per noise level; "
            f"seeds fixed). {s.get('logs_run', '?')} logs; wall time {wall_s / 60:.1f} min, CPU time "
            f"{s.get('cpu_s', float('nan')) / 60:.1f} min ({s.get('jobs', 1)} process(es))"
            + (f"; {s['cached_logs']} logs came from an earlier run's cache (WORK/cache.jsonl)"
               if s.get("cached_logs") else "")
            + (f"; the logs' own wall times (cached and new) add up to {s['log_seconds'] / 60:.1f} min"
               if s.get("cached_logs") and s.get("log_seconds") else "")
            + "." + (f" {s['note']}" if s.get("note") else ""))


def limit_table(s, causes):
    nv = s.get("n_verify", 0)
    L = ["| cause | size | " + " | ".join(
        f"limit at {k} noise ({v['force_noise_N']:.3g} N): detected, {100 * s['conf']:.0f} % lower bound | "
        "failed below" + (" | proven: detected, lower bound" if nv else "")
        for k, v in s["levels"].items()) + " |",
        "|---|---|" + ("---|---|---|" if nv else "---|---|") * len(s["levels"])]
    for cause in causes:
        what, unit = GENERATORS[cause][:2]
        cells = []
        for v in s["levels"].values():
            c = v["causes"][cause]
            if c["limit"] is None:
                cells.append(f"not within the ladder (> {_fmt(c['ladder'][-1], unit)})")
            else:
                a = c["at_limit"]
                pre = "≤ " if c["limit_index"] == 0 else ""
                cells.append(f"{pre}{_fmt(c['limit'], unit)}: {a['detected']}/{a['logs']}, "
                             f"≥ {100 * c['at_limit_lower']:.0f} %")
            b = c["failed_below"]
            cells.append(f"{_fmt(b['size'], unit)}: {b['detected']}/{b['logs']}" if b else
                         "— (smallest size of the ladder passed)")
            if nv:
                if c.get("proven") is None:
                    cells.append("not within the ladder")
                else:
                    pv = c["verify"][-1]
                    up = len(c["verify"]) - 1
                    cells.append(f"**{_fmt(c['proven'], unit)}**: {pv['detected']}/{pv['logs']}, "
                                 f"≥ {100 * c['proven_lower']:.1f} %"
                                 + (f" ({up} size{'s' if up > 1 else ''} up from the limit)" if up else ""))
        L.append(f"| {cause} | {what} | " + " | ".join(cells) + " |")
    return L


def nominal_table(s, kind):
    L = [f"Nominal logs (no cause; {kind}), any finding counted as a false positive; the upper bound is the "
         f"one-sided {100 * s['conf']:.0f} % Clopper-Pearson bound. Goal: false positives at most 2 %.", "",
         "| noise level | nominal logs | false positives (any finding) | upper bound | verdict unexplained | "
         "upper bound |", "|---|---|---|---|---|---|"]
    for k, v in s["levels"].items():
        st = v["nominal"].get(kind)
        if not st:
            continue
        nl, fp = st["nominal_logs"], st["false_positives"]
        fc = ", ".join(f"{c} {m}" for c, m in sorted(st["false_positive_causes"].items()))
        L.append(f"| {k} ({v['force_noise_N']:.3g} N) | {nl} | {fp} ({100 * fp / nl:.1f} %{'; ' + fc if fc else ''})"
                 f" | {100 * st['false_positive_upper']:.1f} % | {st['unexplained']} "
                 f"({100 * st['unexplained'] / nl:.1f} %) | {100 * st['unexplained_upper']:.1f} % |")
    return L


def plant_presliding_m(size):
    """presliding_m of the study's element set at a size (presliding.md's figure, the cause's own
    function): d_max = size times LuGre's Fs/sigma0, the shape GMS_SHAPE, equal shares."""
    d_max = size * lugre_presliding_scale_m()
    return causes.get(PS_NAME).presliding_m([d_max * f for f in GMS_SHAPE], [1.0] * len(GMS_SHAPE))


def presliding_table(s):
    """What the detections of presliding_hysteresis measured: at each probed size (the bisection's
    and the proof's logs), the presliding_m the findings reported over the plant's."""
    L = ["What the detections measured: at each probed size, presliding_m of the finding over the plant's "
         "(presliding.md's figure of the element set: 1.2 d_max for this shape), the median and range over the "
         "logs that named the cause.", "",
         "| noise level | size: plant's presliding_m, identified / plant's: median (range), logs |", "|---|---|"]
    for k, v in s["levels"].items():
        c = v["causes"][PS_NAME]
        per = {}
        for p in c["probes"] + c.get("verify", []):
            # a proof's first logs are the bisection's at that size: the longer list holds the other
            if len(p.get("ps_m", [])) >= len(per.get(p["size"], [])):
                per[p["size"]] = p.get("ps_m", [])
        cells = []
        for size in sorted(per):
            r = np.array(per[size]) / plant_presliding_m(size)
            cells.append(f"{size:.3g}: {1e6 * plant_presliding_m(size):.3g} um, "
                         + (f"{np.median(r):.2f} ({r.min():.2f} .. {r.max():.2f}), {len(r)}" if len(r) else "—"))
        L.append(f"| {k} ({v['force_noise_N']:.3g} N) | " + "; ".join(cells) + " |")
    return L


def probe_tables(s, causes, depth="##"):
    L = ["Detected / logs run at each size the bisection probed (a failing size stops once "
         f"{misses_allowed(s['n']) + 1} logs have missed the cause); in brackets, the logs where another cause was "
         "found too.", ""]
    for k, v in s["levels"].items():
        L += [f"{depth}# {k} noise ({v['force_noise_N']:.3g} N)", "", "| cause | size: detected/logs (other) |",
              "|---|---|"]
        for cause in causes:
            c = v["causes"][cause]
            unit = GENERATORS[cause][1]
            L.append(f"| {cause} | " + ", ".join(
                f"{_fmt(p['size'], unit)}: {p['detected']}/{p['logs']}" + (f" ({p['other_findings']})"
                                                                           if p["other_findings"] else "")
                for p in c["probes"]) + ("; proof: " + ", ".join(
                    f"{_fmt(p['size'], unit)}: {p['detected']}/{p['logs']}" + (f" ({p['other_findings']})"
                                                                               if p["other_findings"] else "")
                    for p in c.get("verify", [])) if c.get("verify") else "") + " |")
        L.append("")
    return L


def ran(s):
    """The causes of the summary, in GENERATORS' order."""
    return [c for c in GENERATORS if all(c in v["causes"] for v in s["levels"].values())]


def markdown(s, command, wall_s):
    """(the page's main part, or None when the run had none of its causes; {block cause: its block})."""
    n = s["n"]
    main_causes = [c for c in ran(s) if c not in BLOCKS]
    blocks = {}
    for cause in (c for c in ran(s) if c in BLOCKS):
        kind = logs_of(cause)
        blocks[cause] = "\n".join(
            [BLOCK_BEGIN.format(cause, cause), "", f"## {cause}", "", run_line(s, command, wall_s), "",
             BLOCK_TEXT[cause].format(scale_um=1e6 * lugre_presliding_scale_m(), zeta=lugre_presliding_zeta()), ""]
            + limit_table(s, [cause]) + [""] + nominal_table(s, kind) + [""]
            + (presliding_table(s) + [""] if cause == PS_NAME else [])
            + probe_tables(s, [cause], "##")
            + [f"![detection rate of {cause} against its size at the probed sizes, with 95 % Clopper-Pearson "
               f"intervals](detection-limits-{cause}.png)", "", BLOCK_END.format(cause)])
    if not main_causes:
        return None, blocks
    L = [BANNER, "", "# Detection limits", "", run_line(s, command, wall_s), "",
         "br_simlog identification logs of the reference machine (3 cycles, 27.96 s) with one cause of a given "
         "size and Gaussian force noise, each diagnosed from the log alone. A cause is detected when it is "
         "among the findings. Noise levels: the EMPS log's force noise as the noise floor measures it, and a "
         "quiet log's.", "",
         "Each cause has a ladder of sizes (ratio √2, 15 sizes). The limit is found by bisection on it: a "
         f"probed size passes when at most {misses_allowed(n)} of its {n} logs miss the cause (at least "
         f"{100 * s['rate']:.0f} % detected), and its logs stop as soon as it cannot pass. The bisection assumes "
         "the detection rate grows with the size: the sizes it did not probe are not checked. The limit is "
         "the smallest passing size; the largest failing probe below it is beside it (the true 95 % size lies "
         "between the two). The lower bound is the one-sided "
         f"{100 * s['conf']:.0f} % Clopper-Pearson bound of the detection rate at the limit (with {n} of {n} "
         f"detected: 0.05^(1/{n}) = {100 * 0.05 ** (1 / n):.1f} %): {n} logs show a rate of "
         f"{100 * s['rate']:.0f} % or more at the limit; they do not prove the rate is that high."]
    nv = s.get("n_verify", 0)
    if nv:
        L += ["", f"The proof: {nv} logs at the limit (its first {n} are the bisection's), all of which must "
              f"detect the cause, else the next size up the ladder is tried the same way. {nv} of {nv} "
              f"detected gives a one-sided {100 * s['conf']:.0f} % Clopper-Pearson lower bound of "
              f"0.05^(1/{nv}) = {100 * 0.05 ** (1 / nv):.2f} %"
              + (f": at the proven size the detection rate is at least {100 * s['rate']:.0f} % at "
                 f"{100 * s['conf']:.0f} % confidence (given that the rate grows with the size)."
                 if 0.05 ** (1 / nv) >= s["rate"] else
                 f", short of {100 * s['rate']:.0f} %: too few logs to prove the rate.")]
    L += [""] + limit_table(s, main_causes) + [""] + nominal_table(s, "ident") + ["", "## Probed sizes", ""]
    L += probe_tables(s, main_causes, "")
    L += ["![detection rate against effect size at the probed sizes, with 95 % Clopper-Pearson intervals]"
          "(detection-limits.png)", ""]
    return "\n".join(L), blocks


def compose(old, main, blocks):
    """The page from a run's main part (None: the old page's) and blocks (the old page's others kept)."""
    old_main, old_blocks = old or "", {}
    for cause in BLOCKS:
        b, e = BLOCK_BEGIN.format(cause, cause), BLOCK_END.format(cause)
        if b in old_main and e in old_main:
            i, j = old_main.index(b), old_main.index(e) + len(e)
            old_blocks[cause] = old_main[i:j]
            old_main = old_main[:i].rstrip("\n") + "\n" + old_main[j:].lstrip("\n")
    page = (main if main is not None else old_main).rstrip("\n") + "\n"
    for cause in BLOCKS:
        blk = blocks.get(cause, old_blocks.get(cause))
        if blk:
            page += "\n" + blk + "\n"
    return page


def plot(s, path, names):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    cols = min(3, len(names))
    rows = (len(names) + cols - 1) // cols
    import textwrap
    width = max(4.2 * cols, 8.0)   # one panel (a block's figure): room for the title and the label
    fig, axs = plt.subplots(rows, cols, figsize=(width, 3.3 * rows + 0.4), sharey=True, squeeze=False)
    for ax, cause in zip(axs.flat, names):
        what, unit = GENERATORS[cause][:2]
        for k, v in s["levels"].items():
            c = v["causes"][cause]
            x = np.array([p["size"] for p in c["probes"]])
            k_ = np.array([p["detected"] for p in c["probes"]])
            n_ = np.array([p["logs"] for p in c["probes"]])
            r = 100 * k_ / n_
            lo = [100 * (k / n - (cp_lower(k, n, 0.975))) for k, n in zip(k_, n_)]
            hi = [100 * (cp_upper(k, n, 0.975) - k / n) for k, n in zip(k_, n_)]
            line = ax.errorbar(x, r, yerr=[lo, hi], fmt="o", capsize=2, label=f"{k} ({v['force_noise_N']:.2g} N)")
            if c["limit"] is not None:
                ax.axvline(c["limit"], color=line[0].get_color(), lw=0.8, ls="--")
            if c.get("verify"):
                # the proof's sizes (their first logs are the bisection's)
                xv = np.array([p["size"] for p in c["verify"]])
                rv = np.array([100 * p["detected"] / p["logs"] for p in c["verify"]])
                ax.plot(xv, rv, "s", mfc="none", ms=8, color=line[0].get_color())
            if c.get("proven") is not None:
                ax.axvline(c["proven"], color=line[0].get_color(), lw=1.2, ls="-")
        ax.set_xscale("log")
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.axhline(100 * s["rate"], color="k", lw=0.6, ls=":")
        ax.set_title(cause, fontsize=9)
        ax.set_xlabel(textwrap.fill(f"{what} [{unit}]" if unit else what, int(width * 12 / cols)), fontsize=8)
        ax.grid(alpha=0.3)
    for ax in axs.flat[len(names):]:
        ax.set_visible(False)
    for row in axs:
        row[0].set_ylabel("detected [% of logs]")
    axs.flat[0].legend(fontsize=7, loc="center right")
    fig.suptitle(textwrap.fill("detection rate at the probed sizes (95 % Clopper-Pearson intervals; dashed: the "
                               "limit; open squares: the proof's sizes; solid: the proven limit)", int(width * 14)),
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def write(s, a, cmd):
    main, blocks = markdown(s, cmd, s.get("wall_s", float("nan")))
    if a.md:
        old = None
        if os.path.isfile(a.md):
            with open(a.md) as f:
                old = f.read()
        with open(a.md, "w") as f:
            f.write(compose(old, main, blocks))
    if a.png:
        names = [c for c in ran(s) if c not in BLOCKS]
        if names:
            plot(s, a.png, names)
        for cause in blocks:
            # the block's figure beside the page's: detection-limits-<cause>.png
            plot(s, os.path.join(os.path.dirname(a.png), f"detection-limits-{cause}.png"), [cause])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--simlog", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--n", type=int, default=20, help="logs per probed size")
    ap.add_argument("--n-verify", type=int, default=59,
                    help="logs at the limit that must all detect the cause (0: no proof)")
    ap.add_argument("--n-nominal", type=int, default=150, help="nominal logs per noise level")
    ap.add_argument("--md")
    ap.add_argument("--png")
    ap.add_argument("--json")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--causes", default=",".join(GENERATORS), help="comma-separated subset of the causes")
    ap.add_argument("--fresh", action="store_true", help="forget the logs an earlier run left in --work")
    ap.add_argument("--from-json", help="write --md / --png from a saved --json summary, running nothing")
    a = ap.parse_args()
    if a.n_verify < 0 or (a.n_verify and a.n_verify < a.n):
        ap.error("--n-verify: 0 or at least --n")   # the proof's first logs are the bisection's
    cmd = os.environ.get("BR_DETECTION_COMMAND", " ".join(["detection_limits.py"] + sys.argv[1:]))
    if a.from_json:
        with open(a.from_json) as f:
            s = json.load(f)
        write(s, a, s.get("command", cmd))
        return 0
    causes = [c for c in a.causes.split(",") if c]
    unknown = [c for c in causes if c not in GENERATORS]
    if unknown:
        raise SystemExit(f"error: unknown cause(s) {unknown}; known: {list(GENERATORS)}")
    os.makedirs(a.work, exist_ok=True)
    if a.fresh and os.path.exists(_cache_path(a.work)):
        os.remove(_cache_path(a.work))
    CACHE.update(load_cache(a.work))
    # the cached logs this code can reuse (a result of other code is never reused: its digest differs)
    digest = run_digest(a.simlog)
    cached = sum(k.endswith("|" + digest) for k in CACHE)
    if CACHE:
        print(f"{len(CACHE)} logs from {_cache_path(a.work)} (an earlier run's; --fresh runs them again)")
    t0 = time.time()
    levels = (("EMPS", emps_noise()), ("quiet", QUIET_N))
    print(f"{len(causes)} causes x {len(levels)} noise levels, N = {a.n} per probed size, "
          f"{a.n_nominal} nominal logs per level, on {a.jobs} process(es)", flush=True)
    res = study(os.path.abspath(a.simlog), os.path.abspath(a.work), levels, a.n, a.n_nominal, a.jobs, causes,
                a.n_verify)
    s = summarize(res, levels, a.n, a.n_nominal, causes, a.n_verify)
    s["wall_s"] = time.time() - t0
    ru = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    s["cpu_s"] = sum(r.ru_utime + r.ru_stime for r in ru)
    s["cached_logs"] = cached
    s["log_seconds"] = sum(SECONDS.get(k, 0.0) for k in USED)
    s["command"] = cmd
    s["jobs"] = a.jobs
    s["note"] = os.environ.get("BR_DETECTION_NOTE", "")
    s["logs_run"] = sum(st["nominal_logs"] for v in s["levels"].values() for st in v["nominal"].values())
    for v in s["levels"].values():
        for c in v["causes"].values():
            seen = {p["size"]: p["logs"] for p in c["probes"]}
            s["logs_run"] += sum(seen.values())
            # a proof's first logs at a probed size are the bisection's
            s["logs_run"] += sum(max(0, p["logs"] - seen.get(p["size"], 0)) for p in c.get("verify", []))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(s, f, indent=1)
    write(s, a, cmd)
    print(f"{s['logs_run']} logs ({cached} from the cache) in {s['wall_s'] / 60:.1f} min, "
          f"CPU {s['cpu_s'] / 60:.1f} min")
    for k, v in s["levels"].items():
        print(f"{k} noise {v['force_noise_N']:.3g} N: " + "; ".join(
            f"{kind}: false positives {st['false_positives']}/{st['nominal_logs']} (upper "
            f"{100 * st['false_positive_upper']:.1f} %), unexplained {st['unexplained']}"
            for kind, st in v["nominal"].items()) + "; limits "
            + ", ".join(f"{c} {d['limit']} (proven {d.get('proven')})" for c, d in v["causes"].items()))
    fp = max((st["false_positives"] / st["nominal_logs"] for v in s["levels"].values()
              for st in v["nominal"].values() if st["nominal_logs"]), default=0.0)
    return 0 if fp <= 0.02 else 1


if __name__ == "__main__":
    sys.exit(main())
