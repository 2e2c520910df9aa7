# SPDX-License-Identifier: Apache-2.0
"""make bench's numpy PF (sim/bench/pf_numpy.py) is the C filter bit for bit,
also where the thesis circle never takes it: on the demo's realistic plant
cfg.adapt's noise factor rises above 1 and the cloud is re-anchored after
consecutive outliers (with the thesis gate, --thesis-gate; with the machine's
transient term no outlier comes). br_bench
records that closed loop (--plant realistic) both ways, and the hardware-like plant's with a 3.1 ms actuator delay
(--plant hardware_like --plant-delay 0.0031), where the PF's delay
identification switches, also in its steady phase (docs/modules/dlyid.md),
and the filter predicts with the delayed torque (all three with --pf-load 0:
the machine's shared external force takes the misfit up and none of these
paths is reached); and the PF with its shared
external force (cfg.load, --pf-load 1e4) behind a 1-sigma thesis gate on the
hardware-like plant, where gated steps are re-acquired as load changes
(the undo of a glitch is not reached by these recordings);
pf_numpy.py --check replays each and exits 1 unless every step's F_hat equals
the C filter's. The test also requires that the recording reaches both paths
(else it would prove nothing); --plant's refusals are in test_tools.py.
Run with a release br_bench (a sanitised one is slow).

Usage: test_bench_numpy.py --bench BIN --work DIR"""
import json
import os
import subprocess
import sys

import tool_check

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def main():
    bench, work = tool_check.start("bench")
    fails = []
    # the machine's gate (its transient term, eq. G1, in the threshold and the NIS cap), then the
    # thesis gate, with which the realistic plant's encoder noise re-anchors the cloud
    # the hardware-like plant (Maxwell-slip friction) with a 3.1 ms actuator delay: the delay identification
    # switches there, also in its steady phase where the machine has one (with the PF tuned with its
    # Maxwell-slip guards, 2026-11-28, the 2.7 ms of before had no switch in the steady phase)
    for tag, plant, extra, need in (
            ("term", "realistic", ["--pf-load", "0"], ("adapt_active_steps",)),
            ("thesis_gate", "realistic", ["--thesis-gate", "--pf-load", "0"], ("adapt_active_steps", "reanchor_steps")),
            ("hardware_like", "hardware_like", ["--plant-delay", "0.0031", "--pf-load", "0"],
             ("adapt_active_steps", "delay_switches", "delay_switches_steady")),
            # the PF's shared external force (cfg.load) with a 1-sigma thesis gate: gated steps re-acquired
            ("load", "hardware_like", ["--thesis-gate", "--pf-load", "1e4", "--pf-gate", "1"],
             ("load_acquisitions",))):
        rec = os.path.join(work, "pf_input_%s.csv" % tag)
        rc, out = run([bench, "--plant", plant, "--reps", "1", "--ukf-reps", "1", "--record", rec] + extra)
        if rc != 0:
            sys.exit("br_bench --plant %s %s failed (exit %d):\n%s" % (plant, " ".join(extra), rc, out))
        res = os.path.join(work, "numpy_%s.json" % tag)
        rc, out = run([sys.executable, os.path.join(ROOT, "sim", "bench", "pf_numpy.py"), rec, "--reps", "1",
                       "--check", "--out", res])
        print(out)
        if rc != 0:
            fails.append("%s: pf_numpy.py --check: exit %d (not bit-identical to the C filter, or not tracking)"
                         % (tag, rc))
            continue
        with open(res) as f:
            r = json.load(f)
        if "adapt_active_steps" in need and r["adapt_active_steps"] == 0:
            fails.append("%s: the recording never raises cfg.adapt's noise factor: the adapt path is not compared"
                         % tag)
        if "reanchor_steps" in need and r["reanchor_steps"] == 0:
            fails.append("%s: the recording never re-anchors the cloud: that path is not compared" % tag)
        if "delay_switches" in need and r["delay_switches"] == 0:
            fails.append("%s: the delay identification never switches: the delayed torque is not compared" % tag)
        if "load_acquisitions" in need and r["load_acquisitions"] == 0:
            fails.append("%s: cfg.load never re-acquires a gated step: its update's gated path is not compared" % tag)
        if "delay_switches_steady" in need and r["delay_id_steady_phase"] and r["delay_switches_steady"] == 0:
            fails.append("%s: no switch in the delay identification's steady phase: its memory and ratio are not "
                         "compared" % tag)
    return tool_check.finish(fails)

if __name__ == "__main__":
    sys.exit(main())
