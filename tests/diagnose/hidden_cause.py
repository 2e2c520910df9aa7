"""Hidden-cause suite: logs whose cause and parameters come from a seeded
generator the diagnosis never sees, diagnosed from the log alone.

Each case: the generator draws a cause (balanced over none + the five
causes, in a seeded order) and its parameters; br_simlog writes an
identification log of the reference machine with that cause (and seeded
force noise); the diagnosis's command line (`python -m bristle.diagnose diagnose`,
called in this process) gets only the log path, in a directory holding
nothing else. The case passes when
  - the verdict is the hidden cause ("none" for a nominal log),
  - every parameter the spec names for the cause (the spec's names: a
    finding's "params") is within PARAM_TOL (20 %) of the hidden value
    (checked for the verdict's finding),
  - the extended model's held-out relerr is below the nominal's (a cause),
    or no finding at all (none).

Usage:
  hidden_cause.py --simlog BIN --work DIR [--cases N] [--shard I/K] [--json OUT]
  hidden_cause.py --merge A.json B.json ... --md OUT.md    (confusion matrix, parameter errors)
Exit status 1 when a case fails (each failure printed with its reasons).
"""
import argparse
import contextlib
import io
import json
import math
import os
import shutil
import subprocess
import sys
import time

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "python"))
from bristle.diagnose import __main__ as diagnose_cli  # noqa: E402
from bristle.diagnose import causes  # noqa: E402

CAUSES = ("none",) + causes.NAMES
MASTER_SEED = 20261121
DEFAULT_CASES = 36
PARAM_TOL = 0.20
# the reference machine's friction, which br_simlog's plant has (through the
# machine file's loader, firmware/design/machine.py)
sys.path.insert(0, os.path.join(REPO, "firmware", "design"))
import machine  # noqa: E402
_REF = machine.params(machine.load(os.path.join(REPO, "machines", "reference.json")))
FC_N, SIGMA2_NSPM = _REF["Fc_N"], _REF["sigma2_Nspm"]


def draw(i, n_cases, master=MASTER_SEED):
    """Case i of n: its cause, hidden parameters, br_simlog flags, noise, seed."""
    order = np.random.default_rng(master).permutation(n_cases)
    cause = CAUSES[int(order[i]) % len(CAUSES)]
    rng = np.random.default_rng([master, i])
    sign = lambda: 1.0 if rng.random() < 0.5 else -1.0  # noqa: E731
    noise = float(rng.uniform(0.0, 0.2))
    truth, flags = {}, []
    if cause == "offset":
        f = sign() * rng.uniform(0.5, 3.0)
        truth = {"force_N": f}
        flags = ["--offset", f"{f:.6g}"]
    elif cause == "asymmetric_friction":
        r = 1.0 + sign() * rng.uniform(0.10, 0.30)
        fv = 1.0 + sign() * rng.uniform(0.20, 0.60)
        truth = {"Fc_pos_N": FC_N, "Fc_neg_N": FC_N * r, "Fv_pos_Nspm": SIGMA2_NSPM, "Fv_neg_Nspm": SIGMA2_NSPM * fv}
        flags = ["--asym", f"{FC_N * (r - 1):.6g},{SIGMA2_NSPM * (fv - 1):.6g}"]
    elif cause == "position_ripple":
        a = rng.uniform(0.3, 1.5)
        p = math.exp(rng.uniform(math.log(3e-3), math.log(20e-3)))
        ph = rng.uniform(0.0, 2 * math.pi)
        truth = {"period_m": p, "amplitude_N": a}
        flags = ["--ripple", f"{a:.6g},{p:.6g},{ph:.6g}"]
    elif cause == "position_gradient":
        s = sign() * rng.uniform(1.5, 5.0)
        truth = {"relative_slope_per_m": s}
        flags = ["--gradient", f"{s:.6g}"]
    elif cause == "actuator_delay":
        d = rng.uniform(1e-3, 5e-3)
        truth = {"delay_s": d}
        flags = ["--delay", f"{d:.6g}"]
    elif cause != "none":
        raise ValueError(f"no generator for the cause {cause}: add one here")
    return {"case": i, "cause": cause, "truth": truth, "flags": flags, "noise_N": noise,
            "sim_seed": int(rng.integers(1, 2 ** 31))}


def run_case(case, simlog, work):
    d = os.path.join(work, f"case{case['case']:03d}")
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(os.path.join(d, "log"))
    log = os.path.join(d, "log", "log.csv")  # alone in its directory: no truth, no machine file beside it
    subprocess.run([simlog, "--out", log, "--seed", str(case["sim_seed"]), "--force-noise", f"{case['noise_N']:.6g}"]
                   + case["flags"], check=True)
    out = os.path.join(d, "out")
    # the diagnosis's own command line, in this process (one interpreter start
    # for all the cases); it is given the log path and nothing else
    t0 = time.time()
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        rc = diagnose_cli.main(["diagnose", "--log", log, "--out", out, "--no-plots", "--quiet"])
    secs = time.time() - t0
    if rc != 0:
        return dict(case, verdict="error", ok=False, reasons=[f"diagnose failed: {err.getvalue().strip()}"],
                    seconds=secs)
    with open(os.path.join(out, "report.json")) as f:
        rep = json.load(f)
    return judge(case, rep, secs)


