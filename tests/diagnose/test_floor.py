# SPDX-License-Identifier: Apache-2.0
"""The noise floor, the verdict "unexplained" and causes in combination
(docs/diagnose.md):
  - the floor's force-noise estimate against br_simlog logs of known noise
    (within 15 % where the noise dominates the drive's own chatter);
  - a nominal log (br_simlog) and a nominal log of the independent
    simulator (axis_sim.py) get "none";
  - a force no named cause describes (axis_sim's quadratic drag) gets
    "unexplained", not "none", and the report says it goes with velocity;
  - offset + asymmetric friction + actuator delay in one log (the case the
    issue found failing): all three found, every parameter within 20 %.

Usage: test_floor.py --simlog BIN --work DIR"""
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "python"))
sys.path.insert(0, HERE)
import axis_sim  # noqa: E402
import work_args  # noqa: E402
from bristle.diagnose import logreader, noise, report, selection, signals  # noqa: E402

FAILS = []


def check(cond, msg):
    print(("ok    " if cond else "FAIL  ") + msg, flush=True)
    if not cond:
        FAILS.append(msg)


def diagnose(path):
    prep = signals.Prepared(logreader.read_log(path))
    return report.build(prep, selection.diagnose(prep))


def main():
    a, simlog = work_args.simlog_script()

    for sigma in (0.05, 0.2):
        p = simlog(f"noise{sigma}", "--seed", 11, "--force-noise", sigma)
        fl = noise.measure(signals.Prepared(logreader.read_log(p)))
        check(abs(fl.sigma_N - sigma) <= 0.15 * sigma,
              f"force noise {sigma} N measured from the log as {fl.sigma_N:.4g} N (within 15 %)")

    rep = diagnose(simlog("nominal", "--seed", 4, "--force-noise", 0.1))
    md = report.markdown(rep, [])
    check("closed_loop" not in rep and "no machine file" in rep.get("closed_loop_skipped", "")
          and rep.get("closed_loop_skipped", "?") in md,
          "no machine file: the report says why the closed loop was skipped")
    check(rep["verdict"] == "none" and rep["unexplained"] is None,
          f"br_simlog nominal log: verdict {rep['verdict']} (none), held-out relerr "
          f"{rep['nominal']['relerr_percent']:.3g} % at the floor {rep['noise_floor_percent']:.3g} %")

    p = axis_sim.write_log(os.path.join(a.work, "axis_nominal.csv"), "reference", {}, 0.1, 21)
    rep = diagnose(p)
    check(rep["verdict"] == "none", f"axis_sim nominal log: verdict {rep['verdict']} (none), relerr "
          f"{rep['nominal']['relerr_percent']:.3g} %, floor {rep['noise_floor_percent']:.3g} %")

    p = axis_sim.write_log(os.path.join(a.work, "axis_drag.csv"), "reference", {"drag": 3000.0}, 0.1, 22)
    rep = diagnose(p)
    une = rep["unexplained"] or {}
    check(rep["verdict"] == "unexplained",
          f"quadratic drag (no named cause): verdict {rep['verdict']} (unexplained), relerr "
          f"{rep['nominal']['relerr_percent']:.3g} % against the floor {rep['noise_floor_percent']:.3g} %")
    check("velocity" in une.get("goes_with", []), f"... and it goes with {une.get('goes_with')} (velocity among them)")

    truth = {"force_N": 2.0, "Fc_pos_N": 7.0, "Fc_neg_N": 8.4, "Fv_pos_Nspm": 50.0, "Fv_neg_Nspm": 70.0,
             "delay_s": 0.003}
    rep = diagnose(simlog("triple", "--seed", 3, "--force-noise", 0.1, "--offset", 2.0, "--asym", "1.4,20",
                          "--delay", 0.003))
    found = {f["cause"]: f["params"] for f in rep["findings"]}
    check(set(found) == {"offset", "asymmetric_friction", "actuator_delay"},
          f"offset + asymmetric friction + delay: found {sorted(found)}")
    got = {k: v for ps in found.values() for k, v in ps.items()}
    for k, v in truth.items():
        e = (got.get(k, math.nan) - v) / v
        check(abs(e) <= 0.2, f"... {k} = {got.get(k, math.nan):.4g}, hidden {v:.4g} ({100 * e:+.1f} %)")
    return 1 if FAILS else 0


if __name__ == "__main__":
    sys.exit(main())
