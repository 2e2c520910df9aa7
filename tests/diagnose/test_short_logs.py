# SPDX-License-Identifier: Apache-2.0
"""Logs that are not long moves (docs/diagnose.md, "Identifiability" and
"Unit checks"), each 24 s from br_simlog with 0.1 N of force noise and a
hidden cause that must be named:

  - the thesis circle with asymmetric friction (the issue's failing case:
    the free fit put sigma2 at -134 N s/m and machine.json did not load):
    asymmetric_friction named, dFc_neg within 10 %, exit 0, machine.json
    loads, sigma2 not identified and held at the machine file's value,
    every parameter within its bounds (sigma2 >= 0, sigma2 + dsigma2 >= 0);
  - a slow back-and-forth with an offset: offset named within 10 %; the
    Stribeck velocity not identified and held; Fc and sigma2 identified,
    the plant's values inside twice their stated 95 % intervals (the free fit
    gave Fc 0.70 N and sigma2 106 N s/m);
  - a sweep with a 2 ms dead time: actuator_delay named within 10 %;
  - the sweep written in mm, with the force as a torque in N m and with
    the time in ms: refused, exit 1, the message naming the unit.

The plant's values come from machines/reference.json (the reference
machine br_simlog simulates), never from numbers written here.

Usage: test_short_logs.py --simlog BIN --work DIR"""
import json
import math
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import work_args  # noqa: E402
sys.path.insert(0, os.path.join(REPO, "python"))
from bristle.diagnose import causes, identify, machinejson, params  # noqa: E402

FAILS = []
ENV = dict(os.environ, PYTHONPATH=os.path.join(REPO, "python"))


def check(cond, msg):
    print(("ok    " if cond else "FAIL  ") + msg, flush=True)
    if not cond:
        FAILS.append(msg)


def near(got, want, rel=0.1):
    return abs(got - want) <= rel * abs(want)


def diagnose(log, out):
    r = subprocess.run([sys.executable, "-m", "bristle.diagnose", "diagnose", "--log", log, "--out", out,
                        "--no-plots", "-q"], env=ENV, capture_output=True, text=True)
    rep = None
    if r.returncode == 0:
        with open(os.path.join(out, "report.json"), encoding="utf-8") as f:
            rep = json.load(f)
    return r, rep


def in_bounds(p):
    table = {q.name: q for q in causes.MODEL_PARAMS}
    bad = [table[k].check(v) for k, v in p.items() if table[k].check(v)]
    bad += [msg for names, ok, msg in params.RELATIONS if all(n in p for n in names) and not ok(p)]
    return bad


def main():
    a, simlog = work_args.simlog_script("--duration", 24, "--force-noise", 0.1)
    p0 = identify.prior(machinejson.base(None))

    # the thesis circle, asymmetric friction
    r, rep = diagnose(simlog("circle", "--traj", "circle", "--asym", "2,30", "--seed", 1), os.path.join(a.work, "c"))
    check(r.returncode == 0, f"circle: diagnosed, exit {r.returncode} {r.stderr.strip()[-300:]}")
    if rep:
        check(rep["verdict"] == "asymmetric_friction", f"circle: verdict {rep['verdict']} (asymmetric_friction)")
        p = rep["extended"]["params"]
        check(near(p.get("dFc_neg_N", 0.0), 2.0), f"circle: dFc_neg_N {p.get('dFc_neg_N')} within 10 % of 2 N")
        held = rep["identifiability"]["held"]
        check("sigma2_Nspm" in held and p["sigma2_Nspm"] == p0["sigma2_Nspm"],
              f"circle: sigma2 not identified, held at the machine file's {p0['sigma2_Nspm']} "
              f"(got {p['sigma2_Nspm']}, held {sorted(held)})")
        check("sigma2_Nspm" in rep["extended"]["not_identified"], "circle: report lists sigma2 as not identified")
        check(not in_bounds(p), f"circle: every parameter within its bounds {in_bounds(p)}")
        mach = machinejson._loader()
        m = mach.load(os.path.join(a.work, "c", "machine.json"))
        check(mach.provenance(m, "friction.sigma2_Nspm") == "assumed",
              "circle: machine.json's sigma2 is the reference's, provenance assumed")

    # a slow back-and-forth, offset
    r, rep = diagnose(simlog("backforth", "--traj", "backforth", "--offset", 1.0, "--seed", 2,
                             "--machine-out", os.path.join(a.work, "backforth.machine.json")), os.path.join(a.work, "b"))
    check(r.returncode == 0, f"back-and-forth: diagnosed, exit {r.returncode} {r.stderr.strip()[-300:]}")
    if rep:
        check(rep["verdict"] == "offset", f"back-and-forth: verdict {rep['verdict']} (offset)")
        p = rep["extended"]["params"]
        check(near(p.get("offset_N", 0.0), 1.0), f"back-and-forth: offset {p.get('offset_N')} within 10 % of 1 N")
        check("vs_mps" in rep["identifiability"]["held"], "back-and-forth: vs not identified, held")
        for k in ("Fc_N", "sigma2_Nspm"):
            # identified, and the plant's value inside twice the 95 % interval the report states (the
            # linearised interval at the machine file's values was measured 5 % short on this log:
            # docs/diagnose.md, Identifiability)
            rse = rep["identifiability"]["identified"].get(k)
            check(rse is not None and abs(p[k] - p0[k]) <= 2 * identify.Z * rse * p0[k],
                  f"back-and-forth: {k} {p[k]:.4g} identified, the plant's {p0[k]} within twice its 95 % interval "
                  f"(rse {rse})")
        check(not in_bounds(p), f"back-and-forth: every parameter within its bounds {in_bounds(p)}")

    # a sweep, 2 ms dead time
    sweep = simlog("sweep", "--traj", "sweep", "--delay", 0.002, "--seed", 3,
                   "--machine-out", os.path.join(a.work, "sweep.machine.json"))
    r, rep = diagnose(sweep, os.path.join(a.work, "s"))
    check(r.returncode == 0, f"sweep: diagnosed, exit {r.returncode} {r.stderr.strip()[-300:]}")
    if rep:
        check(rep["verdict"] == "actuator_delay", f"sweep: verdict {rep['verdict']} (actuator_delay)")
        d = rep["extended"]["params"].get("delay_s", 0.0)
        check(near(d, 0.002), f"sweep: delay {d} within 10 % of 2 ms")

    # unit mistakes, refused before the fit naming the unit
    data = np.loadtxt(sweep, delimiter=",", skiprows=1)
    lead = machinejson.base(None)["mechanics"]["lead_m_per_rev"]
    for name, col, factor, word in (("mm", (1, 2), 1000.0, "millimetres"),
                                    ("Nm", (3,), lead / (2 * math.pi), "torque in N m"),
                                    ("ms", (0,), 1000.0, "milliseconds")):
        d = data.copy()
        d[:, list(col)] *= factor
        path = os.path.join(a.work, f"unit_{name}.csv")
        np.savetxt(path, d, delimiter=",", header="t,ref,pos,force", comments="", fmt="%.10g")
        r, _ = diagnose(path, os.path.join(a.work, f"u_{name}"))
        check(r.returncode == 1 and word in r.stderr and "Traceback" not in r.stderr,
              f"{name}: refused naming the unit ({word}): exit {r.returncode} {r.stderr.strip()[:200]}")
        check(not os.path.exists(os.path.join(a.work, f"u_{name}", "report.json")), f"{name}: no report written")

    if FAILS:
        print(f"{len(FAILS)} failed")
        return 1
    print("all passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
