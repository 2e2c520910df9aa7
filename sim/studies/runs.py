# SPDX-License-Identifier: Apache-2.0
"""A closed-loop run as the tools write it (docs/tools.md, "A faulted run is not
a result"): the one place the studies ask whether a run faulted and say how;
and the one way a study runs a step that must succeed."""


def faulted(run_):
    """the firmware stopped the axis: the run ended early, its figures are null, no result"""
    return run_.get("fault_status", 0) != 0


# the cause of a run whose application the firmware refused at init (sim/lib/tool/br_run_report.h)
REFUSED_AT_INIT = "refused_at_init"


def refused(run_):
    """the firmware refused the application at init (an estimator's setting, the model's sub-step
    bound): the run never started; a fault with this cause in the tools' records (and fleet.py's)"""
    return run_.get("fault_cause") == REFUSED_AT_INIT


def fault_text(run_):
    """the fault where a figure would stand: its time and cause"""
    return "fault at %.3f s (%s)" % (run_["fault_t_s"], run_.get("fault_cause", "unknown"))


def run_or_exit(tool, cmd, **kw):
    """subprocess.run(cmd) after printing it; a failure ends the study (exit 1, naming tool)."""
    import subprocess
    import sys
    print("$ " + " ".join(cmd), flush=True)
    r = subprocess.run(cmd, **kw)
    if r.returncode != 0:
        sys.exit("%s: failed (exit %d): %s" % (tool, r.returncode, " ".join(cmd)))
    return r