def judge(case, rep, secs):
    reasons = []
    verdict = rep["verdict"]
    nom, ext = rep["nominal"]["relerr_percent"], rep["extended"]["relerr_percent"]
    errs = {}
    if verdict != case["cause"]:
        reasons.append(f"verdict {verdict}, hidden cause {case['cause']}")
    if case["cause"] == "none":
        if rep["findings"]:
            reasons.append("findings on a nominal log: " + ", ".join(f["cause"] for f in rep["findings"]))
    else:
        if not ext < nom:
            reasons.append(f"no held-out gain: extended {ext:.4g} % >= nominal {nom:.4g} %")
        if verdict == case["cause"]:
            got = rep["findings"][0]["params"]
            for k, v in case["truth"].items():
                e = (got[k] - v) / abs(v)
                errs[k] = e
                if not abs(e) <= PARAM_TOL:
                    reasons.append(f"{k} = {got[k]:.4g}, hidden {v:.4g} ({100 * e:+.1f} %)")
    return dict(case, verdict=verdict, ok=not reasons, reasons=reasons, param_errors=errs,
                relerr_nominal=nom, relerr_extended=ext, findings=[f["cause"] for f in rep["findings"]],
                seconds=secs)


def markdown(results, command):
    n = len(results)
    idx = {c: k for k, c in enumerate(CAUSES)}
    cols = list(CAUSES) + ["error"]
    m = np.zeros((len(CAUSES), len(cols)), dtype=int)
    for r in results:
        m[idx[r["cause"]], cols.index(r["verdict"]) if r["verdict"] in cols else len(cols) - 1] += 1
    ok = sum(r["ok"] for r in results)
    right = sum(r["verdict"] == r["cause"] for r in results)
    L = ["<!-- generated by tests/diagnose/hidden_cause.py; do not edit -->", "",
         "# Hidden-cause suite: results", "",
         f"Command: `{command}`", "",
         f"{n} cases (master seed {MASTER_SEED}), {right} verdicts right ({100 * right / n:.0f} %), "
         f"{ok} cases passing every check (verdict, parameters within {100 * PARAM_TOL:.0f} %, held-out gain).", "",
         "## Confusion matrix (rows: hidden cause, columns: verdict)", "",
         "| hidden \\ verdict | " + " | ".join(cols) + " |", "|---" * (len(cols) + 1) + "|"]
    for i, c in enumerate(CAUSES):
        L.append(f"| {c} | " + " | ".join(str(x) for x in m[i]) + " |")
    L += ["", "## Parameter errors (verdict's finding against the hidden value)", "",
          "| case | cause | hidden | found error | held-out relerr nominal → extended | noise [N] |",
          "|---|---|---|---|---|---|"]
    for r in sorted(results, key=lambda r: (CAUSES.index(r["cause"]), r["case"])):
        hid = ", ".join(f"{k} = {v:.4g}" for k, v in r["truth"].items()) or "—"
        er = ", ".join(f"{k} {100 * v:+.2f} %" for k, v in r.get("param_errors", {}).items()) or "—"
        if not r["ok"]:
            er += " — FAILED: " + "; ".join(r["reasons"])
        rel = f"{r.get('relerr_nominal', float('nan')):.3g} % → {r.get('relerr_extended', float('nan')):.3g} %"
        L.append(f"| {r['case']} | {r['cause']} | {hid} | {er} | {rel} | {r['noise_N']:.3f} |")
    worst = {}
    for r in results:
        for k, v in r.get("param_errors", {}).items():
            worst[(r["cause"], k)] = max(worst.get((r["cause"], k), 0.0), abs(v))
    L += ["", "## Largest parameter error per cause", "", "| cause | parameter | max abs error |", "|---|---|---|"]
    for (c, k), v in sorted(worst.items(), key=lambda x: (CAUSES.index(x[0][0]), x[0][1])):
        L.append(f"| {c} | {k} | {100 * v:.2f} % |")
    L.append("")
    return "\n".join(L)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--simlog")
    ap.add_argument("--work")
    ap.add_argument("--cases", type=int, default=DEFAULT_CASES)
    ap.add_argument("--shard", default="0/1")
    ap.add_argument("--json")
    ap.add_argument("--merge", nargs="*")
    ap.add_argument("--md")
    ap.add_argument("--min-cases", type=int, default=30)
    ap.add_argument("--master-seed", type=int, default=MASTER_SEED,
                    help="another seed draws other cases (the thresholds were tuned on seeds other than the default)")
    a = ap.parse_args()
    if a.merge:
        results = []
        for p in a.merge:
            with open(p) as f:
                results += json.load(f)
        covered = {r["cause"] for r in results}
        bad = [r for r in results if not r["ok"]]
        if a.md:
            with open(a.md, "w") as f:
                f.write(markdown(results, " ".join(sys.argv[1:]) if not os.environ.get("BR_HIDDEN_COMMAND")
                                 else os.environ["BR_HIDDEN_COMMAND"]))
        print(f"{len(results)} cases, {len(bad)} failing, causes covered: {', '.join(sorted(covered))}")
        if len(results) < a.min_cases or covered != set(CAUSES):
            print(f"error: need at least {a.min_cases} cases covering every cause", file=sys.stderr)
            return 1
        return 1 if bad else 0
    if not (a.simlog and a.work):
        ap.error("--simlog and --work are needed to run cases")
    k, K = (int(x) for x in a.shard.split("/"))
    mine = [i for i in range(a.cases) if i % K == k]
    os.makedirs(a.work, exist_ok=True)
    if a.json and os.path.exists(a.json):
        os.remove(a.json)  # never leave an older shard's results for the merge
    results = []
    for i in mine:
        case = draw(i, a.cases, a.master_seed)
        r = run_case(case, a.simlog, a.work)
        results.append(r)
        status = "ok  " if r["ok"] else "FAIL"
        print(f"{status} case {i:3d}: hidden {r['cause']:20s} verdict {r['verdict']:20s} "
              f"({r['seconds']:.1f} s){'  ' + '; '.join(r['reasons']) if r['reasons'] else ''}", flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(results, f, indent=1)
    return 0 if all(r["ok"] for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
