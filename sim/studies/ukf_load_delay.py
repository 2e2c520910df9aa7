# SPDX-License-Identifier: Apache-2.0
"""The UKF's external-force state against an actuator delay (docs/modules/ukf.md,
"On in the reference machine (2026-11-28, issue 31 item 3)").

The reference machine's plant with a dead time D (0 .. 3.5 ms, the delay
identification's range) on the thesis circle, H-inf + UKF with its
external-force state F_d at random walks q (0: off), two ways:

  known        the estimator's model has the plant's delay (a model.json with
               delay_s, br_robust_run --model, run hinf_ukf_id, --delay-id 0):
               the load loop itself, as the linear map of pf_load_map.py sees it
  identified   the nominal model with the machine's delay identification
               (run hinf_ukf): what the machine would ship

Each cell is the contour RMS over H-inf only's on the same plant, or the
fault (time, cause): a run that stopped is never a figure (sim/studies/runs.py).

Usage: ukf_load_delay.py --bin BUILD/sim [--q Q ...] [--delays-ms D ...] [--md OUT.md] [--check]
  --check  also run the machine file's q (estimator.ukf.load.q_N2_per_s) and exit 1 unless
           every run at it went to its end within the thesis's hardware PF ratio of H-inf only
           (0.4 / 2.4), known and identified alike
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from robustness import reference  # noqa: E402
from runs import fault_text, faulted  # noqa: E402

DELAYS_MS = (0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5)
QS = (0.0, 3e2, 1e3, 1e4)
THESIS_PF_RATIO = 0.4 / 2.4   # the thesis's hardware: H-inf + PF over H-inf only
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def machine_q():
    """the machine file's UKF external-force random walk, N^2/s (0: off)"""
    with open(os.path.join(REPO, "machines", "reference.json"), encoding="utf-8") as f:
        ld = json.load(f)["estimator"]["ukf"].get("load", {})
    return float(ld.get("q_N2_per_s", 0.0))


def run(binp, plant, run_name, extra):
    """one br_robust_run, its record for run_name"""
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "r.json")
        cmd = [os.path.join(binp, "br_robust_run"), "--plant", plant, "--only", run_name, "--json", out] + extra
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit("ukf_load_delay: failed (exit %d): %s\n%s" % (r.returncode, " ".join(cmd), r.stderr))
        with open(out, encoding="utf-8") as f:
            return json.load(f)["controllers"][run_name]


def cell(rec, hinf):
    return fault_text(rec) if faulted(rec) else "%.3f" % (rec["contour_rms_m"] / hinf)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", required=True, help="the build's sim/ folder (br_robust_run)")
    ap.add_argument("--q", type=float, nargs="+", default=list(QS), help="F_d's random walks, N^2/s (0: off)")
    ap.add_argument("--delays-ms", type=float, nargs="+", default=list(DELAYS_MS))
    ap.add_argument("--md", help="the table as markdown into this file")
    ap.add_argument("--check", action="store_true", help="fail unless the machine's q holds everywhere")
    a = ap.parse_args()
    qm = machine_q()
    if a.check and not any(math.isclose(q, qm, rel_tol=1e-12) for q in a.q):
        a.q.append(qm)  # --check runs the machine's q whatever --q lists
    for q in a.q:
        if not 0.0 <= q <= 1e9:
            ap.error("--q: %g is outside [0, 1e9]" % q)
    for dm in a.delays_ms:
        if not 0.0 <= dm <= 3.5:
            ap.error("--delays-ms: %g is outside [0, 3.5] (the identification's range)" % dm)
    ref = reference()
    bad = []
    lines = ["| delay | H-inf only | " + " | ".join(
        "%s, %s" % ("off" if q == 0 else "q %g" % q, how) for how in ("known", "identified") for q in a.q) + " |",
        "|---" * (2 + 2 * len(a.q)) + "|"]
    with tempfile.TemporaryDirectory() as d:
        for dm in a.delays_ms:
            params = dict(ref)
            if dm > 0.0:
                params["delay_s"] = dm * 1e-3
            plant = os.path.join(d, "plant.json")
            with open(plant, "w", encoding="utf-8") as f:
                json.dump({"generator": "sim/studies/ukf_load_delay.py", "params": params}, f)
            h = run(a.bin, plant, "hinf_only", [])
            if faulted(h):
                sys.exit("ukf_load_delay: H-inf only stopped at %g ms: %s" % (dm, fault_text(h)))
            cells = []
            for how in ("known", "identified"):
                for q in a.q:
                    extra = ["--ukf-load", repr(q)]
                    if how == "known":
                        rec = run(a.bin, plant, "hinf_ukf_id", extra + ["--model", plant, "--delay-id", "0"])
                    else:
                        rec = run(a.bin, plant, "hinf_ukf", extra)
                    cells.append(cell(rec, h["contour_rms_m"]))
                    if a.check and math.isclose(q, qm, rel_tol=1e-12) and (
                            faulted(rec) or not rec["contour_rms_m"] <= THESIS_PF_RATIO * h["contour_rms_m"]):
                        bad.append("%.1f ms, q %g, %s: %s" % (dm, q, how, cells[-1]))
            lines.append("| %.1f ms | %.3e m | %s |" % (dm, h["contour_rms_m"], " | ".join(cells)))
            print(lines[-1], flush=True)
    text = "\n".join(lines) + "\n"
    if a.md:
        tmp = a.md + ".partial"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, a.md)
    else:
        sys.stdout.write(text)
    if bad:
        print("CHECK: at the machine's q %g, runs stopped or above %.3f of H-inf only:\n  %s"
              % (qm, THESIS_PF_RATIO, "\n  ".join(bad)))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
