# SPDX-License-Identifier: Apache-2.0
"""PF against UKF, one stress at a time (docs/robustness.md, "Where the PF
beats the UKF"): the reference machine with a single quantity pushed beyond
the robustness study's ranges (unmodelled actuator delay, friction drift,
force noise, encoder noise, bristle-stiffness mismatch, Stribeck velocity),
H-inf only, + UKF and + PF on the nominal model (br_robust_run).

Usage: pf_ukf_regimes.py --bin BUILD/sim --out DIR [--md OUT.md] [--jobs J]
"""
import argparse
import json
import os
import subprocess
import sys
from multiprocessing import Pool

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from robustness import reference, run_figures  # noqa: E402
from runs import fault_text, faulted  # noqa: E402

# (name, plant parameter changes (factor on the reference, or an added cause), run options)
CASES = [
    ("nominal", {}, {}),
    ("delay 1 ms", {"delay_s": 0.001}, {}),
    ("delay 2 ms", {"delay_s": 0.002}, {}),
    ("delay 3 ms", {"delay_s": 0.003}, {}),
    ("drift +30 %", {}, {"--drift": 0.3}),
    ("drift -30 %", {}, {"--drift": -0.3}),
    ("force noise 0.5 N", {}, {"--force-noise": 0.5}),
    ("force noise 2 N", {}, {"--force-noise": 2.0}),
    ("encoder noise p = 0.05", {}, {"--enc-noise": 0.05}),
    ("encoder noise p = 0.3", {}, {"--enc-noise": 0.3}),
    ("sigma0 x 0.25", {"sigma0_Npm": 0.25}, {}),
    ("sigma0 x 4", {"sigma0_Npm": 4.0}, {}),
    ("vs x 0.2", {"vs_mps": 0.2}, {}),
    ("vs x 5", {"vs_mps": 5.0}, {}),
    ("Fs x 1.5", {"Fs_N": 1.5}, {}),
    ("Fc x 0.6, Fs x 0.6", {"Fc_N": 0.6, "Fs_N": 0.6}, {}),
]
CAUSE_KEYS = ("delay_s",)


def one(job):
    k, (name, ch, opts), binp, out = job
    ref = reference()
    params = dict(ref)
    for key, v in ch.items():
        if key in CAUSE_KEYS:
            params[key] = v
        else:
            params[key] = ref[key] * v
    params["Fs_N"] = max(params["Fs_N"], params["Fc_N"])
    d = os.path.join(out, f"{k:02d}")
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "plant.json"), "w") as f:
        json.dump({"generator": "sim/studies/pf_ukf_regimes.py", "params": params}, f, indent=1)
    cmd = [os.path.join(binp, "br_robust_run"), "--plant", os.path.join(d, "plant.json"), "--only",
           "hinf_only,hinf_ukf,hinf_pf", "--seed", str(k + 1), "--json", os.path.join(d, "result.json")]
    for o, v in opts.items():
        cmd += [o, repr(v)]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        return {"name": name, "error": r.stderr.strip()}
    with open(os.path.join(d, "result.json")) as f:
        return {"name": name, **json.load(f)["controllers"]}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--md")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    with Pool(a.jobs) as p:
        rows = p.map(one, [(k, c, a.bin, a.out) for k, c in enumerate(CASES)])
    with open(os.path.join(a.out, "regimes.json"), "w") as f:
        json.dump(rows, f, indent=1)
    L = ["| stress (reference machine otherwise) | H-inf only | H-inf + UKF | H-inf + PF | PF / UKF |",
         "|---|---|---|---|---|"]

    def cell(r):
        # a faulted run is its fault (time, cause), never an RMS beside full runs (docs/tools.md)
        if faulted(r):
            return fault_text(r)
        s = f"{r['contour_rms_m']:.3e} m"
        return s + (f" ({r['outlier_steps']} outlier steps)" if r["outlier_steps"] else "")

    def ratio_of(r):
        pf, ukf = r["hinf_pf"], r["hinf_ukf"]
        return None if faulted(pf) or faulted(ukf) else pf["contour_rms_m"] / ukf["contour_rms_m"]
    for r in rows:
        if "error" in r:
            L.append(f"| {r['name']} | error: {r['error']} | | | |")
            continue
        ratio = ratio_of(r)
        L.append(f"| {r['name']} | {cell(r['hinf_only'])} | {cell(r['hinf_ukf'])} | {cell(r['hinf_pf'])} | "
                 f"{'—' if ratio is None else f'{ratio:.2f}'} |")
    # the case most favourable to the PF, run again with its traces: Figs. 5-8 (g_p histograms)
    ok = [(k, r) for k, r in enumerate(rows) if "error" not in r and ratio_of(r) is not None]
    k, best = min(ok, key=lambda kr: ratio_of(kr[1]))
    opts = [o for kv in CASES[k][2].items() for o in (kv[0], repr(kv[1]))] + ["--seed", str(k + 1)]
    fig = run_figures(a.bin, os.path.join(a.out, f"{k:02d}", "plant.json"), opts, os.path.join(a.out, "pf_best"))
    L += ["", f"Figures of the case most favourable to the PF ({best['name']}): {fig.get('dir', fig)}"]
    print("\n".join(L))
    if a.md:
        with open(a.md, "w") as f:
            f.write("\n".join(L) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
